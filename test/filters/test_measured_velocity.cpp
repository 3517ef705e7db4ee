// Measured joint velocities (EstimatorConfig::measured_velocity) through the message path,
// against the exact loads of an analytic motion: with noisy positions and the robot's own
// velocities the loads are closer to the truth than from the positions alone; a missing or
// non-finite velocity costs that velocity, never the sample; positions-only streams are
// unchanged by the setting.
#include <jle_testing/message_stream.hpp>
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace {

using jle::InputKind;
using jle::Outcome;
using jle::Stamp;

using jle_test::kData;
using jle_test::kMs;
using jle_test::kNone;
using jle_test::kStart;
using jle_test::ur5;

// Joint i moves as a_i sin(w_i t + p_i) (t [s] since kStart): an arm at 0.4-1.1 Hz.
double amplitude(int i) { return 0.6 - 0.07 * i; }
double omega(int i) { return 2.0 * M_PI * (0.4 + 0.13 * i); }
double phase(int i) { return 0.9 * i; }
double q(int i, double t) { return amplitude(i) * std::sin(omega(i) * t + phase(i)); }
double qd(int i, double t) { return amplitude(i) * omega(i) * std::cos(omega(i) * t + phase(i)); }
double qdd(int i, double t) { return -omega(i) * omega(i) * q(i, t); }

// The joint states of 4 s at 1 kHz: positions with white noise of `position_noise` [rad],
// velocities with `velocity_noise` [rad/s] (empty when negative), every message's
// velocity of joint `nan_joint` NaN where k % nan_every == nan_phase.
struct Stream {
  double position_noise = 2e-4;
  double velocity_noise = 2e-3;
  bool velocities = true;
  int nan_joint = -1;
  int nan_every = 1;
  int nan_phase = 0;
};

struct Errors {
  double velocity = 0.0, acceleration = 0.0, effort = 0.0;  // RMS over joints and samples
  long published = 0;
};

// Feeds the stream to `pipeline` and compares every record after the first second with
// the exact loads at its stamp (the core's passes with the exact q, qd, qdd).
Errors run(jle::Pipeline& pipeline, const Stream& s, std::vector<jle::LoadsRecord>* records) {
  const jle::Model<double>& model = pipeline.model();
  const std::vector<std::string>& names = model.coordinate_names;
  const int n = model.nq;
  jle::PortableRandom random(7);
  jle::Data<double> data(model);
  jle::VectorX<double> tq(n), tqd(n), tqdd(n);
  std::vector<double> p(n), v(n);
  Errors e;
  long scored = 0;
  for (int k = 0; k < 4000; ++k) {
    const double t = 1e-3 * k;
    for (int i = 0; i < n; ++i) {
      p[i] = q(i, t) + s.position_noise * random.gaussian();
      v[i] = qd(i, t) + s.velocity_noise * random.gaussian();
    }
    if (s.nan_joint >= 0 && k % s.nan_every == s.nan_phase) v[s.nan_joint] = std::nan("");
    const Stamp stamp = kStart + k * kMs;
    const Outcome o =
        pipeline.onJointState(stamp, stamp, names, p, s.velocities ? v : kNone, kNone);
    EXPECT_TRUE(o == Outcome::kUsed || o == Outcome::kPublished) << k << " " << pipeline.problem();
    if (o != Outcome::kPublished) continue;
    ++e.published;
    const jle::LoadsRecord& r = pipeline.record();
    if (records) records->push_back(r);
    const double tr = 1e-9 * static_cast<double>(r.stamp - kStart);
    if (tr < 1.0) continue;
    for (int i = 0; i < n; ++i) tq[i] = q(i, tr), tqd[i] = qd(i, tr), tqdd[i] = qdd(i, tr);
    jle::forwardKinematics(model, data, tq, tqd, tqdd, Eigen::Vector3d(0.0, 0.0, -9.80665));
    jle::inverseDynamics(model, data);
    for (std::size_t j = 0; j < r.segment.size(); ++j) {
      const int i = static_cast<int>(j);
      e.velocity += std::pow(r.velocity[j] - tqd[i], 2);
      e.acceleration += std::pow(r.acceleration[j] - tqdd[i], 2);
      e.effort += std::pow(r.effort[j] - data.effort[static_cast<std::size_t>(r.segment[j])], 2);
      ++scored;
    }
  }
  e.velocity = std::sqrt(e.velocity / scored);
  e.acceleration = std::sqrt(e.acceleration / scored);
  e.effort = std::sqrt(e.effort / scored);
  return e;
}

jle::Settings with(jle::MeasuredVelocity mode) {
  jle::Settings s;  // the default filter: what users run
  s.estimator.measured_velocity = mode;
  return s;
}

TEST(MeasuredVelocity, UsedByDefaultAndCloserToTheTruthThanThePositions) {
  const jle::Model<double> model = ur5();
  jle::Pipeline measured(model, with(jle::MeasuredVelocity::kAuto), nullptr);
  jle::Pipeline positions(model, with(jle::MeasuredVelocity::kNever), nullptr);
  const Errors m = run(measured, Stream{}, nullptr);
  const Errors p = run(positions, Stream{}, nullptr);
  EXPECT_EQ(measured.velocitiesUsed(), model.nq);
  EXPECT_EQ(positions.velocitiesUsed(), 0);
  EXPECT_EQ(m.published, p.published);
  // Position noise 2e-4 rad at 1 kHz is 1e2-1e3x the velocities' 2e-3 rad/s in q-ddot;
  // the same filter delays both alike, so the velocities must win on every figure.
  EXPECT_LT(m.velocity, 0.5 * p.velocity) << m.velocity << " " << p.velocity;
  EXPECT_LT(m.acceleration, 0.5 * p.acceleration) << m.acceleration << " " << p.acceleration;
  EXPECT_LT(m.effort, 0.5 * p.effort) << m.effort << " " << p.effort;
  std::printf(
      "RMS error, velocities | positions: qd %.3g | %.3g rad/s, qdd %.3g | %.3g rad/s^2, "
      "effort %.3g | %.3g N m\n",
      m.velocity, p.velocity, m.acceleration, p.acceleration, m.effort, p.effort);
}

// Exact positions, velocities with 2e-3 rad/s of noise, 8 s at 1 kHz (the spectra choose
// from their second 2 s block on). The smoother's rule (Estimator::velocitiesBetter) takes
// the positions where they show no noise floor; the causal filter, whose bandwidth is set
// from the same spectrum by default, takes the velocities wherever measured (accuracy
// study, the immediate default: panda 0.049 N m with them, 0.063 with the rule).
TEST(MeasuredVelocity, TheCausalFilterTakesThemWhateverTheSpectraSay) {
  const jle::Model<double> model = ur5();
  const jle::Settings settings;
  jle::EstimatorConfig smoother = settings.estimator;
  smoother.differentiator = settings.smoothed.differentiator;
  jle::Estimator causal(model, settings.estimator), smoothed(model, smoother);
  ASSERT_TRUE(settings.estimator.differentiator.auto_bandwidth);
  ASSERT_EQ(settings.estimator.differentiator.lag, 0.0);
  jle::PortableRandom random(3);
  std::vector<double> p(model.nq), v(model.nq);
  for (int k = 0; k < 8000; ++k) {
    const double t = 1e-3 * k;
    for (int i = 0; i < model.nq; ++i) p[i] = q(i, t), v[i] = qd(i, t) + 2e-3 * random.gaussian();
    causal.addJointSample(t, p.data(), nullptr, v.data());
    smoothed.addJointSample(t, p.data(), nullptr, v.data());
  }
  ASSERT_GT(causal.filters().spectralCutoff(), 0.0);
  ASSERT_GT(smoothed.filters().spectralCutoff(), 0.0);
  EXPECT_EQ(causal.filters().velocitiesUsed(), model.nq);
  EXPECT_TRUE(causal.filters().velocitiesBetter());
  EXPECT_FALSE(smoothed.filters().velocitiesBetter());
}

TEST(MeasuredVelocity, PositionsOnlyStreamsAreUnchangedBySetting) {
  const jle::Model<double> model = ur5();
  Stream s;
  s.velocities = false;
  std::vector<jle::LoadsRecord> a, b, c;
  jle::Pipeline auto_mode(model, with(jle::MeasuredVelocity::kAuto), nullptr);
  jle::Pipeline never(model, with(jle::MeasuredVelocity::kNever), nullptr);
  run(auto_mode, s, &a);
  run(never, s, &b);
  // All-NaN velocities are no velocities.
  s.velocities = true;
  s.nan_joint = -1;
  jle::Pipeline nan_mode(model, with(jle::MeasuredVelocity::kAuto), nullptr);
  Stream all_nan = s;
  all_nan.velocity_noise = std::nan("");
  run(nan_mode, all_nan, &c);
  EXPECT_EQ(auto_mode.velocitiesUsed(), 0);
  EXPECT_EQ(nan_mode.velocitiesUsed(), 0);
  EXPECT_EQ(nan_mode.counters().nonfinite_velocities, 4000);
  EXPECT_EQ(nan_mode.counters().count(InputKind::kJointState, Outcome::kInvalid), 0);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  for (std::size_t k = 0; k < a.size(); ++k)
    for (std::size_t j = 0; j < a[k].effort.size(); ++j) {
      ASSERT_EQ(a[k].effort[j], b[k].effort[j]) << k;  // bit for bit
      ASSERT_EQ(a[k].effort[j], c[k].effort[j]) << k;
      ASSERT_EQ(a[k].force[j], c[k].force[j]) << k;
    }
}

TEST(MeasuredVelocity, ANonFiniteVelocityCostsThatVelocityOnly) {
  const jle::Model<double> model = ur5();
  Stream s;
  s.nan_joint = 2;
  s.nan_every = 10;
  s.nan_phase = 5;  // the first message's is finite: joint 2 uses its velocities
  jle::Pipeline pipeline(model, with(jle::MeasuredVelocity::kAuto), nullptr);
  jle::Pipeline clean(model, with(jle::MeasuredVelocity::kAuto), nullptr);
  const Errors e = run(pipeline, s, nullptr);
  const Errors c = run(clean, Stream{}, nullptr);
  const jle::PipelineCounters& n = pipeline.counters();
  EXPECT_EQ(n.nonfinite_velocities, 400);
  EXPECT_EQ(n.count(InputKind::kJointState, Outcome::kInvalid), 0);
  EXPECT_EQ(e.published, c.published);  // every sample published
  EXPECT_EQ(pipeline.velocitiesUsed(), model.nq);
  // One velocity in ten replaced by the velocity filter's prediction: the loads stay
  // near the clean run's, far from the positions-only error.
  jle::Pipeline positions(model, with(jle::MeasuredVelocity::kNever), nullptr);
  const Errors p = run(positions, Stream{}, nullptr);
  EXPECT_LT(e.effort, 1.2 * c.effort) << e.effort << " " << c.effort;
  EXPECT_LT(e.effort, 0.5 * p.effort) << e.effort << " " << p.effort;
  std::printf("effort RMS error: 10%% NaN velocities %.3g, clean %.3g, positions only %.3g N m\n",
              e.effort, c.effort, p.effort);
}

TEST(MeasuredVelocity, AFirstSampleWithoutVelocityKeepsThatJointOnItsPositions) {
  const jle::Model<double> model = ur5();
  Stream s;
  s.nan_joint = 4;
  s.nan_every = 4000;
  s.nan_phase = 0;  // only the first message's velocity of joint 4 is NaN
  jle::Pipeline pipeline(model, with(jle::MeasuredVelocity::kAuto), nullptr);
  run(pipeline, s, nullptr);
  EXPECT_EQ(pipeline.velocitiesUsed(), model.nq - 1);
  EXPECT_FALSE(pipeline.velocityUsed(4));
  EXPECT_TRUE(pipeline.velocityUsed(3));
}

TEST(MeasuredVelocity, AlwaysWithUncertaintyIsRefused) {
  jle::Settings s = with(jle::MeasuredVelocity::kAlways);
  s.estimator.uncertainty.enabled = true;
  try {
    jle::validate(s);
    FAIL() << "accepted";
  } catch (const jle::SettingsError& e) {
    EXPECT_NE(std::string(e.what()).find("'measured_velocity'"), std::string::npos) << e.what();
  }
  s.estimator.measured_velocity = jle::MeasuredVelocity::kAuto;
  EXPECT_NO_THROW(jle::validate(s));
}

}  // namespace
