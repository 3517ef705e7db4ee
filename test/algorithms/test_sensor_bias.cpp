// A sensor's residual as it reports it and the estimate of its bias (sensor_bias.hpp):
// the re-expression against a closed form, the offset of a simulated biased sensor for
// either sign, Welford's mean and spread against a two-pass computation, and the
// refusals (not still, stale sensor) with their messages.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <joint_load_estimator/estimation/sensor_bias.hpp>
#include <joint_load_estimator/model/frames.hpp>
#include <stdexcept>
#include <vector>

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using Vector6 = jle::BiasEstimator::Vector6;

// A few products of numbers of order 10.
constexpr double kExact = 1e-13;

Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Vector3d::UnitZ()).toRotationMatrix(); }

// The sensor frame S turned by theta about the link's z, its origin d up the z axis.
// A residual force F along the link's x through the link origin and a moment M0 about
// z: in S the force is F (cos, -sin, 0); about S's origin (below it by d) the force's
// moment is (-p) x f = (0, -d F, 0) in the link, (-d F sin, -d F cos, 0) in S.
TEST(ResidualInReading, AgainstAClosedForm) {
  const double theta = 0.7, d = 0.35, F = 12.0, M0 = -1.5;
  jle::Wrench<double> r_link;
  r_link.force = Vector3d(F, 0.0, 0.0);
  r_link.moment = Vector3d(0.0, 0.0, M0);
  const jle::Wrench<double> r = jle::residualInReading(r_link, Rz(theta), Vector3d(0.0, 0.0, d));
  const double c = std::cos(theta), s = std::sin(theta);
  EXPECT_LT((r.force - Vector3d(F * c, -F * s, 0.0)).norm(), kExact) << r.force.transpose();
  EXPECT_LT((r.moment - Vector3d(-d * F * s, -d * F * c, M0)).norm(), kExact)
      << r.moment.transpose();
}

