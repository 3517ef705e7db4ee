// A floating base's channels (base_channels.hpp): the quaternion's sign kept continuous,
// and the pose, twist and acceleration read back from a bank, against a base moving on a
// parabola while turning at a constant rate about a fixed axis.
#include <joint_load_estimator/estimation/base_channels.hpp>
#include <joint_load_estimator/estimation/estimator.hpp>  // BasePose

#include <gtest/gtest.h>

#include <cmath>

namespace {

using Eigen::Vector3d;

// p(t) = p0 + v0 t + a t^2 / 2, orientation exp(w t n) (about the unit axis n at w).
const Vector3d kP0(0.3, -0.2, 1.0), kV0(0.5, 0.1, -0.4), kA(1.0, -2.0, 0.5);
const Vector3d kAxis = Vector3d(1.0, 2.0, 2.0) / 3.0;
constexpr double kRate = 1.5;  // [rad/s]

jle::BasePose poseAt(double t) {
  jle::BasePose pose;
  pose.position = kP0 + kV0 * t + 0.5 * kA * t * t;
  pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kRate * t, kAxis));
  return pose;
}

TEST(BaseChannels, QuaternionSignKeptContinuousAndNormalised) {
  Eigen::Quaterniond last = Eigen::Quaterniond::Identity();
  double plain[7], flipped[7];
  for (int k = 0; k < 8; ++k) {
    jle::BasePose pose = poseAt(0.5 * k);  // 0.75 rad per step, up to 5.25 rad
    Eigen::Quaterniond reference = last;
    jle::writeBasePose(pose, reference, plain);
    pose.orientation.coeffs() *= (k % 2 ? -2.0 : 3.0);  // another sign and scale
    jle::writeBasePose(pose, last, flipped);
    for (int j = 0; j < 7; ++j) EXPECT_NEAR(flipped[j], plain[j], 1e-15) << k << " " << j;
    EXPECT_NEAR(Eigen::Vector4d(plain[3], plain[4], plain[5], plain[6]).norm(), 1.0, 1e-15);
    EXPECT_EQ(plain[0], pose.position.x());
    EXPECT_EQ(plain[2], pose.position.z());
  }
  // Continuous, not made canonical: past pi the quaternion's w = cos(angle / 2) is
  // negative (cos 2.625 = -0.87), as the samples were.
  EXPECT_NEAR(last.w(), std::cos(0.5 * kRate * 3.5), 1e-15);
}

// The centred 3-point difference (delay 1), samples h = 1 ms apart: exact on the
// parabola up to rounding (rate eps |p| / h ~ 1e-13, acceleration eps |p| / h^2 ~ 1e-9).
// The quaternion's components are sinusoids of frequency w / 2: the difference returns
// the rate scaled by sinc(w h / 2) = sin(w h / 2) / (w h / 2), so omega is w n scaled by
// it (1 - 1e-7), and the second difference is a multiple of q itself, so alpha is 0;
// both up to rounding (eps / h, eps / h^2).
TEST(BaseChannels, StateFromTheFilteredChannels) {
  jle::DifferentiatorConfig c;
  c.type = jle::DifferentiatorType::kFiniteDifference;
  c.delay = 1;
  jle::DifferentiatorBank bank(c, 9);
  Eigen::Quaterniond last = Eigen::Quaterniond::Identity();
  double x[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  const double h = 1e-3, t0 = 2.0;
  for (int k = 0; k < 3; ++k) {
    jle::writeBasePose(poseAt(t0 + h * k), last, x + 2);
    bank.update(t0 + h * k, x);
  }
  const double t = bank.stamp();
  ASSERT_NEAR(t, t0 + h, 1e-15);
  const jle::BaseState<double> s = jle::baseStateFromBank(bank, 2);
  EXPECT_NEAR((s.p_world_base - poseAt(t).position).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s.v_world - (kV0 + kA * t)).norm(), 0.0, 1e-10);
  EXPECT_NEAR((s.a_world - kA).norm(), 0.0, 1e-8);
  EXPECT_NEAR((s.R_world_base - poseAt(t).orientation.toRotationMatrix()).norm(), 0.0, 1e-12);
  const double sinc = std::sin(0.5 * kRate * h) / (0.5 * kRate * h);
  EXPECT_NEAR((s.omega_world - sinc * kRate * kAxis).norm(), 0.0, 1e-11);
  EXPECT_NEAR(s.alpha_world.norm(), 0.0, 1e-9);
}

}  // namespace
