// The differentiators against polynomials they must reproduce exactly (at any
// spacing), and the Kalman filter against a known steady state.
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

namespace {

using jle::DifferentiatorBank;
using jle::DifferentiatorConfig;
using jle::DifferentiatorType;

// Times with +-40% jitter around 1 ms, from a fixed seed.
std::vector<double> jitteredTimes(int n, double t0 = 3.0) {
  jle::PortableRandom random(7);
  std::vector<double> t;
  double now = t0;
  for (int i = 0; i < n; ++i) {
    t.push_back(now);
    now += 1e-3 * random.uniform(0.6, 1.4);
  }
  return t;
}

// A polynomial of degree `degree` with known derivatives: sum_k c_k (t - t0)^k.
struct Poly {
  std::vector<double> c;
  double t0;
  double value(double t) const {
    double s = 0, p = 1;
    for (double ck : c) s += ck * p, p *= (t - t0);
    return s;
  }
  double rate(double t) const {
    double s = 0, p = 1;
    for (std::size_t k = 1; k < c.size(); ++k) s += k * c[k] * p, p *= (t - t0);
    return s;
  }
  double accel(double t) const {
    double s = 0, p = 1;
    for (std::size_t k = 2; k < c.size(); ++k) s += k * (k - 1) * c[k] * p, p *= (t - t0);
    return s;
  }
};

void expectExactOnPolynomial(const DifferentiatorConfig& config, int degree) {
  const Poly a{{0.3, -1.2, 2.5, 0.7, -0.4, 0.2}, 3.0}, b{{-2.0, 0.5, -3.0, 1.1, 0.3, -0.1}, 3.0};
  Poly pa = a, pb = b;
  pa.c.resize(degree + 1);
  pb.c.resize(degree + 1);
  DifferentiatorBank bank(config, 2);
  const std::vector<double> t = jitteredTimes(60);
  int outputs = 0;
  for (double ti : t) {
    const double x[2] = {pa.value(ti), pb.value(ti)};
    if (!bank.update(ti, x)) continue;
    ++outputs;
    const double s = bank.stamp();
    // Exact up to rounding: values O(1); the rate is divided by the window's half-span
    // (1e-3 to 7e-3 s) and the acceleration by its square, which scales the rounding of
    // the O(1) sums by up to 1e3 and 1e6 (times the Vandermonde conditioning).
    EXPECT_NEAR(bank.value(0), pa.value(s), 1e-12);
    EXPECT_NEAR(bank.rate(0), pa.rate(s), 1e-8);
    EXPECT_NEAR(bank.accel(0), pa.accel(s), 2e-5);
    EXPECT_NEAR(bank.value(1), pb.value(s), 1e-12);
    EXPECT_NEAR(bank.rate(1), pb.rate(s), 1e-8);
    EXPECT_NEAR(bank.accel(1), pb.accel(s), 2e-5);
  }
  EXPECT_EQ(outputs, 60 - bank.warmup() + 1);
}

TEST(Differentiator, FiniteDifferenceIsExactForQuadraticsAtAnySpacing) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kFiniteDifference;
  expectExactOnPolynomial(c, 2);
}

TEST(Differentiator, SavitzkyGolayIsExactForItsOrder) {
  for (int order = 2; order <= 4; ++order)
    for (int window : {order + 1, 9, 15}) {
      DifferentiatorConfig c;
      c.type = DifferentiatorType::kSavitzkyGolay;
      c.order = order;
      c.window = window;
      SCOPED_TRACE("order " + std::to_string(order) + " window " + std::to_string(window));
      expectExactOnPolynomial(c, order);
    }
}

TEST(Differentiator, CentredSavitzkyGolayDescribesTheMiddleSample) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kSavitzkyGolay;
  c.window = 11;
  c.order = 3;
  c.delay = 5;
  DifferentiatorBank bank(c, 1);
  const std::vector<double> t = jitteredTimes(30);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double x = std::sin(t[i]);
    if (bank.update(t[i], &x)) {
      EXPECT_EQ(bank.stamp(), t[i - 5]);
    }
  }
}

