// The ground-truth generator of the accuracy study: its derivatives are consistent
// with its positions, its sensors have the stated statistics, its output is the same for
// the same seed, and its scenes' loads match closed forms.
#include <jle_testing/ground_truth.hpp>

#include <joint_load_estimator/model/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace {

const std::string kData = JLE_TEST_DATA;
constexpr double kTwoPi = 6.283185307179586;
constexpr double kG = 9.80665;

jle::Model<double> panda() {
  return jle::modelFromUrdfFile(kData + "/urdf/chains/panda_chain.urdf");
}

struct Moments {
  double mean = 0.0, std = 0.0;
  long n = 0;
};

Moments moments(const std::vector<double>& x) {
  Moments m;
  m.n = static_cast<long>(x.size());
  for (double v : x) m.mean += v;
  m.mean /= m.n;
  for (double v : x) m.std += (v - m.mean) * (v - m.mean);
  m.std = std::sqrt(m.std / (m.n - 1));
  return m;
}

TEST(PortableRandom, MapsTheStandardEngineAsDocumented) {
  // The standard fixes mt19937's 10000th output for the default seed 5489
  // ([rand.predef]): 4123659995. uniform() takes two outputs, (a 2^26 + b) 2^-53 with b
  // the second one >> 6: the 5000th uniform() ends in the bits of the 10000th output
  // (2^53 uniform() is an integer below 2^53, exact in a double).
  jle::PortableRandom rng(5489);
  for (int i = 0; i < 4999; ++i) rng.uniform();
  const double u = rng.uniform() * 0x1.0p53;
  EXPECT_EQ(std::fmod(u, 67108864.0), static_cast<double>(4123659995u >> 6));
  EXPECT_EQ(u, std::floor(u));
  // A seed below 2^32 seeds the engine as it is; above, its halves are folded.
  jle::PortableRandom a(7), b((std::uint64_t{5} << 32) | 2);  // 2 ^ 5 = 7
  EXPECT_EQ(a.uniform(), b.uniform());
}

TEST(PortableRandom, UniformAndGaussianHaveTheirMomentsAndRange) {
  jle::PortableRandom rng(7);
  const int n = 1000000;
  std::vector<double> u(n), g(n);
  for (int i = 0; i < n; ++i) {
    u[static_cast<std::size_t>(i)] = rng.uniform();
    ASSERT_GE(u[static_cast<std::size_t>(i)], 0.0);
    ASSERT_LT(u[static_cast<std::size_t>(i)], 1.0);
  }
  for (int i = 0; i < n; ++i) g[static_cast<std::size_t>(i)] = rng.gaussian();
  const Moments mu = moments(u), mg = moments(g);
  // Five standard errors: the mean of n uniforms has std 1/sqrt(12 n) = 2.9e-4; the
  // sample std of a uniform has relative std sqrt(0.8 / n) / 2 = 4.5e-4, of a normal
  // 1 / sqrt(2 n) = 7.1e-4 (so a 0.5 % error in the normal's scale fails).
  EXPECT_NEAR(mu.mean, 0.5, 5 * 2.9e-4);
  EXPECT_NEAR(mu.std, 1.0 / std::sqrt(12.0), 5 * 4.5e-4 / std::sqrt(12.0));
  EXPECT_NEAR(mg.mean, 0.0, 5.0 / std::sqrt(n));
  EXPECT_NEAR(mg.std, 1.0, 5 * 7.1e-4);
  // Fourth moment of a normal: 3, with std sqrt(96 / n) = 0.0098 for the sample's.
  double m4 = 0.0;
  for (double v : g) m4 += v * v * v * v;
  EXPECT_NEAR(m4 / n, 3.0, 5 * 0.0098);
}

TEST(PortableRandom, DerivedSeedsDiffer) {
  EXPECT_NE(jle::deriveSeed(1, 0), jle::deriveSeed(1, 1));
  EXPECT_NE(jle::deriveSeed(1, 0), jle::deriveSeed(2, 0));
  EXPECT_EQ(jle::deriveSeed(3, 4), jle::deriveSeed(3, 4));
}

