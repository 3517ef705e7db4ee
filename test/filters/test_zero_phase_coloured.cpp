// The offline zero-phase cutoff on coloured position noise (issue 37): a 1 kHz Panda
// recording whose encoder noise is flat to 50 Hz and falls above it, with a vibration
// line and measured velocities of their own noise (jle_testing::GroundTruth). The loads
// are checked against the exact ones, the cutoffs against the best fixed cutoff (an
// oracle scanned here with the truth), and joint_loads (the real CLI, on a CSV written
// here) for its choice, its loads and its warnings.
#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/ground_truth.hpp>

#include <jle_testing/tool_test.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace {

const std::string kPandaChain = std::string(JLE_TEST_DATA) + "/urdf/chains/panda_chain.urdf";
constexpr double kDuration = 6.0;  // [s]
constexpr double kSettle = 0.5;    // [s] left out of the errors at each end (the record's ends)

// The scene: stop-and-go motion, 1 kHz, exact stamps; coloured noise 2.75e-4 rad flat to
// 50 Hz, a 3e-5 rad line at 80 Hz, velocities with 5e-3 rad/s of white noise; or none of
// it (`noisy` false: exact positions).
struct Recording {
  std::unique_ptr<jle::GroundTruth> truth;
  std::vector<double> t;
  Eigen::MatrixXd q, qd;           // samples x nq, as the sensors report them
  Eigen::MatrixXd true_effort;     // samples x moving joints
  std::vector<std::string> joint;  // the moving joints' names
};

// The Panda chain's `motion` (seed 31) read by `sensor` over `duration` [s] (seed 32).
Recording record(jle::MotionKind motion, const jle::SensorModel& sensor, double duration) {
  const jle::Model<double> model = jle::modelFromUrdfString(jle_test::readFile(kPandaChain));
  Recording r;
  r.truth = std::make_unique<jle::GroundTruth>(
      model, jle::randomMotion(model, motion, duration, 31), std::vector<jle::WrenchMotion>{});
  const std::vector<jle::JointReading> readings = r.truth->sample(sensor, duration, 32).joints;
  const auto n = static_cast<Eigen::Index>(readings.size());
  const std::vector<int>& moving = model.moving_segments;
  r.q.resize(n, model.nq);
  r.qd.resize(n, model.nq);
  r.true_effort.resize(n, static_cast<Eigen::Index>(moving.size()));
  jle::Data<double> data(model);
  for (Eigen::Index k = 0; k < n; ++k) {
    const jle::JointReading& reading = readings[static_cast<std::size_t>(k)];
    r.t.push_back(reading.time);
    r.q.row(k) = reading.q.transpose();
    r.qd.row(k) = reading.qd.transpose();
    r.truth->loads(reading.time, data);
    for (std::size_t j = 0; j < moving.size(); ++j)
      r.true_effort(k, static_cast<Eigen::Index>(j)) = data.effort[moving[j]];
  }
  for (int s : moving) r.joint.push_back(model.joint_name[static_cast<std::size_t>(s)]);
  return r;
}

Recording record(bool noisy) {
  jle::SensorModel sensor;
  sensor.rate = 1000.0;
  if (noisy) {
    sensor.coloured_noise = 2.75e-4;
    sensor.coloured_corner = 50.0;
    sensor.vibration_amplitude = 3e-5;
    sensor.vibration_frequency = 80.0;
    sensor.velocity_noise = 5e-3;
  }
  return record(jle::MotionKind::kStopAndGo, sensor, kDuration);
}

const Recording& coloured() {
  static const Recording r = record(true);
  return r;
}

// Quiet encoders (2^17 counts a turn and 5e-6 rad of noise, as the accuracy study's
// Panda) at `rate` [Hz].
jle::SensorModel encoders(double rate) {
  jle::SensorModel sensor;
  sensor.rate = rate;
  sensor.counts_per_revolution = 131072.0;
  sensor.position_noise = 5e-6;
  return sensor;
}

// RMS over the moving joints and the samples kSettle or more from the ends of
// (effort - true effort).
double effortError(const Recording& r, const Eigen::MatrixXd& effort) {
  double sum = 0.0;
  long count = 0;
  for (Eigen::Index k = 0; k < effort.rows(); ++k) {
    const double t = r.t[static_cast<std::size_t>(k)];
    if (t < kSettle || t > r.t.back() - kSettle) continue;
    sum += (effort.row(k) - r.true_effort.row(k)).squaredNorm();
    count += effort.cols();
  }
  return std::sqrt(sum / static_cast<double>(count));
}

