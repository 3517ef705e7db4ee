// The covariance's model and workspace (covariance.hpp) on their own: the sweeps of a
// mimic joint, the propagation at rest against closed forms, and the extrapolation of
// uncertainty.period against a quadratic.
#include <joint_load_estimator/estimation/covariance.hpp>
#include <joint_load_estimator/estimation/estimator.hpp>  // UncertaintyConfig
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

using Eigen::Vector3d;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
constexpr double kG = 9.80665;

// A pendulum turning about y at the base origin: a point-like mass m [kg] at (L, 0, 0) of
// its link with inertia iyy [kg m^2] about its centre (about every axis).
std::string pendulum(const std::string& name, double m, double L, double iyy,
                     const std::string& extra) {
  const std::string i = std::to_string(iyy);
  return "<joint name=\"" + name +
         "\" type=\"revolute\"><parent link=\"base\"/><child link=\"arm_" + name +
         "\"/><axis xyz=\"0 1 0\"/>" + extra +
         "<limit lower=\"-3\" upper=\"3\" effort=\"100\" velocity=\"5\"/></joint>" +
         "<link name=\"arm_" + name + "\"><inertial><origin xyz=\"" + std::to_string(L) +
         " 0 0\"/><mass value=\"" + std::to_string(m) + "\"/><inertia ixx=\"" + i +
         "\" ixy=\"0\" ixz=\"0\" iyy=\"" + i + "\" iyz=\"0\" izz=\"" + i + "\"/></inertial></link>";
}

// Two pendulums on a fixed base: a (m 2, L 0.5, Iyy 0.01) and b (m 1, L 0.25, Iyy 0.02),
// which mimics a with multiplier 2.
const std::string kPendulums =
    "<?xml version=\"1.0\"?><robot name=\"mimic_pendulums\"><link name=\"base\"/>" +
    pendulum("a", 2.0, 0.5, 0.01, "") +
    pendulum("b", 1.0, 0.25, 0.02, "<mimic joint=\"a\" multiplier=\"2.0\"/>") + "</robot>";
// Inertia about the joint: Iyy + m L^2.
constexpr double kIa = 0.01 + 2.0 * 0.25, kIb = 0.02 + 1.0 * 0.0625;

std::vector<int> allSegments(const jle::Model<double>& model) {
  std::vector<int> all;
  for (int i = 0; i < model.nsegments(); ++i) all.push_back(i);
  return all;
}

// The covariance at rest at q_a with the noise gain G, for `u` and no wrench input.
struct Rig {
  explicit Rig(const jle::UncertaintyConfig& u, double q_a = 0.0)
      : model(jle::modelFromUrdfString(kPendulums)),
        data(model),
        cm(model, u, {}, {}, allSegments(model), allSegments(model)),
        ws(cm, model.nsegments()) {
    const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, q_a), zero = Eigen::VectorXd::Zero(1);
    jle::forwardKinematics(model, data, q, zero, zero, Vector3d(0.0, 0.0, -kG));
    jle::inverseDynamics(model, data);
  }
  const Matrix6& compute(const Eigen::Matrix3d& G) {
    jle::computeCovariance(cm, ws, model, data, G, 0.0);
    return ws.covariance[0];
  }
  jle::Model<double> model;
  jle::Data<double> data;
  jle::CovarianceModel cm;
  jle::CovarianceWorkspace ws;
};

jle::UncertaintyConfig positionNoise(bool linearize) {
  jle::UncertaintyConfig u;
  u.enabled = true;
  u.position_noise = 1e-3;
  u.linearize_state = linearize;
  u.period = 0.0;
  return u;
}

TEST(CovarianceModel, MimicSweepsBothSubtreesAndTheSegmentAbove) {
  const Rig rig(positionNoise(true));
  const int a = rig.model.segmentOfJoint("a"), b = rig.model.segmentOfJoint("b");
  ASSERT_EQ(rig.model.nq, 1);
  EXPECT_EQ(rig.cm.sweep[0], (std::vector<int>{std::min(a, b), std::max(a, b)}));
  EXPECT_FALSE(rig.cm.single_root[0]);
  EXPECT_EQ(rig.cm.sweep_ancestors[0], std::vector<int>{0});
  EXPECT_EQ(rig.cm.subtree_end[0], 3);
  EXPECT_EQ(rig.cm.subtree_end[a], a + 1);
}

