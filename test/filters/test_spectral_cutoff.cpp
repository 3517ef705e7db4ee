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

// Every size up to the capacity: the first stages (len 2, 4) alone or with stages in
// pairs, and one stage left over where their count is odd (n = 8, 32, 128). Errors of
// about 1e-16 sqrt(n) log2(n) |x| (|x| ~ 1): 1e-12 leaves a margin.
TEST(Fft, EqualsTheDirectSum) {
  jle::PortableRandom random(3);
  const jle::Fft fft(256);
  for (int n = 1; n <= 256; n *= 2) {
    std::vector<std::complex<double>> x(n), direct(n);
    for (auto& v : x) v = {random.uniform(-1.0, 1.0), random.uniform(-1.0, 1.0)};
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)  // the angle reduced: exp(-2 pi i (jk mod n) / n)
        direct[k] += x[j] * std::polar(1.0, -2.0 * M_PI * ((j * k) % n) / n);
    fft.transform(x.data(), n);
    for (int k = 0; k < n; ++k) EXPECT_LT(std::abs(x[k] - direct[k]), 1e-12) << n << ": " << k;
  }
}

// The positions' spectrum by the direct O(n^2) sum, one channel at a time: grid sample g
// the mean of samples first + d g .. first + d g + d - 1 (d: the decimation); block b's
// first differences e_j = g_{bn+j+1} - g_{bn+j}, Hann window w_j = (1 - cos(2 pi (j + 1/2)
// / n)) / 2, E_k = sum_j w_j e_j exp(-2 pi i j k / n); the level |E_k|^2 / (4 sin^2(pi k
// / n)) / sum_j w_j^2 (white noise of variance s^2 has level s^2), summed over the
// channels, averaged over the blocks.
std::vector<double> directSpectrum(const Eigen::MatrixXd& x, int first, int d, int n, int blocks) {
  std::vector<std::complex<double>> root(n);  // exp(-2 pi i m / n)
  for (int m = 0; m < n; ++m) root[m] = std::polar(1.0, -2.0 * M_PI * m / n);
  std::vector<double> window(n), level(n / 2 + 1, 0.0);
  double energy = 0.0;
  for (int j = 0; j < n; ++j) {
    window[j] = 0.5 - 0.5 * std::cos(2.0 * M_PI * (j + 0.5) / n);
    energy += window[j] * window[j];
  }
  const auto grid = [&](int g, int c) { return x.col(c).segment(first + d * g, d).sum() / d; };
  for (Eigen::Index c = 0; c < x.cols(); ++c)
    for (int b = 0; b < blocks; ++b) {
      std::vector<double> e(n);
      for (int j = 0; j < n; ++j) e[j] = window[j] * (grid(b * n + j + 1, c) - grid(b * n + j, c));
      for (int k = 1; k <= n / 2; ++k) {
        std::complex<double> sum = 0.0;
        for (int j = 0; j < n; ++j) sum += e[j] * root[(j * k) % n];
        const double s = std::sin(M_PI * k / n);
        level[k] += std::norm(sum) / (4.0 * s * s) / energy / blocks;
      }
    }
  return level;
}

// The running spectrum, whose transforms take the channels two at a time (z = a + i b),
// against directSpectrum: random data of unequal scales, regular stamps (no shift along
// the rates), two blocks of 1024 grid samples (the first kept), at 500 Hz and at 1 kHz
// (averaged in pairs); an even and an odd count of channels (one left alone), and one.
TEST(SpectralCutoff, PairedSpectrumEqualsTheDirectSumChannelByChannel) {
  const int n = 1024, first = jle::SpectralCutoff::kFirstIntervals;
  for (const int d : {1, 2})
    for (const int channels : {1, 4, 5}) {
      jle::SpectralCutoff cutoff(channels, 0.5, 50.0, jle::SpectralCutoff::Rule::kNoiseFloor,
                                 jle::SpectralCutoff::kBlockSeconds, true);
      const int samples = first + d * (2 * n + 50);
      jle::PortableRandom random(17);
      Eigen::MatrixXd x(samples, channels);
      for (int i = 0; i < samples; ++i)
        for (int c = 0; c < channels; ++c) x(i, c) = (1.0 + 0.7 * c) * random.uniform(-1.0, 1.0);
      const std::vector<double> zero(static_cast<std::size_t>(channels), 0.0);
      for (int i = 0; i < samples; ++i) {
        const Eigen::VectorXd row = x.row(i).transpose();
        cutoff.add(i / (500.0 * d), row.data(), zero.data(), 1);
      }
      ASSERT_EQ(cutoff.decimation(), d);
      ASSERT_EQ(cutoff.blockSamples(), n);
      ASSERT_EQ(cutoff.blocks(), 2);
      ASSERT_EQ(cutoff.pendingSteps(), 0);
      const std::vector<double> expected = directSpectrum(x, first, d, n, 2);
      for (int k = 1; k <= n / 2; ++k)  // the rounding: within 1e-12 here (the bound: 1e-9)
        EXPECT_NEAR(cutoff.spectrum()[k] / expected[k], 1.0, 1e-9)
            << d << ", " << channels << " channels, bin " << k;
    }
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