// The efforts of the positions smoothed at `cutoff` [Hz] (the core's filter and inverse
// dynamics), samples x moving joints.
Eigen::MatrixXd effortsAt(const Recording& r, double cutoff) {
  jle::ZeroPhaseConfig config;
  config.rule = jle::CutoffRule::kFixed;
  config.cutoff = cutoff;
  const jle::ZeroPhaseResult zp = jle::smoothZeroPhase(r.t, r.q, config);
  const jle::Model<double>& model = r.truth->model();
  jle::Data<double> data(model);
  Eigen::MatrixXd effort(r.q.rows(), r.true_effort.cols());
  for (Eigen::Index k = 0; k < r.q.rows(); ++k) {
    jle::forwardKinematics(model, data, jle::VectorX<double>(zp.value.row(k).transpose()),
                           jle::VectorX<double>(zp.rate.row(k).transpose()),
                           jle::VectorX<double>(zp.accel.row(k).transpose()), r.truth->gravity());
    jle::inverseDynamics(model, data);
    for (std::size_t j = 0; j < model.moving_segments.size(); ++j)
      effort(k, static_cast<Eigen::Index>(j)) = data.effort[model.moving_segments[j]];
  }
  return effort;
}

// The best fixed cutoff: scanned from 1 Hz at ratio 1.1 to 40 Hz against the truth.
struct Oracle {
  double cutoff = 0.0, error = std::numeric_limits<double>::infinity();
};

Oracle oracleOf(const Recording& r) {
  Oracle o;
  for (double f = 1.0; f < 40.0; f *= 1.1) {
    const double e = effortError(r, effortsAt(r, f));
    if (e < o.error) o.error = e, o.cutoff = f;
  }
  return o;
}

const Oracle& oracle() {
  static const Oracle best = oracleOf(coloured());
  return best;
}

// The best fixed cutoff lies where the motion meets the noise (a few Hz: the noise is
// flat to 50 Hz), its error tens of mN m; GCV, which takes noise flat to 50 Hz for
// motion, climbs to its bound and errs a hundred times more (docs/studies/zero_phase.md).
TEST(ColouredNoise, TheOracleAndGcvAreWhatTheStudyFound) {
  EXPECT_GT(oracle().cutoff, 2.0);
  EXPECT_LT(oracle().cutoff, 10.0);
  jle::ZeroPhaseConfig gcv;
  gcv.rule = jle::CutoffRule::kGcv;
  const jle::CutoffChoice choice = jle::selectCutoff(coloured().t, coloured().q, gcv);
  EXPECT_GT(effortError(coloured(), effortsAt(coloured(), choice.cutoff)), 10.0 * oracle().error)
      << choice.cutoff << " Hz";
  EXPECT_FALSE(choice.warnings.empty()) << "GCV at " << choice.cutoff << " Hz, not warned";
}

// The velocity evidence: within 1.3 times the oracle's error, its cutoff within a factor
// of 1.5 of the oracle's.
TEST(ColouredNoise, TheVelocityEvidencePicksNearTheBestFixedCutoff) {
  jle::ZeroPhaseConfig config;
  config.rule = jle::CutoffRule::kVelocity;
  const jle::CutoffChoice choice =
      jle::selectCutoff(coloured().t, coloured().q, config, coloured().qd);
  EXPECT_EQ(choice.rule, jle::CutoffRule::kVelocity);
  EXPECT_NEAR(std::log(choice.cutoff / oracle().cutoff), 0.0, std::log(1.5))
      << choice.cutoff << " Hz against " << oracle().cutoff;
  EXPECT_LT(effortError(coloured(), effortsAt(coloured(), choice.cutoff)), 1.3 * oracle().error);
  EXPECT_TRUE(choice.warnings.empty()) << choice.warnings.front();
  // The default rule with velocities given is this one.
  EXPECT_EQ(jle::chooseCutoff(coloured().t, coloured().q, jle::ZeroPhaseConfig{}, coloured().qd),
            choice.cutoff);
}

// Velocities that are all zero (a driver that does not fill them) are no evidence: the
// default rule falls back to the noise spectrum, and says why.
TEST(ColouredNoise, ZeroVelocitiesAreNotEvidence) {
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(coloured().q.rows(), coloured().q.cols());
  const jle::CutoffChoice choice =
      jle::selectCutoff(coloured().t, coloured().q, jle::ZeroPhaseConfig{}, zero);
  EXPECT_EQ(choice.rule, jle::CutoffRule::kSpectrum);
  EXPECT_EQ(choice.cutoff, jle::chooseCutoff(coloured().t, coloured().q, jle::ZeroPhaseConfig{}));
  ASSERT_FALSE(choice.warnings.empty());
  EXPECT_NE(choice.warnings.front().find("do not follow"), std::string::npos)
      << choice.warnings.front();
}

