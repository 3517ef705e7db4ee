// The offline zero-phase smoother (zero_phase.hpp) against closed forms: the Butterworth
// forward-backward gain 1 / (1 + (tan(pi f / fs) / tan(pi fc / fs))^(2 order)) of a
// sine, with no phase; a constant and a ramp passed exactly through the padding, on
// regular and irregular stamps; the automatic cutoffs on a noisy sine. The agreement with
// an independently written scipy pipeline is test/scripts/zero_phase_reference.py.
#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/io/portable_random.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace {

using jle::CutoffRule;
using jle::ZeroPhaseConfig;

std::vector<double> uniformTimes(int n, double fs, double t0 = 2.0) {
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) t[i] = t0 + i / fs;
  return t;
}

// Stamps with +-30% jitter around the period 1 / fs, from a fixed seed.
std::vector<double> jitteredTimes(int n, double fs, double t0 = 2.0) {
  jle::PortableRandom random(11);
  std::vector<double> t(n);
  double now = t0;
  for (int i = 0; i < n; ++i) t[i] = now, now += random.uniform(0.7, 1.3) / fs;
  return t;
}

ZeroPhaseConfig fixed(double cutoff, int order = 4) {
  ZeroPhaseConfig c;
  c.rule = CutoffRule::kFixed;
  c.cutoff = cutoff;
  c.order = order;
  return c;
}

// The forward-backward gain at frequency f of a Butterworth of `order` per pass.
double gain(double f, double fc, double fs, int order) {
  const double r = std::tan(M_PI * f / fs) / std::tan(M_PI * fc / fs);
  return 1.0 / (1.0 + std::pow(r, 2 * order));
}

Eigen::MatrixXd sampled(const std::vector<double>& t, double (*f)(double)) {
  Eigen::MatrixXd x(t.size(), 1);
  for (std::size_t i = 0; i < t.size(); ++i) x(i, 0) = f(t[i]);
  return x;
}

TEST(ZeroPhase, ConstantAndRampPassExactlyToTheEnds) {
  for (const bool jitter : {false, true}) {
    const std::vector<double> t = jitter ? jitteredTimes(300, 100.0) : uniformTimes(300, 100.0);
    Eigen::MatrixXd x(t.size(), 2);
    for (std::size_t i = 0; i < t.size(); ++i) x(i, 0) = 0.7, x(i, 1) = 1.5 - 0.4 * t[i];
    const jle::ZeroPhaseResult r = smoothZeroPhase(t, x, fixed(3.0));
    // Rounding only: a few ulps of values of order 1, divided by h (rate) and h^2 (accel).
    for (std::size_t i = 0; i < t.size(); ++i) {
      EXPECT_NEAR(r.value(i, 0), 0.7, 1e-13) << i;
      EXPECT_NEAR(r.value(i, 1), x(i, 1), 1e-13) << i;
      EXPECT_NEAR(r.rate(i, 0), 0.0, 1e-10) << i;
      EXPECT_NEAR(r.rate(i, 1), -0.4, 1e-10) << i;
      EXPECT_NEAR(r.accel(i, 0), 0.0, 1e-8) << i;
      EXPECT_NEAR(r.accel(i, 1), 0.0, 1e-8) << i;
    }
    EXPECT_EQ(r.cutoff, 3.0);
  }
}

TEST(ZeroPhase, SineBelowTheCutoffPassesWithoutPhase) {
  const double fs = 1000.0, fc = 20.0, f = 1.0, w = 2.0 * M_PI * f;
  const std::vector<double> t = uniformTimes(4000, fs);
  const jle::ZeroPhaseResult r =
      smoothZeroPhase(t, sampled(t, [](double s) { return std::sin(2.0 * M_PI * s); }), fixed(fc));
  // |H|^2 at 1 Hz is 1 - 4e-11; the 5-point differences err by (w h)^4 / 30 = 5e-13
  // (rate) relative. The end transients decay within 0.5 s (10 periods of the cutoff).
  ASSERT_LT(1.0 - gain(f, fc, fs, 4), 1e-10);
  for (std::size_t i = 500; i + 500 < t.size(); ++i) {
    EXPECT_NEAR(r.value(i, 0), std::sin(w * t[i]), 1e-9) << i;
    EXPECT_NEAR(r.rate(i, 0), w * std::cos(w * t[i]), 1e-7 * w) << i;
    EXPECT_NEAR(r.accel(i, 0), -w * w * std::sin(w * t[i]), 1e-6 * w * w) << i;
  }
}

TEST(ZeroPhase, GainAtAndAboveTheCutoffIsTheButterworthOneWithoutPhase) {
  const double fs = 200.0, fc = 10.0;
  const std::vector<double> t = uniformTimes(4000, fs);
  for (const int order : {2, 3, 4}) {
    for (const double f : {5.0, 10.0, 15.0}) {
      Eigen::MatrixXd x(t.size(), 1);
      for (std::size_t i = 0; i < t.size(); ++i) x(i, 0) = std::cos(2.0 * M_PI * f * t[i]);
      const Eigen::MatrixXd y = jle::lowPassZeroPhase(t, x, fc, order);
      // In the middle, the cosine times the gain, in phase (1e-9: the end transients, of
      // time scale 1 / fc = 20 samples, have decayed 1000 samples from the ends).
      const double g = gain(f, fc, fs, order);
      for (std::size_t i = 1000; i + 1000 < t.size(); ++i)
        EXPECT_NEAR(y(i, 0), g * x(i, 0), 1e-9) << order << " " << f << " " << i;
    }
  }
  EXPECT_NEAR(gain(10.0, 10.0, 200.0, 4), 0.5, 1e-15);  // -6 dB at the cutoff, as stated
}