// Central differences of q against qd and qdd. Taylor: the first-difference error is
// at most h^2/6 max|q'''|, the second-difference error h^2/12 max|q''''| (q is C3 with a
// bounded q'''' between knots, so the integral remainder holds across them). The bounds
// on q''' and q'''' follow from the ranges ground_truth.hpp states:
//   sines: sum over <= 3 sines of A w^3 (A w^4), A < 0.3, w < 2 pi 0.6;
//   steps (one active at a time per coordinate): |height| < 0.8, duration >= 0.6, and
//     for S(s) = 35 s^4 - 84 s^5 + 70 s^6 - 20 s^7, max|S'''| = 52.5 (at s = 1/2) and
//     max|S''''| = 840 (at the ends);
//   quadratics: q''' = 0.
// Rounding adds at most about 4 eps |q| / h^2 to the second difference and eps |q| / h to
// the first (a few ulps of q, divided); 8 eps (1 + |q|) / h^k is allowed for it.
void expectConsistent(const jle::Model<double>& model, jle::MotionKind kind, double jerk_bound,
                      double snap_bound) {
  const double duration = 10.0, h = 1e-3, eps = std::numeric_limits<double>::epsilon();
  const std::vector<jle::CoordinateMotion> motion = jle::randomMotion(model, kind, duration, 11);
  ASSERT_EQ(static_cast<int>(motion.size()), model.nq);
  // Worst excess of the error over its bound (must stay <= 0), and the largest qdd.
  double excess_qd = -1.0, excess_qdd = -1.0, largest_qdd = 0.0;
  for (const jle::CoordinateMotion& m : motion)
    for (double t = 0.0; t <= duration; t += 0.00737) {
      const jle::CoordinateState s = m.at(t), before = m.at(t - h), after = m.at(t + h);
      const double rounding = 8 * eps * (1.0 + std::abs(s.q));
      excess_qd = std::max(excess_qd, std::abs((after.q - before.q) / (2 * h) - s.qd) -
                                          (h * h / 6 * jerk_bound + rounding / h));
      excess_qdd = std::max(excess_qdd, std::abs((after.q - 2 * s.q + before.q) / (h * h) - s.qdd) -
                                            (h * h / 12 * snap_bound + rounding / (h * h)));
      largest_qdd = std::max(largest_qdd, std::abs(s.qdd));
    }
  EXPECT_LE(excess_qd, 0.0);
  EXPECT_LE(excess_qdd, 0.0);
  // The motion is not trivially still: the check above can fail.
  EXPECT_GT(largest_qdd, 0.1);
}

TEST(GroundTruth, DerivativesMatchFiniteDifferencesOfPositions) {
  const jle::Model<double> model = panda();
  const double w = kTwoPi * 0.6;
  expectConsistent(model, jle::MotionKind::kSines, 3 * 0.3 * w * w * w, 3 * 0.3 * w * w * w * w);
  const double step_jerk = 52.5 * 0.8 / (0.6 * 0.6 * 0.6), step_snap = 840 * 0.8 / std::pow(0.6, 4);
  expectConsistent(model, jle::MotionKind::kRamps, step_jerk, step_snap);
  expectConsistent(model, jle::MotionKind::kStopAndGo, step_jerk, step_snap);
  expectConsistent(model, jle::MotionKind::kQuadratic, 0.0, 0.0);
  // A tree with prismatic joints (scaled ranges, the same bounds hold a fortiori).
  const jle::Model<double> tree = jle::modelFromUrdfString(jle::randomTreeUrdf(7, 12));
  expectConsistent(tree, jle::MotionKind::kSines, 3 * 0.3 * w * w * w, 3 * 0.3 * w * w * w * w);
}

TEST(GroundTruth, StopAndGoHoldsAllCoordinatesStillTogether) {
  const jle::Model<double> model = panda();
  const std::vector<jle::CoordinateMotion> motion =
      jle::randomMotion(model, jle::MotionKind::kStopAndGo, 10.0, 3);
  // The first hold lasts at least 0.2 s from t = 0; holds recur between moves.
  int still = 0, samples = 0;
  for (double t = 0.0; t < 10.0; t += 0.01, ++samples) {
    bool all = true;
    for (const jle::CoordinateMotion& m : motion) {
      const jle::CoordinateState s = m.at(t);
      all = all && s.qd == 0.0 && s.qdd == 0.0;
    }
    if (t < 0.2) {
      EXPECT_TRUE(all) << t;
    }
    still += all;
  }
  // Holds of [0.2, 0.8) s between moves of [0.6, 1.5) s: between 0.2/1.7 and 0.8/1.4 of
  // the time (give or take the last, cut, interval).
  EXPECT_GT(still, samples * 0.2 / 1.7 - 80);
  EXPECT_LT(still, samples * 0.8 / 1.4 + 80);
}

jle::GroundTruth pandaTruth(jle::MotionKind kind) {
  const jle::Model<double> model = panda();
  return jle::GroundTruth(model, jle::randomMotion(model, kind, 10.0, 5),
                          {jle::randomWrench("panda_hand", 9)});
}