// A velocity rule without velocities is refused; velocities of another shape too.
TEST(ColouredNoise, TheVelocityRuleNeedsVelocities) {
  jle::ZeroPhaseConfig config;
  config.rule = jle::CutoffRule::kVelocity;
  EXPECT_THROW(jle::chooseCutoff(coloured().t, coloured().q, config), std::invalid_argument);
  EXPECT_THROW(jle::chooseCutoff(coloured().t, coloured().q, config, coloured().qd.leftCols(3)),
               std::invalid_argument);
}

// A record too short for a band of the spectrum (5 samples at 1 kHz: the lowest cutoff
// searched, one period over the record, is 250 Hz, above the 50 Hz bound): the search
// sits on its bound, and says so.
TEST(ColouredNoise, ARecordTooShortForTheSpectrumChoosesTheBoundAndWarns) {
  const std::vector<double> t{0.0, 0.001, 0.002, 0.003, 0.004};
  Eigen::MatrixXd x(5, 1);
  x << 0.0, 1e-3, -2e-3, 1.5e-3, 0.5e-3;
  const jle::CutoffChoice choice = jle::selectCutoff(t, x, jle::ZeroPhaseConfig{});
  EXPECT_NEAR(choice.cutoff, 250.0, 1e-9);
  ASSERT_FALSE(choice.warnings.empty());
  EXPECT_NE(choice.warnings.front().find("no noise floor"), std::string::npos)
      << choice.warnings.front();
}

// The noise spectrum's choice on quiet encoders, positions only, against the best fixed
// cutoff (the oracle, scanned with the truth): within 1.3 times its effort error, the
// bound of issue 37. Slow sines (0.1 .. 0.6 Hz) at 1 kHz: the motion meets the noise near
// 3 Hz, but there the filter's end transient (odd reflection bends the curvature) still
// reaches past the settle length, and the choice moves up for it (without: 3.2 Hz here,
// more than 1.3 times the oracle's error). Stop-and-go at 4 kHz over 5 s, whose motion reaches
// 11 Hz: the analysis bands' end transients are taken out at the source (the record at
// rest at its ends), not by leaving out more of the record near its ends, which loses
// the motion there (8 periods of each band left out: 6.7 Hz, 2.6 times).
void expectNearTheOracle(const Recording& r) {
  jle::ZeroPhaseConfig config;
  config.rule = jle::CutoffRule::kSpectrum;
  const double cutoff = jle::chooseCutoff(r.t, r.q, config);
  const Oracle best = oracleOf(r);
  const double error = effortError(r, effortsAt(r, cutoff));
  EXPECT_LE(error, 1.3 * best.error)
      << "chosen " << cutoff << " Hz, best " << best.cutoff << " Hz (" << best.error << " N m)";
}

TEST(QuietEncoders, SlowSinesChooseNearTheBestFixedCutoff) {
  expectNearTheOracle(record(jle::MotionKind::kSines, encoders(1000.0), 10.0));
}

TEST(QuietEncoders, StopAndGoAt4kHzChoosesNearTheBestFixedCutoff) {
  expectNearTheOracle(record(jle::MotionKind::kStopAndGo, encoders(4000.0), 5.0));
}

