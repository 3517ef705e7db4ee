// Frames rigid to a segment (frames.hpp): a wrench carried from a frame to its link
// against a transform worked by hand, the round trip through its inverse, and the pose
// of a URDF frame in a link across fixed joints of wrist_sensor_arm.urdf.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <joint_load_estimator/model/frames.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <random>
#include <stdexcept>

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

const std::string kUrdf = std::string(JLE_TEST_DATA) + "/urdf/wrist_sensor_arm.urdf";
// A handful of products and sums of numbers of order 1 (and cos(pi/2) ~ 6e-17).
constexpr double kExact = 1e-14;

Matrix3d rotation(double angle, const Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// F turned by +90 deg about L's z and its origin at (1, 2, 3) in L. A force (1, 0, 0)
// and a moment (0, 0, 1) in F: F's x is L's y, so the force is (0, 1, 0) in L; about
// L's origin the moment gains p x f = (1, 2, 3) x (0, 1, 0) = (-3, 0, 1), so (-3, 0, 2).
TEST(WrenchInLink, AgainstATransformWorkedByHand) {
  const Matrix3d R = rotation(M_PI / 2, Vector3d::UnitZ());
  const Vector3d p(1.0, 2.0, 3.0);
  Vector3d f, m;
  jle::wrenchInLink(R, p, Vector3d(1.0, 0.0, 0.0), Vector3d(0.0, 0.0, 1.0), f, m);
  EXPECT_LT((f - Vector3d(0.0, 1.0, 0.0)).norm(), kExact) << f.transpose();
  EXPECT_LT((m - Vector3d(-3.0, 0.0, 2.0)).norm(), kExact) << m.transpose();

  // And back: the same wrench in F.
  Vector3d f_frame, m_frame;
  jle::wrenchInFrame(R, p, f, m, f_frame, m_frame);
  EXPECT_LT((f_frame - Vector3d(1.0, 0.0, 0.0)).norm(), kExact);
  EXPECT_LT((m_frame - Vector3d(0.0, 0.0, 1.0)).norm(), kExact);
}

// The power of a wrench on a rigid motion does not depend on the frame: a twist (v at
// L's origin, w) seen from F is (R^T (v + w x p), R^T w), and f.v + m.w must agree.
TEST(WrenchInLink, RoundTripAndFrameFreePower) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random3 = [&] { return Vector3d(u(rng), u(rng), u(rng)); };
  for (int trial = 0; trial < 100; ++trial) {
    const Matrix3d R = rotation(3.0 * u(rng), random3());
    const Vector3d p = 2.0 * random3(), f_frame = 10.0 * random3(), m_frame = random3();
    Vector3d f_link, m_link, f_back, m_back;
    jle::wrenchInLink(R, p, f_frame, m_frame, f_link, m_link);
    jle::wrenchInFrame(R, p, f_link, m_link, f_back, m_back);
    // Loads of order 10 N, lever arms of order 2 m: ~30 rounded operations.
    EXPECT_LT((f_back - f_frame).norm(), 1e-13) << "trial " << trial;
    EXPECT_LT((m_back - m_frame).norm(), 1e-13) << "trial " << trial;

    const Vector3d v_link = random3(), w = random3();
    const Vector3d v_frame = R.transpose() * (v_link + w.cross(p)), w_frame = R.transpose() * w;
    EXPECT_NEAR(f_link.dot(v_link) + m_link.dot(w), f_frame.dot(v_frame) + m_frame.dot(w_frame),
                1e-12)
        << "trial " << trial;
  }
}

// link2 -> ft_joint (fixed, at (0.3, 0, 0), turned +90 deg about y) -> ft_sensor ->
// tool_joint (fixed, (0, 0, 0.05)) -> tool -> tip_joint (fixed, (0, 0, 0.15)) -> tool_tip.
// Lumped (the default), all four links ride on j2's segment.
TEST(RigidFrameInLink, AcrossLumpedFixedJoints) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kUrdf);
  const Matrix3d Ry = rotation(M_PI / 2, Vector3d::UnitY());
  Matrix3d R;
  Vector3d p;
  ASSERT_TRUE(jle::rigidFrameInLink(model, "link2", "ft_sensor", R, p));
  EXPECT_LT((R - Ry).norm(), kExact);
  EXPECT_LT((p - Vector3d(0.3, 0.0, 0.0)).norm(), kExact);

  // The tip 0.2 m along the sensor's z, which is link2's x.
  ASSERT_TRUE(jle::rigidFrameInLink(model, "link2", "tool_tip", R, p));
  EXPECT_LT((R - Ry).norm(), kExact);
  EXPECT_LT((p - Vector3d(0.5, 0.0, 0.0)).norm(), kExact) << p.transpose();

  // Seen from the tip: the inverse pose.
  ASSERT_TRUE(jle::rigidFrameInLink(model, "tool_tip", "link2", R, p));
  EXPECT_LT((R - Ry.transpose()).norm(), kExact);
  EXPECT_LT((p - Vector3d(0.0, 0.0, -0.5)).norm(), kExact) << p.transpose();

  ASSERT_TRUE(jle::rigidFrameInLink(model, "ft_sensor", "tool_tip", R, p));
  EXPECT_LT((R - Matrix3d::Identity()).norm(), kExact);
  EXPECT_LT((p - Vector3d(0.0, 0.0, 0.2)).norm(), kExact);
}

TEST(RigidFrameInLink, MovingOrUnknownFrames) {
  jle::ModelOptions options;
  options.keep_fixed_joints = {"ft_joint"};  // ft_sensor gets its own segment
  const jle::Model<double> model = jle::modelFromUrdfFile(kUrdf, options);
  Matrix3d R = Matrix3d::Zero();
  Vector3d p = Vector3d::Zero();
  EXPECT_FALSE(jle::rigidFrameInLink(model, "link1", "link2", R, p));   // j2 moves
  EXPECT_FALSE(jle::rigidFrameInLink(model, "link2", "tool", R, p));    // another segment
  EXPECT_FALSE(jle::rigidFrameInLink(model, "link2", "camera", R, p));  // no such link
  EXPECT_EQ(R, Matrix3d::Zero());                                       // left unchanged
  ASSERT_TRUE(jle::rigidFrameInLink(model, "ft_sensor", "tool_tip", R, p));
  EXPECT_LT((p - Vector3d(0.0, 0.0, 0.2)).norm(), kExact);
  try {
    jle::rigidFrameInLink(model, "gripper", "tool", R, p);
    ADD_FAILURE() << "an unknown link was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'gripper'"), std::string::npos) << e.what();
  }
}

}  // namespace