TEST(GroundTruth, EncoderQuantisationIsUniformOverOneCount) {
  const jle::GroundTruth truth = pandaTruth(jle::MotionKind::kSines);
  jle::SensorModel sensor;
  sensor.counts_per_revolution = 4096.0;
  const double res = kTwoPi / 4096.0;
  const jle::SensorReadings r = truth.sample(sensor, 10.0, 1);
  ASSERT_EQ(r.joints.size(), 10001u);
  std::vector<double> error;
  for (const jle::JointReading& j : r.joints) {
    EXPECT_EQ(j.stamp, j.time);
    for (int c = 0; c < truth.model().nq; ++c) {
      const double counts = j.q[c] / res;
      ASSERT_NEAR(counts, std::round(counts), 1e-6);  // on the count grid
      const double e = j.q[c] - truth.motion()[static_cast<std::size_t>(c)].at(j.time).q;
      ASSERT_LE(std::abs(e), 0.5 * res * (1 + 1e-9));
      error.push_back(e);
    }
  }
  // Uniform on [-res/2, res/2]: mean 0, std res/sqrt(12). 70007 errors from slow motion
  // (0.1..0.9 counts per sample) are not independent; 3% on the std and 2% of a count on
  // the mean are ten times what independent draws would scatter.
  const Moments m = moments(error);
  EXPECT_NEAR(m.mean, 0.0, 0.02 * res);
  EXPECT_NEAR(m.std, res / std::sqrt(12.0), 0.03 * res / std::sqrt(12.0));
}

TEST(GroundTruth, NoiseJitterDropsAndBiasHaveTheirStatistics) {
  const jle::GroundTruth truth = pandaTruth(jle::MotionKind::kStopAndGo);
  jle::SensorModel sensor;
  sensor.position_noise = 1e-3;
  sensor.velocity_noise = 2e-2;
  sensor.sample_jitter = 2e-5;  // the truncation at 0.2 ms = 10 sigma is immaterial
  sensor.stamp_jitter = 3e-5;
  sensor.drop_probability = 0.1;
  sensor.wrench_rate = 500.0;
  sensor.wrench_offset = 1e-4;
  sensor.force_noise = 0.5;
  sensor.moment_noise = 0.02;
  sensor.force_bias = Eigen::Vector3d(1.0, -2.0, 3.0);
  sensor.moment_bias = Eigen::Vector3d(0.1, 0.0, -0.1);
  sensor.wrench_drop_probability = 0.05;
  const jle::SensorReadings r = truth.sample(sensor, 10.0, 2);

  // Kept samples: binomial(10001, 0.9), std 30; five of them.
  EXPECT_NEAR(static_cast<double>(r.joints.size()), 0.9 * 10001, 150);
  std::vector<double> eq, eqd, esample, estamp;
  double last = -1.0;
  for (const jle::JointReading& j : r.joints) {
    EXPECT_GT(j.stamp, last);  // in order despite the jitter
    last = j.stamp;
    const double nominal = std::round(j.time * 1000.0) / 1000.0;
    esample.push_back(j.time - nominal);
    estamp.push_back(j.stamp - j.time);
    for (int c = 0; c < truth.model().nq; ++c) {
      const jle::CoordinateState s = truth.motion()[static_cast<std::size_t>(c)].at(j.time);
      eq.push_back(j.q[c] - s.q);
      eqd.push_back(j.qd[c] - s.qd);
    }
  }
  // Gaussian of std sigma over n draws: mean within 5 sigma / sqrt(n), sample std within
  // 5 / sqrt(2 n) relative (n = 63000 errors per coordinate set, 9000 per jitter).
  auto expectGaussian = [](const std::vector<double>& x, double mean, double sigma) {
    const Moments m = moments(x);
    EXPECT_NEAR(m.mean, mean, 5 * sigma / std::sqrt(static_cast<double>(m.n)));
    EXPECT_NEAR(m.std, sigma, 5 * sigma / std::sqrt(2.0 * m.n));
  };
  expectGaussian(eq, 0.0, 1e-3);
  expectGaussian(eqd, 0.0, 2e-2);
  expectGaussian(esample, 0.0, 2e-5);
  expectGaussian(estamp, 0.0, 3e-5);

  // F/T: 5001 samples at 500 Hz from 0.1 ms, 5% dropped (std 15), exact stamps,
  // bias + noise about the truth.
  EXPECT_NEAR(static_cast<double>(r.wrenches.size()), 0.95 * 5001, 5 * 15.4);
  std::vector<std::vector<double>> ew(6);
  for (const jle::WrenchReading& w : r.wrenches) {
    ASSERT_EQ(w.input, 0);
    const double k = (w.stamp - 1e-4) * 500.0;
    ASSERT_NEAR(k, std::round(k), 1e-9);
    const Eigen::Matrix<double, 6, 1> exact = truth.wrenches()[0].at(w.stamp);
    for (int c = 0; c < 3; ++c) {
      ew[static_cast<std::size_t>(c)].push_back(w.force[c] - exact[c]);
      ew[static_cast<std::size_t>(c + 3)].push_back(w.moment[c] - exact[c + 3]);
    }
  }
  for (int c = 0; c < 3; ++c) {
    expectGaussian(ew[static_cast<std::size_t>(c)], sensor.force_bias[c], 0.5);
    expectGaussian(ew[static_cast<std::size_t>(c + 3)], sensor.moment_bias[c], 0.02);
  }
}