// The wrench columns that the positions' cutoff filters alike (checkFilteredAlike): a
// contact force of heel strikes (8 ms rise into a 0.25 s half sine, 1500 N, 0.5 N of
// noise, 1 kHz) carries content far above a 5 Hz choice, and is warned about; a slow F/T
// wrench (0.1 .. 1 Hz sines, 0.1 N of noise) is not; a fixed cutoff is not checked.
TEST(FilteredAlike, WarnsWhereTheWrenchesCarryContentAboveTheCutoff) {
  jle::WrenchMotion strikes, slow;
  for (double start : {0.7, 1.9, 3.1, 4.3}) {
    jle::Stance s;
    s.start = start;
    s.rise = 0.008;
    s.duration = 0.25;
    s.peak << 150.0, 0.0, 1500.0, 0.0, 60.0, 0.0;
    strikes.stances.push_back(s);
  }
  slow.mean << 5.0, -3.0, -15.0, 0.2, -0.1, 0.05;
  slow.amplitude << 5.0, 2.0, 8.0, 0.3, 0.5, 0.1;
  slow.omega << 0.7, 1.9, 3.3, 4.4, 5.8, 6.2;
  jle::PortableRandom random(5);
  std::vector<double> t;
  Eigen::MatrixXd f_strikes(6000, 6), f_slow(6000, 6);
  for (Eigen::Index k = 0; k < 6000; ++k) {
    t.push_back(1e-3 * static_cast<double>(k));
    f_strikes.row(k) = strikes.at(t.back()).transpose();
    f_slow.row(k) = slow.at(t.back()).transpose();
    for (Eigen::Index c = 0; c < 6; ++c) {
      f_strikes(k, c) += 0.5 * random.gaussian();
      f_slow(k, c) += 0.1 * random.gaussian();
    }
  }
  jle::CutoffChoice choice;
  choice.rule = jle::CutoffRule::kSpectrum;
  choice.cutoff = 5.0;
  const jle::ZeroPhaseConfig config;
  const double f = jle::checkFilteredAlike(t, f_strikes, config, "the contact", choice);
  EXPECT_GT(f, jle::kCutoffDisagreement * 5.0);
  ASSERT_EQ(choice.warnings.size(), 1u);
  EXPECT_NE(choice.warnings.front().find("zero-phase cutoff: the contact: its own spectrum"),
            std::string::npos)
      << choice.warnings.front();
  std::printf("heel strikes: %.3g Hz; %s\n", f, choice.warnings.front().c_str());
  choice.warnings.clear();
  const double g = jle::checkFilteredAlike(t, f_slow, config, "the F/T sensor", choice);
  EXPECT_LT(g, jle::kCutoffDisagreement * 5.0);
  EXPECT_TRUE(choice.warnings.empty()) << choice.warnings.front();
  std::printf("slow wrench: %.3g Hz\n", g);
  choice.rule = jle::CutoffRule::kFixed;
  EXPECT_EQ(jle::checkFilteredAlike(t, f_strikes, config, "the contact", choice), 0.0);
  EXPECT_TRUE(choice.warnings.empty());
}

// A gait-like record, as the accuracy study's leg_gait_70hz: the planar leg's swings
// ending in heel strikes (seed 41), its positions at 70 Hz with 2e-3 rad of noise flat to
// 15 Hz (motion capture; no velocities), the foot's contact force at 1 kHz with 0.5 N and
// 0.02 N m of noise: an 8 ms rise at each strike into a 0.25 s half sine of (150, 1500) N
// and 60 N m.
struct Gait {
  std::unique_ptr<jle::GroundTruth> truth;
  std::vector<double> t, t_force;  // [s] the positions' and the force's stamps
  Eigen::MatrixXd q, force;        // samples x 3, samples x (force, moment)
  Eigen::MatrixXd true_effort;     // samples x 3, at t
};

// The gait with its positions read at `rate` [Hz] (70: the study's).
Gait gaitRecord(double rate) {
  constexpr double duration = 10.0;
  const jle::Model<double> model = jle::modelFromUrdfString(jle::planarLegUrdf());
  const std::vector<jle::CoordinateMotion> motion =
      jle::randomMotion(model, jle::MotionKind::kImpacts, duration, 41);
  jle::WrenchMotion contact;
  contact.link = "foot";
  const std::vector<jle::AccelPulse>& pulses = motion.front().pulses;
  for (std::size_t p = 1; p < pulses.size(); p += 2) {
    jle::Stance s;
    s.start = pulses[p].start;
    s.rise = 0.008;
    s.duration = 0.25;
    s.peak << 150.0, 0.0, 1500.0, 0.0, 60.0, 0.0;
    contact.stances.push_back(s);
  }
  jle::SensorModel sensor;
  sensor.rate = rate;
  sensor.coloured_noise = 2e-3;
  sensor.coloured_corner = 15.0;
  sensor.wrench_rate = 1000.0;
  sensor.force_noise = 0.5;
  sensor.moment_noise = 0.02;
  Gait r;
  r.truth =
      std::make_unique<jle::GroundTruth>(model, motion, std::vector<jle::WrenchMotion>{contact});
  const jle::SensorReadings readings = r.truth->sample(sensor, duration, 42);
  const auto n = static_cast<Eigen::Index>(readings.joints.size());
  r.q.resize(n, model.nq);
  r.true_effort.resize(n, 3);
  jle::Data<double> data(model);
  for (Eigen::Index k = 0; k < n; ++k) {
    const jle::JointReading& reading = readings.joints[static_cast<std::size_t>(k)];
    r.t.push_back(reading.time);
    r.q.row(k) = reading.q.transpose();
    r.truth->loads(reading.time, data);
    for (Eigen::Index j = 0; j < 3; ++j)
      r.true_effort(k, j) = data.effort[model.moving_segments[static_cast<std::size_t>(j)]];
  }
  r.force.resize(static_cast<Eigen::Index>(readings.wrenches.size()), 6);
  for (std::size_t k = 0; k < readings.wrenches.size(); ++k) {
    const jle::WrenchReading& w = readings.wrenches[k];
    r.t_force.push_back(w.stamp);
    r.force.row(static_cast<Eigen::Index>(k)) << w.force.transpose(), w.moment.transpose();
  }
  return r;
}