// The q-ddot part alone (linearize_state false): d(moment about y)/d qdd_a of each arm is
// its inertia about the joint (times the multiplier for b), and the base sees their sum:
// var = sigma^2 G22 I^2, with (kIa + 2 kIb) for the base, not kIa^2 + 4 kIb^2.
TEST(CovarianceModel, AccelerationNoiseAtRest) {
  Rig rig(positionNoise(false));
  const Eigen::Matrix3d G = Eigen::Vector3d(0.5, 3.0, 40.0).asDiagonal();
  const Matrix6& base = rig.compute(G);
  const double var = 1e-6 * 40.0;
  const int a = rig.model.segmentOfJoint("a"), b = rig.model.segmentOfJoint("b");
  // Rounding: a few products of numbers of order 1.
  EXPECT_NEAR(rig.ws.covariance[a](4, 4), var * kIa * kIa, 1e-15);
  EXPECT_NEAR(rig.ws.covariance[b](4, 4), var * 4.0 * kIb * kIb, 1e-15);
  EXPECT_NEAR(base(4, 4), var * (kIa + 2.0 * kIb) * (kIa + 2.0 * kIb), 1e-15);
  EXPECT_NEAR(jle::effortVariance(rig.model, rig.ws.covariance[a], a), var * kIa * kIa, 1e-15);
}

// Linearised (G diagonal: q, qd, qdd independent): at rest the velocity terms vanish; the
// gravity moment -m g L cos q about y changes with q by m g L sin q. Arm a at q = 0.5:
// var = sigma^2 (G00 (m g L sin q)^2 + G22 I^2).
TEST(CovarianceModel, PositionNoiseLinearised) {
  Rig rig(positionNoise(true), 0.5);
  const Eigen::Matrix3d G = Eigen::Vector3d(0.5, 3.0, 40.0).asDiagonal();
  rig.compute(G);
  const int a = rig.model.segmentOfJoint("a");
  const double dq = 2.0 * kG * 0.5 * std::sin(0.5);
  const double expected = 1e-6 * (0.5 * dq * dq + 40.0 * kIa * kIa);
  EXPECT_NEAR(rig.ws.covariance[a](4, 4), expected, 1e-14);
}

// The mass alone (exact: the loads are linear in m): at q = 0 arm a's joint wrench is m
// times d = (a_com, c x a_com) with a_com = (0, 0, g) and c = (0.5, 0, 0): the force along
// z and the moment -0.5 m g about y are fully correlated.
TEST(CovarianceModel, MassFractionAtRest) {
  jle::UncertaintyConfig u;
  u.enabled = true;
  u.mass_fraction = 0.1;
  u.period = 0.0;
  Rig rig(u);
  rig.compute(Eigen::Matrix3d::Identity());
  const int a = rig.model.segmentOfJoint("a");
  const double s = 0.1 * 2.0;  // sigma of the mass [kg]
  const Matrix6& C = rig.ws.covariance[a];
  EXPECT_NEAR(C(2, 2), s * s * kG * kG, 1e-12);
  EXPECT_NEAR(C(4, 4), s * s * 0.25 * kG * kG, 1e-12);
  EXPECT_NEAR(C(2, 4), -s * s * 0.5 * kG * kG, 1e-12);
  EXPECT_NEAR(C(0, 0), 0.0, 1e-15);
}