TEST(GroundTruth, SameSeedSameReadingsAndStreamsAreIndependent) {
  const jle::Model<double> model = panda();
  jle::SensorModel sensor;
  sensor.counts_per_revolution = 131072.0;
  sensor.position_noise = 1e-5;
  sensor.stamp_jitter = 1e-5;
  sensor.drop_probability = 0.01;
  sensor.force_noise = 0.1;
  auto make = [&](std::uint64_t motion_seed) {
    return jle::GroundTruth(model,
                            jle::randomMotion(model, jle::MotionKind::kSines, 2.0, motion_seed),
                            {jle::randomWrench("panda_hand", 4)});
  };
  const jle::SensorReadings a = make(1).sample(sensor, 2.0, 8), b = make(1).sample(sensor, 2.0, 8);
  ASSERT_EQ(a.joints.size(), b.joints.size());
  ASSERT_EQ(a.wrenches.size(), b.wrenches.size());
  for (std::size_t k = 0; k < a.joints.size(); ++k) {
    EXPECT_EQ(a.joints[k].stamp, b.joints[k].stamp);
    EXPECT_EQ(a.joints[k].q, b.joints[k].q);
    EXPECT_EQ(a.joints[k].qd, b.joints[k].qd);
  }
  for (std::size_t k = 0; k < a.wrenches.size(); ++k) {
    EXPECT_EQ(a.wrenches[k].stamp, b.wrenches[k].stamp);
    EXPECT_EQ(a.wrenches[k].force, b.wrenches[k].force);
  }
  // Another sensor seed changes the readings; another motion seed the motion.
  const jle::SensorReadings c = make(1).sample(sensor, 2.0, 9);
  EXPECT_NE(a.joints[100].q, c.joints[100].q);
  EXPECT_NE(make(1).motion()[0].at(0.5).q, make(2).motion()[0].at(0.5).q);
  // The wrench sensor draws from its own stream: its noise leaves the joints alone.
  jle::SensorModel louder = sensor;
  louder.force_noise = 5.0;
  const jle::SensorReadings d = make(1).sample(louder, 2.0, 8);
  ASSERT_EQ(a.joints.size(), d.joints.size());
  for (std::size_t k = 0; k < a.joints.size(); ++k) EXPECT_EQ(a.joints[k].q, d.joints[k].q);
  EXPECT_EQ(jle::randomTreeUrdf(7, 12), jle::randomTreeUrdf(7, 12));
  EXPECT_NE(jle::randomTreeUrdf(7, 12), jle::randomTreeUrdf(8, 12));
}