const Gait& gait() {
  static const Gait g = gaitRecord(70.0);
  return g;
}

// The gait's effort error (RMS over the joints and the samples kSettle or more from the
// ends) with the positions and the contact force both filtered at `cutoff` [Hz] (the force
// interpolated linearly to the positions' stamps), through the core's inverse dynamics.
double gaitError(double cutoff) {
  const Gait& g = gait();
  jle::ZeroPhaseConfig config;
  config.rule = jle::CutoffRule::kFixed;
  config.cutoff = cutoff;
  const jle::ZeroPhaseResult zp = jle::smoothZeroPhase(g.t, g.q, config);
  const Eigen::MatrixXd f = jle::lowPassZeroPhase(g.t_force, g.force, cutoff, config.order);
  const jle::Model<double>& model = g.truth->model();
  const int foot = model.frameIndex("foot");
  jle::Data<double> data(model);
  double sum = 0.0;
  long count = 0;
  for (Eigen::Index k = 0; k < g.q.rows(); ++k) {
    const double t = g.t[static_cast<std::size_t>(k)];
    if (t < kSettle || t > g.t.back() - kSettle) continue;
    const auto after = std::upper_bound(g.t_force.begin(), g.t_force.end(), t) - g.t_force.begin();
    const Eigen::Index b = std::min<Eigen::Index>(after, f.rows() - 1), a = b - 1;
    const double u =
        (t - g.t_force[static_cast<std::size_t>(a)]) /
        (g.t_force[static_cast<std::size_t>(b)] - g.t_force[static_cast<std::size_t>(a)]);
    const Eigen::Matrix<double, 1, 6> w = (1.0 - u) * f.row(a) + u * f.row(b);
    jle::forwardKinematics(model, data, jle::VectorX<double>(zp.value.row(k).transpose()),
                           jle::VectorX<double>(zp.rate.row(k).transpose()),
                           jle::VectorX<double>(zp.accel.row(k).transpose()), g.truth->gravity());
    jle::addExternalWrench(model, data, foot, Eigen::Vector3d(w.head<3>().transpose()),
                           Eigen::Vector3d(w.tail<3>().transpose()), jle::WrenchFrame::kLocal);
    jle::inverseDynamics(model, data);
    for (Eigen::Index j = 0; j < 3; ++j) {
      const double e =
          data.effort[model.moving_segments[static_cast<std::size_t>(j)]] - g.true_effort(k, j);
      sum += e * e;
      ++count;
    }
  }
  return std::sqrt(sum / static_cast<double>(count));
}