// A sensor with bias b reads b + sign * P (P: the prediction, reading frame). The node
// subtracts its current estimate b0 and hands sign * (reading - b0), carried to the
// link, to the estimator; the residual is that minus the prediction. The offset it
// implies is the true bias, whatever b0 and the sign.
TEST(ReadingOffset, RecoversTheBiasOfASimulatedSensor) {
  const Matrix3d R =
      Eigen::AngleAxisd(1.1, Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  const Vector3d p(0.1, -0.2, 0.3);
  const Vector3d P_f(1.0, -7.8, 2.5), P_m(0.3, 0.1, -0.2);  // prediction [N, N m]
  jle::SensorBias b, b0;
  b.force = Vector3d(0.7, -0.4, 1.2);
  b.torque = Vector3d(0.05, -0.03, 0.02);
  b0.force = Vector3d(0.2, 0.1, -0.3);
  b0.torque = Vector3d(-0.01, 0.0, 0.04);
  for (double sign : {1.0, -1.0}) {
    const Vector3d reading_f = b.force + sign * P_f, reading_m = b.torque + sign * P_m;
    Vector3d meas_f, meas_m, pred_f, pred_m;
    jle::wrenchInLink(R, p, sign * (reading_f - b0.force), sign * (reading_m - b0.torque), meas_f,
                      meas_m);
    jle::wrenchInLink(R, p, P_f, P_m, pred_f, pred_m);
    jle::Wrench<double> r_link;
    r_link.force = meas_f - pred_f;
    r_link.moment = meas_m - pred_m;
    const Vector6 x = jle::readingOffset(jle::residualInReading(r_link, R, p), sign, b0);
    EXPECT_LT((x.head<3>() - b.force).norm(), kExact) << "sign " << sign;
    EXPECT_LT((x.tail<3>() - b.torque).norm(), kExact) << "sign " << sign;
  }
}

Vector6 sampleOf(int sensor, int j) {
  Vector6 x;
  // Large offsets with small spread: a naive sum of squares would lose digits.
  for (int i = 0; i < 6; ++i)
    x[i] = 1000.0 * (sensor + 1) + i + 0.1 * std::sin(1.3 * j + 0.7 * i + sensor);
  return x;
}

// 7 samples stamped 0.25 s apart fill a window of 1.5 s (exact binary fractions).
TEST(BiasEstimator, WelfordAgainstTwoPass) {
  jle::BiasEstimator bias({"left", "right"}, {"j1", "j2"});
  EXPECT_FALSE(bias.collecting());
  bias.start(1.5, false, 0.02);
  const VectorXd qd = VectorXd::Zero(2);
  const std::vector<char> needed{1, 1};
  std::vector<jle::BiasSample> sample(2);
  const int n = 7;
  for (int j = 0; j < n; ++j) {
    EXPECT_FALSE(bias.done());
    for (int k = 0; k < 2; ++k) sample[static_cast<std::size_t>(k)] = {true, sampleOf(k, j)};
    EXPECT_TRUE(bias.add(0.25 * j + 10.0, sample, qd, needed)) << "sample " << j;
  }
  EXPECT_TRUE(bias.done());
  EXPECT_FALSE(bias.collecting());
  EXPECT_TRUE(bias.failure().empty());
  EXPECT_EQ(bias.samples(), n);
  EXPECT_FALSE(bias.add(12.0, sample, qd, needed));  // full: not taken
  EXPECT_EQ(bias.samples(), n);
  for (int k = 0; k < 2; ++k) {
    Vector6 mean = Vector6::Zero(), var = Vector6::Zero();
    for (int j = 0; j < n; ++j) mean += sampleOf(k, j);
    mean /= n;
    for (int j = 0; j < n; ++j) var += (sampleOf(k, j) - mean).cwiseAbs2();
    var /= n - 1;
    const jle::SensorBias m = bias.mean(static_cast<std::size_t>(k));
    const jle::SensorBias s = bias.stddev(static_cast<std::size_t>(k));
    // Means of ~2000 (ulp 2.3e-13) after 7 rounded updates: measured 6e-13. Spreads of
    // ~0.07 from deviations rounded at ~2e-13: measured 9e-14.
    EXPECT_LT((m.force - mean.head<3>()).norm(), 1e-11) << "sensor " << k;
    EXPECT_LT((m.torque - mean.tail<3>()).norm(), 1e-11) << "sensor " << k;
    EXPECT_LT((s.force - var.head<3>().cwiseSqrt()).norm(), 1e-12) << "sensor " << k;
    EXPECT_LT((s.torque - var.tail<3>().cwiseSqrt()).norm(), 1e-12) << "sensor " << k;
  }
}

TEST(BiasEstimator, OneSampleHasNoSpread) {
  jle::BiasEstimator bias({"ft_joint"}, {"j1"});
  bias.start(0.0001, true, 0.02);
  ASSERT_TRUE(bias.add(3.0, {{true, sampleOf(0, 0)}}, VectorXd::Zero(1), {1}));
  EXPECT_FALSE(bias.done());  // one stamp spans no time
  EXPECT_EQ(bias.stddev(0).force, Vector3d::Zero());
  EXPECT_EQ(bias.stddev(0).torque, Vector3d::Zero());
  EXPECT_EQ(bias.mean(0).force, sampleOf(0, 0).head<3>());
}

TEST(BiasEstimator, NotStillNamesTheJoint) {
  jle::BiasEstimator bias({"ft_joint"}, {"j1", "j2"});
  const std::vector<jle::BiasSample> sample{{true, sampleOf(0, 0)}};
  bias.start(1.0, false, 0.02);
  // j2 moves, but the loads do not need it: still enough.
  EXPECT_TRUE(bias.add(0.0, sample, VectorXd((VectorXd(2) << 0.01, 0.5).finished()), {1, 0}));
  EXPECT_FALSE(bias.add(0.1, sample, VectorXd((VectorXd(2) << 0.01, -0.05).finished()), {1, 1}));
  EXPECT_FALSE(bias.collecting());
  EXPECT_FALSE(bias.done());
  EXPECT_EQ(bias.failure(),
            "the robot is not still: the estimated velocity of 'j2' is -0.05, above "
            "still_velocity 0.02");
  EXPECT_EQ(bias.samples(), 1);

  // assume_still: the velocities are not looked at.
  bias.start(1.0, true, 0.02);
  EXPECT_TRUE(bias.failure().empty());
  EXPECT_TRUE(bias.add(0.0, sample, VectorXd::Constant(2, 3.0), {1, 1}));
  EXPECT_EQ(bias.samples(), 1);
}

TEST(BiasEstimator, StaleSensorAndOtherFailures) {
  jle::BiasEstimator bias({"left_ft", "right_ft"}, {"j1"});
  const VectorXd qd = VectorXd::Zero(1);
  const std::vector<char> needed{1};
  std::vector<jle::BiasSample> sample{{true, sampleOf(0, 0)}, {false, Vector6::Zero()}};
  EXPECT_FALSE(bias.add(0.0, sample, qd, needed));  // not started
  bias.start(1.0, false, 0.02);
  EXPECT_FALSE(bias.add(0.0, sample, qd, needed));
  EXPECT_EQ(bias.failure(), "sensor 'right_ft' is stale");
  EXPECT_EQ(bias.samples(), 0);

  // Moving and stale: the motion is reported.
  bias.start(1.0, false, 0.02);
  EXPECT_FALSE(bias.add(0.0, sample, VectorXd::Constant(1, 0.1), needed));
  EXPECT_NE(bias.failure().find("not still"), std::string::npos) << bias.failure();

  // fail() ends a collecting window, and only that.
  bias.start(1.0, false, 0.02);
  bias.fail("no samples");
  EXPECT_EQ(bias.failure(), "no samples");
  bias.fail("another reason");
  EXPECT_EQ(bias.failure(), "no samples");
  sample[1].used = true;
  bias.start(0.5, false, 0.02);
  EXPECT_TRUE(bias.add(0.0, sample, qd, needed));
  EXPECT_TRUE(bias.add(0.5, sample, qd, needed));
  EXPECT_TRUE(bias.done());
  bias.fail("too late");
  EXPECT_TRUE(bias.failure().empty());
}

TEST(BiasEstimator, RefusesBadArguments) {
  jle::BiasEstimator bias({"ft_joint"}, {"j1", "j2"});
  EXPECT_THROW(bias.start(0.0, true, 0.02), std::invalid_argument);
  EXPECT_THROW(bias.start(NAN, true, 0.02), std::invalid_argument);
  EXPECT_THROW(bias.start(INFINITY, true, 0.02), std::invalid_argument);
  EXPECT_THROW(bias.start(1.0, false, 0.0), std::invalid_argument);
  bias.start(1.0, false, 0.02);
  const std::vector<jle::BiasSample> one{{true, Vector6::Zero()}};
  EXPECT_THROW(bias.add(0.0, {}, VectorXd::Zero(2), {1, 1}), std::invalid_argument);
  EXPECT_THROW(bias.add(0.0, one, VectorXd::Zero(1), {1, 1}), std::invalid_argument);
  EXPECT_THROW(bias.add(0.0, one, VectorXd::Zero(2), {1}), std::invalid_argument);
  EXPECT_TRUE(bias.add(0.0, one, VectorXd::Zero(2), {1, 1}));
}

}  // namespace