TEST(ZeroPhase, IrregularStampsAddOnlyTheInterpolationError) {
  const double fs = 200.0, w = 2.0 * M_PI * 1.5;
  const std::vector<double> t = jitteredTimes(2000, fs);
  const jle::ZeroPhaseResult r = smoothZeroPhase(
      t, sampled(t, [](double s) { return std::sin(3.0 * M_PI * s); }), fixed(15.0));
  // Linear resampling errs by up to h^2 w^2 / 8 = 4.6e-4 in value at a sine's crest
  // (samples up to 1.3 + 1.3 periods apart at +-30 % jitter: h = 13 ms). That error varies
  // from sample to sample; the filter passes its part below the cutoff wc, whose rate and
  // acceleration are at most wc and wc^2 times larger. Away from the ends.
  const double h = 2.6 / fs, bound = h * h * w * w / 8.0, wc = 2.0 * M_PI * 15.0;
  for (std::size_t i = 200; i + 200 < t.size(); ++i) {
    EXPECT_NEAR(r.value(i, 0), std::sin(w * t[i]), bound) << i;
    EXPECT_NEAR(r.rate(i, 0), w * std::cos(w * t[i]), bound * wc) << i;
    EXPECT_NEAR(r.accel(i, 0), -w * w * std::sin(w * t[i]), bound * wc * wc) << i;
  }
}

TEST(ZeroPhase, LowPassIsTheSmoothedValue) {
  const std::vector<double> t = jitteredTimes(500, 100.0);
  Eigen::MatrixXd x(t.size(), 3);
  jle::PortableRandom random(3);
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = random.gaussian();
  const jle::ZeroPhaseResult r = smoothZeroPhase(t, x, fixed(6.0, 3));
  const Eigen::MatrixXd y = jle::lowPassZeroPhase(t, x, 6.0, 3);
  // The same filter: at the stamps, the Hermite value and the linear interpolation of the
  // grid's values differ by the interpolation only (bounded by the signal's smoothness).
  EXPECT_LT((r.value - y).cwiseAbs().maxCoeff(), 0.05 * y.cwiseAbs().maxCoeff());
  const std::vector<double> u = uniformTimes(500, 100.0);
  EXPECT_EQ(smoothZeroPhase(u, x, fixed(6.0, 3)).value, jle::lowPassZeroPhase(u, x, 6.0, 3));
}

// A 1.5 Hz sine of amplitude 0.5 with white noise of 1e-3: both rules find a cutoff
// between the signal and the noise, and their smoothed acceleration is far closer to the
// truth than the raw second difference.
TEST(ZeroPhase, AutomaticCutoffsSeparateSignalFromNoise) {
  const double fs = 200.0, w = 2.0 * M_PI * 1.5;
  const std::vector<double> t = uniformTimes(2000, fs);
  Eigen::MatrixXd x(t.size(), 2);
  jle::PortableRandom random(5);
  for (std::size_t i = 0; i < t.size(); ++i)
    for (int c = 0; c < 2; ++c) x(i, c) = 0.5 * std::sin(w * t[i] + c) + 1e-3 * random.gaussian();
  for (const CutoffRule rule : {CutoffRule::kResidual, CutoffRule::kGcv}) {
    ZeroPhaseConfig config;
    config.rule = rule;
    const jle::ZeroPhaseResult r = smoothZeroPhase(t, x, config);
    EXPECT_GT(r.cutoff, 1.5) << static_cast<int>(rule);
    EXPECT_LT(r.cutoff, 20.0) << static_cast<int>(rule);
    EXPECT_EQ(r.cutoff, jle::chooseCutoff(t, x, config));
    double error = 0.0;
    for (std::size_t i = 100; i + 100 < t.size(); ++i)
      error = std::max(error, std::abs(r.accel(i, 0) + 0.5 * w * w * std::sin(w * t[i])));
    // The raw second difference's noise alone: 1e-3 * sqrt(6) * fs^2 = 98 rad/s^2.
    EXPECT_LT(error, 2.0) << static_cast<int>(rule) << " " << r.cutoff;
  }
}

TEST(ZeroPhase, RefusesBadInputNamingIt) {
  const std::vector<double> t = uniformTimes(10, 100.0);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Zero(10, 1);
  EXPECT_THROW(smoothZeroPhase(t, x, fixed(0.0)), std::invalid_argument);
  EXPECT_THROW(smoothZeroPhase(t, x, fixed(60.0)), std::invalid_argument);  // > Nyquist
  EXPECT_THROW(smoothZeroPhase(t, x, fixed(5.0, 9)), std::invalid_argument);
  EXPECT_THROW(smoothZeroPhase(t, Eigen::MatrixXd::Zero(9, 1), fixed(5.0)), std::invalid_argument);
  std::vector<double> back = t;
  back[4] = back[3];
  EXPECT_THROW(smoothZeroPhase(back, x, fixed(5.0)), std::invalid_argument);
  try {
    jle::lowPassZeroPhase(t, x, -1.0, 4);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("zero_phase cutoff"), std::string::npos);
  }
}

}  // namespace