// The default rule on the gait, given the contact force as the channels filtered alike:
// its cutoff lies in the range where the loads' error is within 1.3 times the best fixed
// cutoff's (scanned here from 1 Hz at ratio 1.1 to 0.4 of the 70 Hz, against the truth),
// the bound of issue 37. The positions alone (their noise spectrum) choose below that
// range, where the force filtered alike loses its heel strikes; the force raises the
// choice, and the choice says so and that the force still carries content above it.
TEST(FilteredAlike, AGaitRecordsContactForceRaisesTheCutoffIntoTheBestRange) {
  const Gait& g = gait();
  std::vector<std::pair<double, double>> scan;  // (cutoff [Hz], effort error [N m])
  double best = std::numeric_limits<double>::infinity();
  for (double f = 1.0; f <= 28.0; f *= 1.1) {
    scan.emplace_back(f, gaitError(f));
    best = std::min(best, scan.back().second);
  }
  double lowest = 0.0, highest = 0.0;  // the scanned cutoffs within 1.3 times the best
  for (const auto& [f, e] : scan)
    if (e <= 1.3 * best) highest = f, lowest = lowest > 0.0 ? lowest : f;
  const jle::ZeroPhaseConfig config;
  const jle::CutoffChoice own = jle::selectCutoff(g.t, g.q, config);
  const jle::CutoffChoice choice =
      jle::selectCutoff(g.t, g.q, config, Eigen::MatrixXd(), {{g.t_force, g.force, "the contact"}});
  std::printf(
      "gait: within 1.3x of the best (%.3g N m) from %.3g to %.3g Hz; positions alone "
      "%.3g Hz (%.3g N m), with the contact force %.3g Hz (%.3g N m)\n",
      best, lowest, highest, own.cutoff, gaitError(own.cutoff), choice.cutoff,
      gaitError(choice.cutoff));
  EXPECT_LE(gaitError(choice.cutoff), 1.3 * best);
  EXPECT_GE(choice.cutoff, lowest / 1.1);  // between two scanned cutoffs within the range
  EXPECT_LE(choice.cutoff, highest * 1.1);
  EXPECT_GT(gaitError(own.cutoff), 1.3 * best) << own.cutoff << " Hz";
  EXPECT_EQ(choice.rule, jle::CutoffRule::kSpectrum);
  EXPECT_EQ(choice.positions_cutoff, own.cutoff);
  const auto said = [&](const std::string& what) {
    return std::any_of(choice.warnings.begin(), choice.warnings.end(),
                       [&](const std::string& w) { return w.find(what) != std::string::npos; });
  };
  EXPECT_TRUE(said("raised from the")) << choice.warnings.size() << " warnings";
  EXPECT_TRUE(said("the contact: its own spectrum meets its noise floor"));
}

// A slow F/T wrench (0.1 .. 1 Hz sines, 0.1 N of noise) filtered alike carries nothing
// above the coloured arm's cutoff: the choice is the positions' own, and nothing is said.
TEST(FilteredAlike, ASlowWrenchLeavesThePositionsCutoff) {
  jle::WrenchMotion slow;
  slow.mean << 5.0, -3.0, -15.0, 0.2, -0.1, 0.05;
  slow.amplitude << 5.0, 2.0, 8.0, 0.3, 0.5, 0.1;
  slow.omega << 0.7, 1.9, 3.3, 4.4, 5.8, 6.2;
  jle::PortableRandom random(6);
  const Recording& r = coloured();
  Eigen::MatrixXd f(r.q.rows(), 6);
  for (Eigen::Index k = 0; k < f.rows(); ++k) {
    f.row(k) = slow.at(r.t[static_cast<std::size_t>(k)]).transpose();
    for (Eigen::Index c = 0; c < 6; ++c) f(k, c) += 0.1 * random.gaussian();
  }
  jle::ZeroPhaseConfig config;
  config.rule = jle::CutoffRule::kSpectrum;
  const jle::CutoffChoice own = jle::selectCutoff(r.t, r.q, config);
  const jle::CutoffChoice choice =
      jle::selectCutoff(r.t, r.q, config, Eigen::MatrixXd(), {{r.t, f, "the F/T sensor"}});
  EXPECT_EQ(choice.cutoff, own.cutoff);
  EXPECT_EQ(choice.positions_cutoff, own.cutoff);
  EXPECT_EQ(choice.warnings, own.warnings);
}

class JointLoadsColoured : public jle_test::ToolTest {
 protected:
  JointLoadsColoured() : ToolTest("jle_coloured") {}

  // The recording as a joint_loads CSV: t, every J.q, and every J.qd if `velocities`.
  void writeCsv(const std::string& name, const Recording& r, bool velocities) const {
    const std::vector<std::string>& names = r.truth->model().coordinate_names;
    std::string text = "t";
    for (const std::string& j : names) text += "," + j + ".q";
    if (velocities)
      for (const std::string& j : names) text += "," + j + ".qd";
    text += "\n";
    char cell[40];
    for (Eigen::Index k = 0; k < r.q.rows(); ++k) {
      std::snprintf(cell, sizeof cell, "%.17g", r.t[static_cast<std::size_t>(k)]);
      text += cell;
      for (Eigen::Index c = 0; c < r.q.cols(); ++c) {
        std::snprintf(cell, sizeof cell, ",%.17g", r.q(k, c));
        text += cell;
      }
      for (Eigen::Index c = 0; velocities && c < r.qd.cols(); ++c) {
        std::snprintf(cell, sizeof cell, ",%.17g", r.qd(k, c));
        text += cell;
      }
      text += "\n";
    }
    write(name, text);
  }