// uncertainty.period: three covariances on the quadratic C(t) = A + B t + D t^2 a period
// apart give C at any t within the next period (the Lagrange quadratic is exact on it),
// up to rounding of ~1e-15 relative on entries of order 1.
jle::CovarianceWorkspace quadraticHistory(const jle::CovarianceModel& cm, double t0, double h) {
  jle::CovarianceWorkspace ws(cm, 3);
  auto C = [](double t) {
    Matrix6 M = Matrix6::Identity() * (1.0 + t + 3.0 * t * t);
    M(0, 1) = M(1, 0) = 0.5 - 2.0 * t + t * t;
    return M;
  };
  ws.prev2.assign(3, C(t0 - 2 * h));
  ws.prev.assign(3, C(t0 - h));
  ws.last.assign(3, C(t0));
  ws.time[0] = t0;
  ws.time[1] = t0 - h;
  ws.time[2] = t0 - 2 * h;
  for (Eigen::Matrix3d& g : ws.gain) g = Eigen::Matrix3d::Identity();
  ws.history = 3;
  return ws;
}

jle::CovarianceModel periodModel(const jle::Model<double>& model) {
  jle::UncertaintyConfig u;
  u.enabled = true;
  u.period = 0.01;
  return jle::CovarianceModel(model, u, {}, {}, allSegments(model), allSegments(model));
}

TEST(CovarianceWorkspace, ExtrapolationIsExactOnAQuadratic) {
  const jle::Model<double> model = jle::modelFromUrdfString(kPendulums);
  const jle::CovarianceModel cm = periodModel(model);
  jle::CovarianceWorkspace ws = quadraticHistory(cm, 2.0, 0.01);
  const double t = 2.007;
  ASSERT_TRUE(jle::extrapolateCovariance(cm, ws, Eigen::Matrix3d::Identity(), t));
  EXPECT_NEAR(ws.covariance[1](0, 0), 1.0 + t + 3.0 * t * t, 1e-12);
  EXPECT_NEAR(ws.covariance[1](0, 1), 0.5 - 2.0 * t + t * t, 1e-12);
  EXPECT_NEAR(ws.covariance[2](5, 5), 1.0 + t + 3.0 * t * t, 1e-12);
}

TEST(CovarianceWorkspace, ComputedAgainAfterAPeriodAGapOrANewGain) {
  const jle::Model<double> model = jle::modelFromUrdfString(kPendulums);
  const jle::CovarianceModel cm = periodModel(model);
  jle::CovarianceWorkspace ws = quadraticHistory(cm, 2.0, 0.01);
  EXPECT_FALSE(
      jle::extrapolateCovariance(cm, ws, Eigen::Matrix3d::Identity(), 2.01));  // a period on
  EXPECT_EQ(ws.history, 3);
  EXPECT_FALSE(jle::extrapolateCovariance(cm, ws, Eigen::Matrix3d::Identity(), 2.05));  // a gap
  EXPECT_EQ(ws.history, 0);
  ws = quadraticHistory(cm, 2.0, 0.01);
  // Default gain_tolerance 0.02: G00 moved by 5% of its standard deviation.
  const Eigen::Matrix3d moved = Eigen::Vector3d(1.05, 1.0, 1.0).asDiagonal();
  EXPECT_FALSE(jle::extrapolateCovariance(cm, ws, moved, 2.005));
  EXPECT_EQ(ws.history, 0);
}

// A variance extrapolated below zero is zero, and its row and column with it.
TEST(CovarianceWorkspace, NegativeVarianceClearsItsRowAndColumn) {
  const jle::Model<double> model = jle::modelFromUrdfString(kPendulums);
  const jle::CovarianceModel cm = periodModel(model);
  jle::CovarianceWorkspace ws = quadraticHistory(cm, 2.0, 0.01);
  // The variance of mx falling by 2 per period to 0 at t0: -1 half a period later.
  for (int i = 0; i < 3; ++i) {
    ws.prev2[i](3, 3) = 4.0;
    ws.prev[i](3, 3) = 2.0;
    ws.last[i](3, 3) = 0.0;
    ws.last[i](3, 0) = ws.last[i](0, 3) = 0.25;
  }
  ASSERT_TRUE(jle::extrapolateCovariance(cm, ws, Eigen::Matrix3d::Identity(), 2.005));
  EXPECT_EQ(ws.covariance[1](3, 3), 0.0);
  EXPECT_EQ(ws.covariance[1](3, 0), 0.0);
  EXPECT_EQ(ws.covariance[1](0, 3), 0.0);
  EXPECT_GT(ws.covariance[1](0, 0), 0.0);
}

}  // namespace