TEST(Differentiator, CentredFitErrorIsTheTextbookTruncationTerm) {
  // A quadratic least-squares fit over x = k h, k = -m..m, of f picks up its quartic
  // term: the fitted second derivative is f'' + f'''' h^2 S(m), with
  // S = (sum k^6 - mu sum k^4) / (12 (sum k^4 - (2m+1) mu^2)), mu = mean k^2 (the odd
  // terms cancel by symmetry). For m = 4: S = 5060 / (12 * 308) = 1.36904. On
  // sin(w t) at h = 1 ms the worst error must be that term (to 1%: the next term is
  // O(h^4 w^6)); the causal fit keeps an O(h f''') term and is far worse.
  const double h = 1e-3, w = 2 * M_PI * 2.0;
  const double S = 5060.0 / (12.0 * 308.0);
  double worst[2] = {0, 0};
  for (int delay : {0, 4}) {
    DifferentiatorConfig c;
    c.type = DifferentiatorType::kSavitzkyGolay;
    c.window = 9;
    c.order = 2;
    c.delay = delay;
    DifferentiatorBank bank(c, 1);
    for (int i = 0; i < 2000; ++i) {
      const double t = i * h;
      const double x = std::sin(w * t);
      if (!bank.update(t, &x)) continue;
      const double s = bank.stamp();
      double& e = worst[delay ? 1 : 0];
      e = std::max(e, std::abs(bank.accel(0) + w * w * std::sin(w * s)));
    }
  }
  const double predicted = S * std::pow(w, 4) * h * h;
  EXPECT_NEAR(worst[1], predicted, 0.01 * predicted);
  EXPECT_GT(worst[0], 20 * worst[1]);
}

TEST(Differentiator, KalmanTracksConstantAccelerationWithoutBias) {
  // A constant-acceleration model fed an exact parabola converges to it: the steady
  // state of the filter has no bias for this signal (the signal is in the model).
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kKalman;
  c.process_noise = 1.0;
  c.kalman_model = jle::KalmanModel::kConstantAcceleration;
  c.measurement_noise = 1e-3;
  DifferentiatorBank bank(c, 1);
  const Poly p{{0.1, 0.4, 1.5}, 0.0};
  for (int i = 0; i < 20000; ++i) {
    const double t = i * 1e-3;
    const double x = p.value(t);
    bank.update(t, &x);
  }
  EXPECT_NEAR(bank.value(0), p.value(19.999), 1e-9);
  EXPECT_NEAR(bank.rate(0), p.rate(19.999), 1e-7);
  EXPECT_NEAR(bank.accel(0), p.accel(19.999), 1e-5);
}

TEST(Differentiator, KalmanHandlesIrregularSpacing) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kKalman;
  c.kalman_model = jle::KalmanModel::kConstantJerk;
  c.process_noise = 10.0;
  c.measurement_noise = 1e-4;
  DifferentiatorBank bank(c, 1);
  const Poly p{{0.1, 0.4, 1.5, -0.3}, 0.0};
  const std::vector<double> t = jitteredTimes(20000, 0.0);
  for (double ti : t) {
    const double x = p.value(ti);
    bank.update(ti, &x);
  }
  const double s = t.back();
  // A cubic is in the constant-jerk model: no steady-state bias (bounds: 1e-6 of scale).
  EXPECT_NEAR(bank.rate(0), p.rate(s), 1e-6 * std::abs(p.rate(s)));
  EXPECT_NEAR(bank.accel(0), p.accel(s), 1e-5 * std::abs(p.accel(s)));
}

TEST(Differentiator, RefusesTimeThatDoesNotIncrease) {
  DifferentiatorBank bank(DifferentiatorConfig(), 1);
  const double x = 0.0;
  bank.update(1.0, &x);
  EXPECT_THROW(bank.update(1.0, &x), std::invalid_argument);
  EXPECT_THROW(bank.update(0.5, &x), std::invalid_argument);
}

TEST(Differentiator, GapRestartsTheWindow) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kFiniteDifference;
  c.max_gap = 0.1;
  DifferentiatorBank bank(c, 1);
  const double x = 1.0;
  EXPECT_FALSE(bank.update(0.000, &x));
  EXPECT_FALSE(bank.update(0.001, &x));
  EXPECT_TRUE(bank.update(0.002, &x));
  EXPECT_FALSE(bank.update(1.000, &x));  // 1 s gap: the window restarts
  EXPECT_FALSE(bank.update(1.001, &x));
  EXPECT_TRUE(bank.update(1.002, &x));
}