// Impacts: q'' is piecewise constant, with the steps the pulses state, exactly; q' and q
// are its exact integrals (central differences agree to the bound of a piecewise-
// quadratic q); every swing ends at rest, and the robot holds still between swings.
TEST(GroundTruth, ImpactsStepTheAccelerationExactlyAndEndAtRest) {
  const jle::Model<double> model = panda();
  const double duration = 10.0;
  const std::vector<jle::CoordinateMotion> motion =
      jle::randomMotion(model, jle::MotionKind::kImpacts, duration, 4);
  ASSERT_EQ(static_cast<int>(motion.size()), model.nq);
  const double h = 1e-4;
  double largest_step = 0.0;
  for (const jle::CoordinateMotion& m : motion) {
    ASSERT_GE(m.pulses.size(), 4u);  // at least two swings in 10 s
    double largest_accel = 0.0;
    for (const jle::AccelPulse& p : m.pulses)
      largest_accel = std::max(largest_accel, std::abs(p.accel));
    for (std::size_t i = 0; i + 1 < m.pulses.size(); i += 2) {
      const jle::AccelPulse &go = m.pulses[i], &stop = m.pulses[i + 1];
      // The impact stops the swing: the speed gained is lost, the rate is exactly 0.
      EXPECT_NEAR(go.accel * go.duration + stop.accel * stop.duration, 0.0, 1e-12);
      const double end = stop.start + stop.duration;
      EXPECT_NEAR(m.at(end).qd, 0.0, 1e-12);
      EXPECT_EQ(m.at(end + 0.2).qdd, 0.0);
      EXPECT_NEAR(m.at(end + 0.2).q, m.at(end).q, 1e-12);
      // The step at the impact's start: the acceleration jumps by the pulse's, exactly.
      EXPECT_EQ(m.at(stop.start).qdd - m.at(stop.start - 1e-9).qdd, stop.accel);
      EXPECT_GE(stop.duration, 0.01);
      EXPECT_LT(stop.duration, 0.03);
      largest_step = std::max(largest_step, std::abs(stop.accel));
    }
    for (double t = 0.0; t <= duration; t += 0.00737) {
      const jle::CoordinateState s = m.at(t), before = m.at(t - h), after = m.at(t + h);
      // |q'' - a| <= max |a| inside [t - h, t + h]: the central difference's error in q'
      // is at most max|a| h / 2; rounding of q ~1e-15 over 2h adds 1e-11.
      EXPECT_LE(std::abs((after.q - before.q) / (2 * h) - s.qd), largest_accel * h / 2 + 1e-10);
      EXPECT_LE(std::abs((after.qd - before.qd) / (2 * h) - s.qdd), largest_accel + 1e-9);
    }
  }
  // A step in acceleration of at least 0.2 / 0.03 rad/s^2 (the slowest, weakest impact).
  EXPECT_GT(largest_step, 0.2 / 0.03);
}

TEST(GroundTruth, LongHoldsHoldStillForAtLeastTwoSeconds) {
  const jle::Model<double> model = panda();
  const std::vector<jle::CoordinateMotion> motion =
      jle::randomMotion(model, jle::MotionKind::kLongHolds, 20.0, 3);
  double still_since = 0.0, longest = 0.0;
  bool moving_seen = false;
  for (double t = 0.0; t < 20.0; t += 0.01) {
    bool all = true;
    for (const jle::CoordinateMotion& m : motion) all = all && m.at(t).qd == 0.0;
    if (!all) {
      moving_seen = true;
      still_since = t;
    }
    longest = std::max(longest, t - still_since);
    if (t < 2.0) {
      EXPECT_TRUE(all) << t;
    }
  }
  EXPECT_TRUE(moving_seen);
  EXPECT_GE(longest, 2.0 - 0.02);
}

// Gaps: runs of 1 .. max_gap lost samples, so no two readings are more than max_gap + 1
// periods apart, and the longest gap is reached; bursts: stamp errors of the burst's
// deviation in runs, the others' of the sensor's; stamps stay in order.
TEST(GroundTruth, GapsAndBurstsHaveTheirLengthsAndStatistics) {
  const jle::GroundTruth truth = pandaTruth(jle::MotionKind::kSines);
  jle::SensorModel sensor;
  sensor.rate = 1000.0;
  sensor.stamp_jitter = 5e-6;  // 0.5 % of the period
  sensor.burst_probability = 0.01;
  sensor.burst_length = 20;
  sensor.burst_stamp_jitter = 5e-5;  // truncated at 2e-4 = 4 sigma
  sensor.gap_probability = 0.01;
  sensor.max_gap = 8;
  const jle::SensorReadings r = truth.sample(sensor, 10.0, 3);
  long widest = 0, loud = 0;
  std::vector<double> quiet_errors, loud_errors;
  for (std::size_t k = 0; k < r.joints.size(); ++k) {
    const jle::JointReading& j = r.joints[k];
    const long index = std::lround(j.time * 1000.0);
    EXPECT_NEAR(j.time, index / 1000.0, 1e-12);  // no sample jitter
    const double e = j.stamp - j.time;
    EXPECT_LE(std::abs(e), 2e-4 + 1e-12);
    (std::abs(e) > 4e-5 ? loud_errors : quiet_errors).push_back(e);  // 8 sigma of the quiet
    if (k > 0) {
      EXPECT_GT(j.stamp, r.joints[k - 1].stamp);
      const long spacing = index - std::lround(r.joints[k - 1].time * 1000.0);
      EXPECT_LE(spacing, 9);
      widest = std::max(widest, spacing);
    }
  }
  EXPECT_EQ(widest, 9);
  // Lost: a gap of mean 4.5 samples starts at ~1% of the samples: 4.3%. About 96 gaps:
  // their count scatters by 10%, their lengths by 6%; 30% is three times that.
  const double lost = 1.0 - static_cast<double>(r.joints.size()) / 10001.0;
  EXPECT_NEAR(lost, 0.045 / 1.045, 0.3 * 0.043);
  // Bursts cover ~20/120 of the time (a burst of 20, then ~100 samples to the next):
  // 16.7%; 42% of a burst's errors (|e| > 0.8 sigma) are loud, so ~7%; about 80 bursts
  // scatter that by 11%: +-3% (absolute) is ample and still fails without bursts.
  loud = static_cast<long>(loud_errors.size());
  EXPECT_NEAR(static_cast<double>(loud) / static_cast<double>(r.joints.size()), 0.07, 0.03);
  // The others have the sensor's deviation: their median |error| would be 0.674 sigma
  // = 3.4e-6 s alone; the bursts' errors below 4e-5 s (10% of them) move the median of
  // all |errors| to 0.82 sigma = 4.1e-6 s; +-0.5e-6 s is 10 times the scatter of a
  // median of 9500 draws.
  std::vector<double> magnitudes;
  for (const std::vector<double>* errors : {&quiet_errors, &loud_errors})
    for (double e : *errors) magnitudes.push_back(std::abs(e));
  std::nth_element(magnitudes.begin(), magnitudes.begin() + magnitudes.size() / 2,
                   magnitudes.end());
  EXPECT_NEAR(magnitudes[magnitudes.size() / 2], 4.1e-6, 0.5e-6);
}