  // joint_loads on the CSV; its efforts (samples x moving joints) and standard error.
  Eigen::MatrixXd efforts(const Recording& r, const std::string& csv,
                          const std::vector<std::string>& extra, std::string& err) const {
    std::vector<std::string> args{"--urdf", kPandaChain, "--input", path(csv)};
    args.insert(args.end(), extra.begin(), extra.end());
    const jle_test::Result result = run(JLE_JOINT_LOADS, args);
    err = result.err;
    EXPECT_EQ(result.status, 0) << result.err;
    const jle_test::Table table = jle_test::parseCsv(result.out);
    Eigen::MatrixXd effort(static_cast<Eigen::Index>(table.rows.size()),
                           static_cast<Eigen::Index>(r.joint.size()));
    for (std::size_t k = 0; k < table.rows.size(); ++k)
      for (std::size_t j = 0; j < r.joint.size(); ++j)
        effort(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) =
            table.number(k, r.joint[j] + ".effort");
    return effort;
  }

  // The cutoff [Hz] that joint_loads printed.
  static double printedCutoff(const std::string& err) {
    const std::size_t at = err.find("cutoff ");
    return at == std::string::npos ? std::nan("") : std::strtod(err.c_str() + at + 7, nullptr);
  }
};

// The bounds a positions-only choice must meet: its cutoff within a factor of 1.5 of the
// oracle's, its loads within 1.3 times the oracle's error (issue 37's bound). Measured:
// 4.53 Hz and 0.0735 N m against the oracle's 5.05 Hz and 0.0696 N m (1.06x); GCV 50 Hz
// and 10.4 N m (149x).
::testing::AssertionResult withinTheBounds(double cutoff, double error) {
  const bool near = std::abs(std::log(cutoff / oracle().cutoff)) <= std::log(1.5);
  if (near && error <= 1.3 * oracle().error) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "chose " << cutoff << " Hz, " << error << " N m; oracle "
                                       << oracle().cutoff << " Hz, " << oracle().error << " N m";
}

// Positions only, the default rule: within the bounds, the rule printed. The same bounds
// fail the white-noise rule (GCV, --cutoff-rule gcv), which takes the noise flat to 50 Hz
// for motion and climbs to the search's bound: the bounds tell a sound choice from it.
TEST_F(JointLoadsColoured, PositionsOnlyChoosesASaneCutoffAndBoundedLoads) {
  const Recording& r = coloured();
  writeCsv("q.csv", r, false);
  std::string err;
  const Eigen::MatrixXd effort = efforts(r, "q.csv", {}, err);
  ASSERT_EQ(effort.rows(), r.q.rows()) << err;
  EXPECT_NE(err.find("(noise spectrum)"), std::string::npos) << err;
  EXPECT_TRUE(withinTheBounds(printedCutoff(err), effortError(r, effort))) << err;
  std::printf("joint_loads, positions only: %.3g Hz, %.3g N m; oracle %.3g Hz, %.3g N m\n",
              printedCutoff(err), effortError(r, effort), oracle().cutoff, oracle().error);
  const Eigen::MatrixXd gcv = efforts(r, "q.csv", {"--cutoff-rule", "gcv"}, err);
  ASSERT_EQ(gcv.rows(), r.q.rows()) << err;
  EXPECT_FALSE(withinTheBounds(printedCutoff(err), effortError(r, gcv))) << err;
  std::printf("joint_loads --cutoff-rule gcv: %.3g Hz, %.3g N m\n", printedCutoff(err),
              effortError(r, gcv));
}

// With J.qd columns: the velocity evidence chooses, and says so.
TEST_F(JointLoadsColoured, MeasuredVelocitiesGuideTheCutoff) {
  const Recording& r = coloured();
  writeCsv("qqd.csv", r, true);
  std::string err;
  const Eigen::MatrixXd effort = efforts(r, "qqd.csv", {}, err);
  ASSERT_EQ(effort.rows(), r.q.rows()) << err;
  EXPECT_NE(err.find("(velocity evidence)"), std::string::npos) << err;
  EXPECT_LT(effortError(r, effort), 1.3 * oracle().error) << err;
}