TEST(Differentiator, InvalidConfigurationsNameTheField) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kSavitzkyGolay;
  c.order = 1;
  try {
    DifferentiatorBank bank(c, 1);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("order"), std::string::npos);
  }
  c = DifferentiatorConfig();
  c.type = DifferentiatorType::kSavitzkyGolay;
  c.delay = 20;
  EXPECT_THROW(DifferentiatorBank(c, 1), std::invalid_argument);
  c = DifferentiatorConfig();
  c.type = DifferentiatorType::kKalman;
  c.process_noise = -1;
  EXPECT_THROW(DifferentiatorBank(c, 1), std::invalid_argument);
}

// RMS error [rad/s^2] of the acceleration of a 1 Hz, 0.5 rad sine sampled at 1 kHz with
// Gaussian noise of 2.5e-4 rad (the accuracy study's jittered arm), after 1 s.
double accelError(const DifferentiatorConfig& c) {
  DifferentiatorBank bank(c, 1);
  jle::PortableRandom random(7);
  double sum = 0.0;
  int count = 0;
  for (int k = 0; k < 5000; ++k) {
    const double t = 1e-3 * k, x = 0.5 * std::sin(2.0 * M_PI * t) + 2.5e-4 * random.gaussian();
    if (!bank.update(t, &x) || k < 1000) continue;
    const double e = bank.accel(0) + 2.0 * M_PI * M_PI * std::sin(2.0 * M_PI * bank.stamp());
    sum += e * e;
    ++count;
  }
  return std::sqrt(sum / count);
}

// Two configurations are the same filter when every field its type reads is equal
// (asRun over fields(), which the compiler checks names every field: a field forgotten
// there would keep the old filter on a retune); the process noise is compared as the
// filter runs it. A field only another type reads (a Savitzky-Golay order while a Kalman
// filter runs) changes nothing: the filters are kept.
TEST(Differentiator, ConfigurationsAreComparedOnTheFieldsTheirTypeReads) {
  EXPECT_EQ(jle::detail::fieldCount<DifferentiatorConfig>(),
            std::tuple_size_v<decltype(DifferentiatorConfig().fields())>);
  // Each field changed alone, in the order of fields().
  const auto changes = [](const DifferentiatorConfig& base) {
    std::vector<DifferentiatorConfig> changed(14, base);
    changed[0].type = base.type == jle::DifferentiatorType::kAdaptive
                          ? jle::DifferentiatorType::kKalman
                          : jle::DifferentiatorType::kAdaptive;
    changed[1].window = 11;
    changed[2].order = 3;
    changed[3].delay = 1;
    changed[4].kalman_model = jle::KalmanModel::kConstantAcceleration;
    changed[5].process_noise = 2e4;
    changed[6].measurement_noise = 2e-4;
    changed[7].lag = 0.1;
    changed[8].auto_bandwidth = true;
    changed[9].min_bandwidth = 1.0;
    changed[10].max_bandwidth = 40.0;
    changed[11].noise = 1e-3;
    changed[12].memory = 2.0;
    changed[13].max_gap = 0.25;
    return changed;
  };
  const std::vector<std::size_t> fit_fields = {1, 2, 3};  // window, order, delay
  struct Case {
    jle::DifferentiatorType type;
    std::vector<std::size_t> unread;  // fields of changes() the type does not read
  };
  const std::vector<Case> cases = {
      {jle::DifferentiatorType::kKalman, fit_fields},
      {jle::DifferentiatorType::kAdaptive, fit_fields},
      {jle::DifferentiatorType::kSavitzkyGolay, {4, 5, 6, 7, 8, 9, 10, 11, 12}},
      {jle::DifferentiatorType::kFiniteDifference, {1, 4, 5, 6, 7, 8, 9, 10, 11, 12}}};
  for (const Case& c : cases) {
    DifferentiatorConfig base;
    base.type = c.type;
    EXPECT_TRUE(jle::sameDifferentiator(base, base));
    const std::vector<DifferentiatorConfig> changed = changes(base);
    for (std::size_t k = 0; k < changed.size(); ++k) {
      const bool unread = std::find(c.unread.begin(), c.unread.end(), k) != c.unread.end();
      EXPECT_EQ(jle::sameDifferentiator(base, changed[k]), unread)
          << "type " << static_cast<int>(c.type) << ", field " << k;
    }
  }
  const DifferentiatorConfig base;
  DifferentiatorConfig explicit_default = base;
  explicit_default.process_noise = jle::processNoise(base);
  EXPECT_TRUE(jle::sameDifferentiator(base, explicit_default));
}