// The defects draw from their own stream: with none configured the readings are those
// of a sensor without the fields; with gaps, the readings kept are unchanged.
TEST(GroundTruth, GapsLeaveTheKeptReadingsUnchanged) {
  const jle::GroundTruth truth = pandaTruth(jle::MotionKind::kStopAndGo);
  jle::SensorModel sensor;
  sensor.position_noise = 1e-4;
  sensor.stamp_jitter = 1e-5;
  sensor.drop_probability = 0.01;
  jle::SensorModel gappy = sensor;
  gappy.gap_probability = 0.02;
  const jle::SensorReadings a = truth.sample(sensor, 2.0, 5), b = truth.sample(gappy, 2.0, 5);
  ASSERT_LT(b.joints.size(), a.joints.size());
  std::size_t i = 0;
  for (const jle::JointReading& j : b.joints) {
    while (i < a.joints.size() && a.joints[i].time < j.time) ++i;
    ASSERT_LT(i, a.joints.size());
    EXPECT_EQ(a.joints[i].stamp, j.stamp);
    EXPECT_EQ(a.joints[i].q, j.q);
  }
}

// Coloured noise (a 2nd-order Butterworth at 50 Hz on white noise, 1 kHz): its standard
// deviation as stated; its first difference far smaller than white noise's (sqrt(2)
// sigma), as a low-pass at a twentieth of the rate makes it (the difference's variance
// over the noise's is 2 (1 - rho(1)), rho(1) > 0.9 for this filter); the vibration line's
// amplitude as stated. Drawn from its own stream: the stamps, the velocities and
// everything else read exactly as without it.
TEST(GroundTruth, ColouredNoiseHasItsLevelAndSpectrumAndItsOwnStream) {
  const jle::GroundTruth truth = pandaTruth(jle::MotionKind::kStopAndGo);
  jle::SensorModel sensor;
  sensor.position_noise = 1e-4;
  sensor.velocity_noise = 1e-3;
  sensor.stamp_jitter = 1e-5;
  jle::SensorModel coloured = sensor;
  coloured.coloured_noise = 2.75e-4;
  coloured.coloured_corner = 50.0;
  const double seconds = 20.0;
  const jle::SensorReadings a = truth.sample(sensor, seconds, 9);
  const jle::SensorReadings b = truth.sample(coloured, seconds, 9);
  ASSERT_EQ(a.joints.size(), b.joints.size());
  std::vector<double> noise, step;
  for (std::size_t k = 0; k < a.joints.size(); ++k) {
    EXPECT_EQ(a.joints[k].stamp, b.joints[k].stamp);
    EXPECT_EQ(a.joints[k].qd, b.joints[k].qd);
    noise.push_back(b.joints[k].q[0] - a.joints[k].q[0]);
    if (k > 0) step.push_back(noise[k] - noise[k - 1]);
  }
  // 20000 samples correlated over about 1 / (2 pi 50 Hz): some 2000 independent ones,
  // a standard deviation known to about 2 %; 6 % is three times that.
  EXPECT_NEAR(moments(noise).std, 2.75e-4, 0.06 * 2.75e-4);
  EXPECT_LT(moments(step).std, 0.45 * 2.75e-4);
  jle::SensorModel line;
  line.vibration_amplitude = 3e-5;
  line.vibration_frequency = 80.0;
  const jle::SensorReadings c = truth.sample(line, 1.0, 9), exact = truth.sample({}, 1.0, 9);
  double largest = 0.0;
  for (std::size_t k = 0; k < c.joints.size(); ++k)
    largest = std::max(largest, std::abs(c.joints[k].q[1] - exact.joints[k].q[1]));
  // 80 Hz at 1 kHz: every 25 samples hit the same phases, 14.4 degrees apart, so one lies
  // within 7.2 degrees of a peak (cos 7.2 = 0.992).
  EXPECT_NEAR(largest, 3e-5, 1e-6);
}

