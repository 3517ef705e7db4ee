// The adaptive smoother's bandwidth choice (spectral_cutoff.hpp) against independent
// references: the FFT against the direct sum, the running-spectrum GCV against the
// time-domain GCV of the offline zero-phase filter (zero_phase.cpp) on the same record.
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/filters/spectral_cutoff.hpp>
#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/io/portable_random.hpp>

#include <gtest/gtest.h>

#include <complex>
#include <vector>

namespace {

TEST(Fft, EqualsTheDirectSum) {
  const int n = 64;
  jle::PortableRandom random(3);
  std::vector<std::complex<double>> x(n), direct(n);
  for (auto& v : x) v = {random.uniform(-1.0, 1.0), random.uniform(-1.0, 1.0)};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j) direct[k] += x[j] * std::polar(1.0, -2.0 * M_PI * j * k / n);
  jle::Fft(256).transform(x.data(), n);
  for (int k = 0; k < n; ++k) EXPECT_LT(std::abs(x[k] - direct[k]), 1e-12) << k;
}

// Three joints, smooth motion (sines 0.5..2.3 Hz), white noise, stamps jittered by
// +-`jitter` of the period around regular sampling instants.
struct Record {
  std::vector<double> t;
  Eigen::MatrixXd x;
};

// The time-domain GCV of the offline zero-phase filter (not its default rule).
jle::ZeroPhaseConfig gcvConfig() {
  jle::ZeroPhaseConfig config;
  config.rule = jle::CutoffRule::kGcv;
  return config;
}

Record smoothMotion(double rate, double noise, double jitter, double seconds) {
  const int n = static_cast<int>(seconds * rate);
  jle::PortableRandom random(7);
  Record r{std::vector<double>(n), Eigen::MatrixXd(n, 3)};
  for (int i = 0; i < n; ++i) {
    const double ti = i / rate;
    r.t[i] = ti + random.uniform(-jitter, jitter) / rate;
    for (int c = 0; c < 3; ++c)
      r.x(i, c) = 0.3 * std::sin(2 * M_PI * (0.5 + 0.4 * c) * ti) +
                  0.1 * std::sin(2 * M_PI * 2.3 * ti + c) + noise * random.gaussian();
  }
  return r;
}

double spectralChoice(const Record& r, int channels = 3) {
  jle::SpectralCutoff choice(channels, 0.5, 50.0);
  const Eigen::Vector3d rate = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    const Eigen::Vector3d row = r.x.row(static_cast<Eigen::Index>(i)).transpose();
    choice.add(r.t[i], row.data(), rate.data(), 1);
  }
  return choice.cutoff();
}

TEST(SpectralCutoff, ChoosesWithinFifteenPercentOfTheTimeDomainGcv) {
  struct Case {
    double rate, noise;
  };
  for (const Case c : {Case{1000, 1e-3}, Case{1000, 1e-4}, Case{200, 1e-3}, Case{100, 2e-4}}) {
    const Record r = smoothMotion(c.rate, c.noise, 0.0, 20.0);
    const double offline = jle::chooseCutoff(r.t, r.x, gcvConfig());
    const double online = spectralChoice(r);
    EXPECT_NEAR(online / offline, 1.0, 0.15)
        << c.rate << " Hz, noise " << c.noise << ": " << online << " against " << offline;
  }
}

TEST(SpectralCutoff, NoChoiceBeforeTwoBlocksAndAGapEndsOnlyTheBlock) {
  Record r = smoothMotion(1000, 1e-3, 0.0, 20.0);
  Record shortRecord{std::vector<double>(r.t.begin(), r.t.begin() + 3000), r.x.topRows(3000)};
  EXPECT_EQ(spectralChoice(shortRecord), 0.0);  // 15 intervals + the first block + 0.95 block
  // A gap of 50 periods in the middle: the choice is made all the same, close to the
  // gapless one.
  const double gapless = spectralChoice(r);
  for (std::size_t i = 10000; i < r.t.size(); ++i) r.t[i] += 0.05;
  EXPECT_NEAR(spectralChoice(r) / gapless, 1.0, 0.1);
}

// A completed block's work (a transform per channel, the spectrum, the scores) is done a
// step per sample over the samples after it, not in the call that completes it: the
// choice comes exactly pendingSteps() samples later, one step each.
TEST(SpectralCutoff, ABlocksWorkIsSpreadOneStepPerSample) {
  const Record r = smoothMotion(1000, 1e-3, 0.0, 10.0);
  jle::SpectralCutoff choice(3, 0.5, 50.0);
  const Eigen::Vector3d rate = Eigen::Vector3d::Zero();
  int pending = 0, choices = 0, due = -1;
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    const Eigen::Vector3d row = r.x.row(static_cast<Eigen::Index>(i)).transpose();
    const bool chosen = choice.add(r.t[i], row.data(), rate.data(), 1);
    const int now = choice.pendingSteps();
    if (pending == 0 && now > 0) {  // a block completed at this sample
      // 3 transforms, the spectrum, the scores of 0.5..50 Hz at ratio 1.05 (95) by 16.
      EXPECT_EQ(now, 3 + 1 + 6);
      due = static_cast<int>(i) + now;
    } else if (pending > 0) {
      EXPECT_EQ(now, pending - 1) << i;
    }
    EXPECT_EQ(chosen, static_cast<int>(i) == due) << i;
    choices += chosen;
    pending = now;
  }
  EXPECT_EQ(choices, 3);  // 10 s of 2.048 s blocks, the first left out
  EXPECT_GT(choice.cutoff(), 0.0);
}

TEST(SpectralCutoff, OnlyTheChoosingChannelsChoose) {
  Record r = smoothMotion(1000, 1e-3, 0.1, 20.0);
  const double joints = spectralChoice(r, 2);
  // A third channel of pure large noise (a wrench, say) left out of the choice.
  jle::PortableRandom random(11);
  for (Eigen::Index i = 0; i < r.x.rows(); ++i) r.x(i, 2) = 5.0 * random.gaussian();
  EXPECT_EQ(spectralChoice(r, 2), joints);
  EXPECT_NE(spectralChoice(r, 3), joints);
}

TEST(SpectralCutoff, TheAdaptiveSmootherUsesItFromALagOf014SecondsOn) {
  jle::DifferentiatorConfig config;
  config.type = jle::DifferentiatorType::kAdaptive;
  const Record r = smoothMotion(1000, 1e-3, 0.1, 12.0);
  for (const double lag : {0.1, 0.2, 0.5}) {
    config.lag = lag;
    jle::DifferentiatorBank bank(config, 3);
    for (std::size_t i = 0; i < r.t.size(); ++i) {
      const Eigen::Vector3d row = r.x.row(static_cast<Eigen::Index>(i)).transpose();
      bank.update(r.t[i], row.data());
    }
    if (lag < 0.14) {  // the likelihood's choice: one of the bank's bandwidths
      const double b = bank.bandwidth();
      EXPECT_NEAR(std::log2(b / config.min_bandwidth),
                  std::round(std::log2(b / config.min_bandwidth)), 1e-9);
    } else {
      const double offline = jle::chooseCutoff(r.t, r.x, gcvConfig());
      EXPECT_NEAR(bank.bandwidth() / std::max(offline, 1.4 / lag), 1.0, 0.15) << lag;
    }
  }
}

}  // namespace