// process_noise 0 (the default) is the model's: 1e4 for constant jerk, 10 for constant
// acceleration, resolved by processNoise() alone. Both put the bandwidth
// (q / r^2)^(1 / (2n)) at 10^1.5 rad/s with the default r = 1e-4 (closed form). With
// the jerk's 1e4 the constant-acceleration filter was 4.5 times worse on this signal
// (measured: 8.08 against 1.78 rad/s^2; the constant-jerk default 0.71).
TEST(Differentiator, EachKalmanModelHasItsOwnDefaultProcessNoise) {
  DifferentiatorConfig cj, ca;
  ca.kalman_model = jle::KalmanModel::kConstantAcceleration;
  EXPECT_EQ(cj.process_noise, 0.0);
  EXPECT_EQ(jle::processNoise(cj), 1e4);
  EXPECT_EQ(jle::processNoise(ca), 10.0);
  const double r2 = cj.measurement_noise * cj.measurement_noise;
  EXPECT_NEAR(std::pow(jle::processNoise(cj) / r2, 1.0 / 8.0), std::pow(10.0, 1.5), 1e-12);
  EXPECT_NEAR(std::pow(jle::processNoise(ca) / r2, 1.0 / 6.0), std::pow(10.0, 1.5), 1e-12);
  // The same filter as the value set explicitly, to the bit.
  DifferentiatorConfig explicit_ca = ca;
  explicit_ca.process_noise = 10.0;
  EXPECT_TRUE(jle::sameDifferentiator(ca, explicit_ca));
  EXPECT_EQ(accelError(ca), accelError(explicit_ca));
  DifferentiatorConfig jerk_noise = ca;
  jerk_noise.process_noise = 1e4;
  EXPECT_LT(3.0 * accelError(ca), accelError(jerk_noise));
  // 0 is accepted, a negative value refused by name.
  EXPECT_NO_THROW(jle::validate(ca));
  ca.process_noise = -1.0;
  EXPECT_THROW(jle::validate(ca), std::invalid_argument);
}

// RMS error [rad/s^2] of the smoother's acceleration of sum_k a_k sin(2 pi f_k t), 1 kHz,
// Gaussian noise `noise` [rad], over the estimates from 6 s on (after the spectrum's first
// choice, two 2 s blocks after the start), 12 s; and the bank's bandwidth [Hz] at the end.
double smoothedAccelError(const DifferentiatorConfig& c, double noise, double& bandwidth,
                          bool raise_only = false) {
  const double amplitude[] = {0.3, 0.02, 2e-3, 3e-4, 6e-5, 2e-5};
  const double frequency[] = {0.5, 3.0, 6.0, 10.0, 14.0, 19.0};
  DifferentiatorBank bank(c, 1);
  bank.raiseOnly(raise_only);
  jle::PortableRandom random(11);
  double sum = 0.0;
  int count = 0;
  const auto accel = [&](double t) {
    double a = 0.0;
    for (int k = 0; k < 6; ++k) {
      const double w = 2.0 * M_PI * frequency[k];
      a -= amplitude[k] * w * w * std::sin(w * t);
    }
    return a;
  };
  for (int k = 0; k < 12000; ++k) {
    const double t = 1e-3 * k;
    double x = noise * random.gaussian();
    for (int j = 0; j < 6; ++j) x += amplitude[j] * std::sin(2.0 * M_PI * frequency[j] * t);
    if (!bank.update(t, &x) || bank.stamp() < 6.0) continue;
    const double e = bank.accel(0) - accel(bank.stamp());
    sum += e * e;
    ++count;
  }
  bandwidth = bank.bandwidth();
  return std::sqrt(sum / count);
}