// The planar arm, from its stated geometry: link lengths L = 0.5, 0.4, 0.3 m, masses
// m = 3, 2, 1 kg, thin rods (centre of mass at L/2, inertia m L^2 / 12 about y). A
// rotation about +y takes x towards -z, so gravity (-z) at a horizontal offset x from a
// joint exerts +m g x about y, and a force (fx, 0, fz) at offset (x, z) exerts z fx - x fz.
TEST(GroundTruth, PlanarArmStaticLoadsMatchTheLeverRule) {
  const jle::Model<double> model = jle::modelFromUrdfString(jle::planarArmUrdf());
  ASSERT_EQ(model.nq, 3);
  const double L[3] = {0.5, 0.4, 0.3}, m[3] = {3.0, 2.0, 1.0};
  const double theta[3] = {0.3, -0.8, 0.5};
  std::vector<jle::CoordinateMotion> still(3);
  for (int i = 0; i < 3; ++i) still[static_cast<std::size_t>(i)].p0 = theta[i];
  jle::WrenchMotion tip;
  tip.link = "tip";
  tip.mean << 4.0, 0.0, -7.0, 0.0, 0.6, 0.0;  // fx, fz, and a moment my
  const jle::GroundTruth truth(model, still, {tip});
  jle::Data<double> data(model);
  truth.loads(1.0, data);
  // Joint origins and centres of mass in the world x-z plane (angles accumulate).
  double jx[4], jz[4], cx[3], phi = 0.0;
  jx[0] = 0.0;
  jz[0] = 0.2;
  for (int i = 0; i < 3; ++i) {
    phi += theta[i];
    cx[i] = jx[i] + 0.5 * L[i] * std::cos(phi);
    jx[i + 1] = jx[i] + L[i] * std::cos(phi);
    jz[i + 1] = jz[i] - L[i] * std::sin(phi);
  }
  for (int j = 0; j < 3; ++j) {
    double applied = 0.0;  // moment about joint j's y axis of everything distal to it
    for (int i = j; i < 3; ++i) applied += m[i] * kG * (cx[i] - jx[j]);
    applied += (jz[3] - jz[j]) * 4.0 - (jx[3] - jx[j]) * (-7.0) + 0.6;
    const int s = model.segmentOfJoint("joint" + std::to_string(j + 1));
    // Statics: the joint balances the applied moment. Sums of O(10) terms: 1e-12.
    EXPECT_NEAR(data.effort[static_cast<std::size_t>(s)], -applied, 1e-12);
    // In-plane loads: no out-of-plane force, no moment about the in-plane axes.
    EXPECT_NEAR(data.force[static_cast<std::size_t>(s)].y(), 0.0, 1e-12);
    EXPECT_NEAR(data.moment[static_cast<std::size_t>(s)].x(), 0.0, 1e-12);
    EXPECT_NEAR(data.moment[static_cast<std::size_t>(s)].z(), 0.0, 1e-12);
  }
}