// GCV asked for on coloured noise: it climbs to the search's upper bound, and joint_loads
// warns (the bound, and the noise spectrum's far lower choice).
TEST_F(JointLoadsColoured, WarnsWhenTheChoiceSitsOnABound) {
  writeCsv("q.csv", coloured(), false);
  std::string err;
  efforts(coloured(), "q.csv", {"--cutoff-rule", "gcv"}, err);
  EXPECT_NE(err.find("joint_loads: warning: zero-phase cutoff: 50 Hz (generalised "
                     "cross-validation) is on the search's highest bound"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("joint_loads: warning: zero-phase cutoff: noise spectrum chooses"),
            std::string::npos)
      << err;
  // Exact positions: no noise floor for the spectrum to find; its choice is the bound.
  const Recording exact = record(false);
  writeCsv("exact.csv", exact, false);
  efforts(exact, "exact.csv", {}, err);
  EXPECT_NE(err.find("joint_loads: warning: zero-phase cutoff: 50 Hz (noise spectrum) is on "
                     "the search's highest bound"),
            std::string::npos)
      << err;
  // A given cutoff: nothing to warn about.
  efforts(coloured(), "q.csv", {"--cutoff", "5"}, err);
  EXPECT_EQ(err.find("warning"), std::string::npos) << err;
}

// The gait as a joint_loads CSV, positions and contact force both at 1 kHz on the same rows
// (a motion-capture export at the force plate's rate; the positions' noise still flat to
// 15 Hz): the wrench columns' own spectrum raises the printed cutoff above the positions'
// own, joint_loads says so, and its loads err less against the truth than at the
// positions' own cutoff (--cutoff).
TEST_F(JointLoadsColoured, TheGaitsContactForceRaisesThePrintedCutoff) {
  const Gait g = gaitRecord(1000.0);
  ASSERT_EQ(g.force.rows(), g.q.rows());
  std::string text = "t";
  for (const std::string& j : g.truth->model().coordinate_names) text += "," + j + ".q";
  for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"})
    text += std::string(",wrench@foot.") + c;
  text += "\n";
  char cell[40];
  for (Eigen::Index k = 0; k < g.q.rows(); ++k) {
    ASSERT_NEAR(g.t_force[static_cast<std::size_t>(k)], g.t[static_cast<std::size_t>(k)], 1e-9);
    std::snprintf(cell, sizeof cell, "%.17g", g.t[static_cast<std::size_t>(k)]);
    text += cell;
    for (Eigen::Index c = 0; c < g.q.cols(); ++c) {
      std::snprintf(cell, sizeof cell, ",%.17g", g.q(k, c));
      text += cell;
    }
    for (Eigen::Index c = 0; c < 6; ++c) {
      std::snprintf(cell, sizeof cell, ",%.17g", g.force(k, c));
      text += cell;
    }
    text += "\n";
  }
  write("gait.csv", text);
  write("leg.urdf", jle::planarLegUrdf());
  const auto loads = [&](const std::vector<std::string>& extra, std::string& err) {
    std::vector<std::string> args{"--urdf", path("leg.urdf"), "--input", path("gait.csv")};
    args.insert(args.end(), extra.begin(), extra.end());
    const jle_test::Result result = run(JLE_JOINT_LOADS, args);
    err = result.err;
    EXPECT_EQ(result.status, 0) << result.err;
    const jle_test::Table table = jle_test::parseCsv(result.out);
    const jle::Model<double>& model = g.truth->model();
    double sum = 0.0;
    long count = 0;
    for (std::size_t k = 0; k < table.rows.size(); ++k) {
      const double t = g.t[k];
      if (t < kSettle || t > g.t.back() - kSettle) continue;
      for (Eigen::Index j = 0; j < 3; ++j) {
        const int s = model.moving_segments[static_cast<std::size_t>(j)];
        const double e =
            table.number(k, model.joint_name[static_cast<std::size_t>(s)] + ".effort") -
            g.true_effort(static_cast<Eigen::Index>(k), j);
        sum += e * e;
        ++count;
      }
    }
    return std::sqrt(sum / static_cast<double>(std::max(1L, count)));
  };
  std::string err, err_own;
  const double raised = loads({}, err);
  const jle::CutoffChoice own = jle::selectCutoff(g.t, g.q, jle::ZeroPhaseConfig{});
  char given[32];
  std::snprintf(given, sizeof given, "%.17g", own.cutoff);
  const double at_own = loads({"--cutoff", given}, err_own);
  EXPECT_NE(err.find("joint_loads: warning: zero-phase cutoff: "), std::string::npos) << err;
  char from[48];
  std::snprintf(from, sizeof from, "raised from the %.3g Hz of noise spectrum", own.cutoff);
  EXPECT_NE(err.find(from), std::string::npos) << err;
  EXPECT_GT(printedCutoff(err), 1.5 * own.cutoff) << err;
  EXPECT_LT(raised, at_own) << err;
  std::printf(
      "joint_loads, gait with wrench@foot: %.3g Hz, %.3g N m; at the positions' own "
      "%.3g Hz: %.3g N m\n",
      printedCutoff(err), raised, own.cutoff, at_own);
}

}  // namespace