// auto_bandwidth (the smoothed stream's default): lines up to 19 Hz, the default process
// noise's bandwidth 8.0 Hz ((q / (r^2 h))^(1/8) / 2 pi, q 400, r 1e-4, h 1 ms). With noise
// of 1e-7 or 1e-4 rad the lines stand above the floor to 19 Hz: the bandwidth is raised
// past them and the acceleration error against the closed form falls (measured 0.028 and
// 0.18 rad/s^2 against 0.70 and 0.70). With 0.02 rad the floor hides everything above a
// few Hz: the bandwidth is lowered below the default's, to the lag's floor (kLagFloor /
// lag, 7 Hz), and the error falls with it.
TEST(Differentiator, TheSmoothersBandwidthFollowsTheSpectrumBothWays) {
  DifferentiatorConfig fixed = jle::defaultSmoother();
  fixed.auto_bandwidth = false;
  const DifferentiatorConfig automatic = jle::defaultSmoother();
  ASSERT_TRUE(automatic.auto_bandwidth);
  const double r = fixed.measurement_noise;
  const double own = std::pow(jle::processNoise(fixed) / (r * r * 1e-3), 1.0 / 8.0) / (2.0 * M_PI);
  EXPECT_NEAR(own, 8.0, 0.05);
  double bandwidth = 0.0, unused = 0.0;
  const double clean = smoothedAccelError(automatic, 1e-7, bandwidth);
  EXPECT_GT(bandwidth, 19.0);
  EXPECT_LT(bandwidth, 30.0);
  EXPECT_LT(10.0 * clean, smoothedAccelError(fixed, 1e-7, unused));
  const double noisy = smoothedAccelError(automatic, 1e-4, bandwidth);
  EXPECT_GT(bandwidth, 19.0);
  EXPECT_LT(2.0 * noisy, smoothedAccelError(fixed, 1e-4, unused));
  const double hidden = smoothedAccelError(automatic, 0.02, bandwidth);
  EXPECT_NEAR(bandwidth, DifferentiatorBank::kLagFloor / automatic.lag, 1e-9);
  EXPECT_LT(hidden, smoothedAccelError(fixed, 0.02, unused));
}

// auto_bandwidth without a lag (the immediate stream's default): the same spectrum, but
// the causal filter's bandwidth is only raised above its process noise's, 11.9 Hz (q 1e4,
// r 1e-4, h 1 ms), never lowered; for positions only where the spectrum shows no noise
// floor (exact data: to max_bandwidth, and the acceleration error against the closed form
// falls, measured 0.19 against 2.81 rad/s^2); with noise of 1e-4 rad the lines to 19 Hz
// stand above a floor: positions keep the default's bandwidth, a filter of rates
// (raiseOnly: the measured velocities') is raised past them (21 Hz, 1.48 against 2.83
// rad/s^2); with 0.02 rad the floor hides everything above a few Hz: the default's.
TEST(Differentiator, TheCausalFiltersBandwidthIsOnlyRaised) {
  const DifferentiatorConfig automatic = jle::defaultDifferentiator();
  ASSERT_TRUE(automatic.auto_bandwidth);
  ASSERT_EQ(automatic.lag, 0.0);
  DifferentiatorConfig fixed = automatic;
  fixed.auto_bandwidth = false;
  const double r = fixed.measurement_noise;
  const double own = std::pow(jle::processNoise(fixed) / (r * r * 1e-3), 1.0 / 8.0) / (2.0 * M_PI);
  EXPECT_NEAR(own, 11.9, 0.05);
  double bandwidth = 0.0, unused = 0.0;
  const double exact = smoothedAccelError(automatic, 0.0, bandwidth);
  EXPECT_NEAR(bandwidth, automatic.max_bandwidth, 1e-6);
  EXPECT_LT(3.0 * exact, smoothedAccelError(fixed, 0.0, unused));
  const double noisy = smoothedAccelError(automatic, 1e-4, bandwidth);
  EXPECT_NEAR(bandwidth, own, 0.05);
  EXPECT_NEAR(noisy, smoothedAccelError(fixed, 1e-4, unused), 1e-9 * noisy);
  const double rates = smoothedAccelError(automatic, 1e-4, bandwidth, true);
  EXPECT_GT(bandwidth, 19.0);
  EXPECT_LT(1.5 * rates, smoothedAccelError(fixed, 1e-4, unused));
  const double hidden = smoothedAccelError(automatic, 0.02, bandwidth, true);
  EXPECT_NEAR(bandwidth, own, 0.05);
  EXPECT_NEAR(hidden, smoothedAccelError(fixed, 0.02, unused), 1e-9 * hidden);
}

}  // namespace