TEST(GroundTruth, PlanarArmSwingingAsOneBodyMatchesTheRigidPendulum) {
  const jle::Model<double> model = jle::modelFromUrdfString(jle::planarArmUrdf());
  std::vector<jle::CoordinateMotion> motion(3);
  motion[0].sines.push_back({0.7, kTwoPi * 0.4, 0.3});
  motion[0].p0 = 0.2;
  motion[1].p0 = motion[2].p0 = 0.0;  // joints 2 and 3 locked straight
  const jle::GroundTruth truth(model, motion, {});
  jle::Data<double> data(model);
  // One rigid rod system about joint 1: centres of mass at 0.25, 0.7, 1.05 m from it.
  const double m[3] = {3.0, 2.0, 1.0}, L[3] = {0.5, 0.4, 0.3}, d[3] = {0.25, 0.7, 1.05};
  double inertia = 0.0, first_moment = 0.0;
  for (int i = 0; i < 3; ++i) {
    inertia += m[i] * L[i] * L[i] / 12.0 + m[i] * d[i] * d[i];
    first_moment += m[i] * d[i];
  }
  const int s = model.segmentOfJoint("joint1");
  for (double t = 0.0; t < 2.5; t += 0.1) {
    truth.loads(t, data);
    const jle::CoordinateState x = motion[0].at(t);
    // effort = I qdd - (moment of gravity about y) = I qdd - g sum(m d) cos(q).
    EXPECT_NEAR(data.effort[static_cast<std::size_t>(s)],
                inertia * x.qdd - kG * first_moment * std::cos(x.q), 1e-11);
  }
}

TEST(GroundTruth, StanceRisesFastIntoAHalfSine) {
  jle::WrenchMotion w;
  w.link = "foot";
  jle::Stance stance;
  stance.start = 1.0;
  stance.rise = 0.01;
  stance.duration = 0.25;
  stance.peak << 100.0, 0.0, 1500.0, 0.0, 80.0, 0.0;
  w.stances.push_back(stance);
  EXPECT_EQ(w.at(0.999).norm(), 0.0);
  EXPECT_EQ(w.at(1.26).norm(), 0.0);
  const double pi = kTwoPi / 2;
  // Linear in the rise: half of it at half the rise time, times the half sine.
  EXPECT_NEAR(w.at(1.005)[2], 1500.0 * 0.5 * std::sin(pi * 0.005 / 0.25), 1e-9);
  EXPECT_NEAR(w.at(1.125)[2], 1500.0, 1e-9);  // the sine's top
  EXPECT_NEAR(w.at(1.125)[4], 80.0, 1e-12);
  EXPECT_NEAR(w.at(1.25)[2], 0.0, 1e-9);
}

// The leg hangs along -z with every joint on the z axis: at rest only the foot's centre of
// mass, 0.05 m ahead of the ankle, has a lever; every joint holds m_foot g 0.05.
TEST(GroundTruth, PlanarLegHangingHoldsTheFootsLever) {
  const jle::Model<double> model = jle::modelFromUrdfString(jle::planarLegUrdf());
  ASSERT_EQ(model.nq, 3);
  std::vector<jle::CoordinateMotion> still(3);
  const jle::GroundTruth truth(model, still, {});
  jle::Data<double> data(model);
  truth.loads(0.0, data);
  for (const char* joint : {"hip", "knee", "ankle"}) {
    const int s = model.segmentOfJoint(joint);
    EXPECT_NEAR(std::abs(data.effort[static_cast<std::size_t>(s)]), 1.1 * kG * 0.05, 1e-12)
        << joint;
  }
}

TEST(GroundTruth, RandomTreeIsAValidModelWithMasslessAndPrismaticLinks) {
  const jle::Model<double> model = jle::modelFromUrdfString(jle::randomTreeUrdf(7, 12));
  EXPECT_EQ(model.nq, 12);
  int prismatic = 0, massless = 0, branches = 0;
  std::vector<int> children(static_cast<std::size_t>(model.nsegments()), 0);
  for (int i = 1; i < model.nsegments(); ++i) {
    prismatic += model.joint_type[static_cast<std::size_t>(i)] == jle::JointType::kPrismatic;
    massless += model.mass[static_cast<std::size_t>(i)] == 0.0;
    ++children[static_cast<std::size_t>(model.parent[static_cast<std::size_t>(i)])];
  }
  for (int c : children) branches += c > 1;
  // Seed 7 was chosen to cover each case at least once.
  EXPECT_GE(prismatic, 1);
  EXPECT_GE(massless, 1);
  EXPECT_GE(branches, 1);
  EXPECT_NO_THROW(model.frameIndex("link12"));
}

TEST(GroundTruth, RefusesUnknownLinksAndWrongSizes) {
  const jle::Model<double> model = panda();
  EXPECT_THROW(jle::GroundTruth(model, jle::randomMotion(model, jle::MotionKind::kSines, 1.0, 1),
                                {jle::randomWrench("no_such_link", 1)}),
               std::invalid_argument);
  EXPECT_THROW(jle::GroundTruth(model, std::vector<jle::CoordinateMotion>(2), {}),
               std::invalid_argument);
}

}  // namespace
