// The two streams of one pipeline (settings.smoothed; README, "Two streams"): the
// immediate (causal) loads and the smoothed ones, `lag` seconds of stamps behind, from
// the same messages. Against the exact loads of an analytic motion: the smoothed stream
// is closer to the truth; every joint state reaches it once, across a jump back of time
// and at the end of a stream.
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/kinematics.hpp>
#include <joint_load_estimator/pipeline.hpp>
#include <joint_load_estimator/portable_random.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace {

using jle::Outcome;
using jle::Stamp;

const std::string kData = JLE_TEST_DATA;
constexpr Stamp kStart = 1700000000123456789;  // [ns]
constexpr Stamp kMs = 1000000;
const std::vector<double> kNone;

jle::Model<double> ur5() { return jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf"); }

// Joint i: 0.5 sin(w_i t + i), 0.3-1.0 Hz.
double q(int i, double t) { return 0.5 * std::sin(2.0 * M_PI * (0.3 + 0.14 * i) * t + i); }

struct Truth {
  explicit Truth(const jle::Model<double>& model) : model(model), data(model) {}
  // The exact effort of every published joint at t (central differences of q at 1e-5 s:
  // q-ddot to 1e-6 relative, far below the filters' error).
  double effortError(const jle::LoadsRecord& r) {
    const double t = 1e-9 * static_cast<double>(r.stamp - kStart);
    const int n = model.nq;
    jle::VectorX<double> a(n), b(n), c(n);
    constexpr double h = 1e-5;
    for (int i = 0; i < n; ++i) {
      a[i] = q(i, t);
      b[i] = (q(i, t + h) - q(i, t - h)) / (2 * h);
      c[i] = (q(i, t + h) - 2 * q(i, t) + q(i, t - h)) / (h * h);
    }
    jle::forwardKinematics(model, data, a, b, c, Eigen::Vector3d(0.0, 0.0, -9.80665));
    jle::inverseDynamics(model, data);
    double sum = 0.0;
    for (std::size_t j = 0; j < r.segment.size(); ++j)
      sum += std::pow(r.effort[j] - data.effort[static_cast<std::size_t>(r.segment[j])], 2);
    return sum;
  }
  const jle::Model<double>& model;
  jle::Data<double> data;
};

// 1 kHz joint states with white position noise (5e-5 rad), stamps kStart + k ms + offset.
Outcome feed(jle::Pipeline& p, int k, Stamp offset, jle::PortableRandom& random) {
  const int n = p.model().nq;
  std::vector<double> pos(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) pos[i] = q(i, 1e-3 * k) + 5e-5 * random.gaussian();
  const Stamp stamp = kStart + offset + k * kMs;
  return p.onJointState(stamp, stamp, p.model().coordinate_names, pos, kNone, kNone);
}

TEST(TwoStreams, SmoothedStreamIsLagBehindAndCloserToTheTruth) {
  const jle::Model<double> model = ur5();
  jle::Pipeline p(model, jle::Settings{}, nullptr);  // the defaults: both streams
  ASSERT_TRUE(p.hasSmoothed());
  Truth truth(model);
  jle::PortableRandom random(3);
  double immediate = 0.0, smoothed = 0.0;
  long n_immediate = 0, n_smoothed = 0;
  std::map<Stamp, int> seen;  // smoothed stamps
  for (int k = 0; k < 3000; ++k) {
    const Outcome o = feed(p, k, 0, random);
    const Stamp newest = kStart + k * kMs;
    if (o == Outcome::kPublished && k >= 500) {
      immediate += truth.effortError(p.record());
      ++n_immediate;
    }
    if (!p.smoothedPublished()) continue;
    const jle::LoadsRecord& r = p.smoothedRecord();
    ++seen[r.stamp];
    // lag 0.2 s of stamps behind the newest joint state (1 kHz, exact stamps).
    EXPECT_NEAR(1e-9 * static_cast<double>(newest - r.stamp), 0.2, 1.5e-3) << k;
    if (r.stamp - kStart >= 500 * kMs) {
      smoothed += truth.effortError(r);
      ++n_smoothed;
    }
  }
  while (p.flushSmoothed()) ++seen[p.smoothedRecord().stamp];
  EXPECT_EQ(seen.size(), 3000u);  // every joint state once
  for (const auto& [stamp, count] : seen) ASSERT_EQ(count, 1) << stamp;
  immediate = std::sqrt(immediate / n_immediate);
  smoothed = std::sqrt(smoothed / n_smoothed);
  std::printf("effort RMS error: immediate %.4g, smoothed %.4g N m\n", immediate, smoothed);
  EXPECT_LT(smoothed, 0.5 * immediate);
}

TEST(TwoStreams, AJumpBackDrainsTheSmoothedStream) {
  const jle::Model<double> model = ur5();
  jle::Pipeline p(model, jle::Settings{}, nullptr);
  jle::PortableRandom random(4);
  std::map<Stamp, int> seen;
  const auto collect = [&] {
    if (p.smoothedPublished()) ++seen[p.smoothedRecord().stamp];
    while (p.takeDrainedSmoothed()) ++seen[p.smoothedRecord().stamp];
  };
  for (int k = 0; k < 1000; ++k) {
    feed(p, k, 0, random);
    collect();
  }
  // A looping bag: the stamps (and the clock) go back 1 s.
  for (int k = 0; k < 400; ++k) {
    feed(p, k, -10000 * kMs, random);
    collect();
  }
  EXPECT_EQ(p.counters().backJumps(), 1);
  while (p.flushSmoothed()) ++seen[p.smoothedRecord().stamp];
  EXPECT_EQ(seen.size(), 1400u);  // every joint state of both timelines once
  for (const auto& [stamp, count] : seen) ASSERT_EQ(count, 1) << stamp;
}

TEST(TwoStreams, OffMeansOneStream) {
  const jle::Model<double> model = ur5();
  jle::Settings settings;
  settings.smoothed.enabled = false;
  jle::Pipeline p(model, settings, nullptr);
  EXPECT_FALSE(p.hasSmoothed());
  jle::PortableRandom random(5);
  for (int k = 0; k < 400; ++k) {
    feed(p, k, 0, random);
    EXPECT_FALSE(p.smoothedPublished());
  }
  EXPECT_FALSE(p.flushSmoothed());
  EXPECT_FALSE(p.takeDrainedSmoothed());
}

}  // namespace
