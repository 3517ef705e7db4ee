// Force-plate decoding (force_plate.hpp): every sign convention against numbers worked
// by hand in the comments: what the plate reports (the foot's load on the plate, moment
// about the plate origin) against the reaction the foot receives, the moment about the
// plate origin against the centre of pressure and the free moment, a plate origin below
// the surface, a plate whose own z axis points down, the contact threshold, bad input;
// and the reaction applied to the foot (applyPlateReaction) in double and in float.
#include <joint_load_estimator/model/force_plate.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <string>

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// The numbers below are short decimals combined by a few products and one division:
// they come out within a few ulps of the hand-worked values.
constexpr double kTol = 1e-12;

void expectVector(const Vector3d& actual, const Vector3d& expected, double tol) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(actual[i], expected[i], tol) << "component " << i;
}

// A z-up plate whose origin is on its surface, at the world origin. The foot presses
// 700 N straight down at (0.1, 0.2). The plate reports F = (0, 0, -700) and the moment
// of that force about its origin, r x F with r = (0.1, 0.2, 0):
//   Mx = ry Fz - rz Fy = 0.2 (-700) = -140,  My = rz Fx - rx Fz = -0.1 (-700) = 70,
//   Mz = rx Fy - ry Fx = 0.
TEST(ForcePlate, FootPressingDownDecodesToItsCopAndAnUpwardReaction) {
  jle::ForcePlateConfig plate;
  const jle::PlateReading r =
      jle::readForcePlate(plate, Vector3d(0.0, 0.0, -700.0), Vector3d(-140.0, 70.0, 0.0));
  ASSERT_TRUE(r.contact);
  EXPECT_NEAR(r.normal_force, 700.0, kTol);
  expectVector(r.cop_plate, Vector3d(0.1, 0.2, 0.0), kTol);
  EXPECT_NEAR(r.free_moment, 0.0, kTol);
  // The reaction on the foot is the opposite: 700 N up, moment (140, -70, 0) about the
  // plate origin.
  expectVector(r.force_on_foot_plate, Vector3d(0.0, 0.0, 700.0), kTol);
  expectVector(r.moment_on_foot_plate, Vector3d(140.0, -70.0, 0.0), kTol);
}

// The same foot with a forward shear (the foot pushes the plate 50 N forward) and a free
// moment of 5 N m about +z (the foot twists the plate anticlockwise seen from above).
// Plate moment = r x F + (0, 0, 5) with F = (50, 0, -700), r = (0.1, 0.2, 0):
//   Mx = 0.2 (-700) = -140;  My = 0 * 50 - 0.1 (-700) = 70;  Mz = 0.1 * 0 - 0.2 * 50 + 5 = -5.
// The reaction about the foot's origin p = (0.05, 0.2, 0.08) (above and behind the COP):
//   force (-50, 0, 700) at the COP, (c - p) = (0.05, 0, -0.08),
//   (c - p) x F = (0 * 700 - (-0.08) 0, (-0.08)(-50) - 0.05 * 700, 0.05 * 0 - 0 (-50))
//               = (0, -31, 0), plus the opposite free moment (0, 0, -5).
// About the COP itself only the free moment is left: (0, 0, -5).
TEST(ForcePlate, ShearAndFreeMomentAboutTheFootAndAboutTheCop) {
  jle::ForcePlateConfig plate;
  const jle::PlateReading r =
      jle::readForcePlate(plate, Vector3d(50.0, 0.0, -700.0), Vector3d(-140.0, 70.0, -5.0));
  ASSERT_TRUE(r.contact);
  expectVector(r.cop_plate, Vector3d(0.1, 0.2, 0.0), kTol);
  EXPECT_NEAR(r.free_moment, 5.0, kTol);

  Vector3d force, moment;
  jle::plateReactionInWorld(plate, r, Vector3d(0.05, 0.2, 0.08), force, moment);
  expectVector(force, Vector3d(-50.0, 0.0, 700.0), kTol);
  expectVector(moment, Vector3d(0.0, -31.0, -5.0), kTol);

  jle::plateReactionInWorld(plate, r, Vector3d(0.1, 0.2, 0.0), force, moment);
  expectVector(moment, Vector3d(0.0, 0.0, -5.0), kTol);
}

// A plate whose origin lies 0.04 m below its surface (surface_height = 0.04). The foot
// presses F = (50, 0, -700) at (0.1, 0.2, 0.04). Moment about the origin, r x F:
//   Mx = 0.2 (-700) - 0.04 * 0 = -140;  My = 0.04 * 50 - 0.1 (-700) = 72;
//   Mz = 0.1 * 0 - 0.2 * 50 = -10.
// Decoded: COP x = (h Fx - My) / Fz = (2 - 72) / -700 = 0.1 (a decoder ignoring h would
// say 72 / 700 = 0.10286), y = (Mx + h Fy) / Fz = 0.2; free moment 0.
TEST(ForcePlate, OriginBelowTheSurface) {
  jle::ForcePlateConfig plate;
  plate.surface_height = 0.04;
  const jle::PlateReading r =
      jle::readForcePlate(plate, Vector3d(50.0, 0.0, -700.0), Vector3d(-140.0, 72.0, -10.0));
  ASSERT_TRUE(r.contact);
  expectVector(r.cop_plate, Vector3d(0.1, 0.2, 0.04), kTol);
  EXPECT_NEAR(r.free_moment, 0.0, kTol);
}

// An AMTI-style plate: its own frame D has z pointing down into the plate, and here it
// is also turned 90 deg about the vertical: R_world_D = Rz(pi/2) Rx(pi) =
// [[0,1,0],[1,0,0],[0,0,-1]] (x_D = world y, y_D = world x, z_D = world -z); its origin
// is at world (0.2, 0.3, -0.04), 0.04 m below the surface z = 0. The foot presses 700 N
// down at world (0.3, 0.5, 0). In D: r = R_world_D^T (0.1, 0.2, 0.04) = (0.2, 0.1, -0.04),
// F = (0, 0, 700) (AMTI's Fz is positive under load), M = r x F = (0.1 * 700,
// -0.2 * 700, 0) = (70, -140, 0).
// The plate frame P given to the decoder is D rotated by pi about x (z up):
// v_P = Rx(pi)^T v_D = (vx, -vy, -vz), so F_P = (0, 0, -700), M_P = (70, 140, 0); the
// surface is at z_P = +0.04; R_world_P = R_world_D Rx(pi) = Rz(pi/2).
// Decoded: COP_P = ((0 - 140) / -700, 70 / -700, 0.04) = (0.2, -0.1, 0.04); in the world
// (0.2, 0.3, -0.04) + Rz(pi/2) (0.2, -0.1, 0.04) = (0.2 + 0.1, 0.3 + 0.2, 0) = the COP.
TEST(ForcePlate, PlateWithItsZAxisDownGivesTheSamePhysicalCop) {
  const Vector3d force_D(0.0, 0.0, 700.0), moment_D(70.0, -140.0, 0.0);
  Matrix3d Rx_pi;
  Rx_pi << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  Matrix3d Rz_half_pi;
  Rz_half_pi << 0, -1, 0, 1, 0, 0, 0, 0, 1;

  jle::ForcePlateConfig plate;
  plate.R_world_plate = Rz_half_pi;
  plate.p_world_plate = Vector3d(0.2, 0.3, -0.04);
  plate.surface_height = 0.04;
  const jle::PlateReading r =
      jle::readForcePlate(plate, Rx_pi.transpose() * force_D, Rx_pi.transpose() * moment_D);
  ASSERT_TRUE(r.contact);
  EXPECT_NEAR(r.normal_force, 700.0, kTol);
  expectVector(r.cop_plate, Vector3d(0.2, -0.1, 0.04), kTol);

  // The reaction about the physical COP: 700 N up and no moment.
  Vector3d force, moment;
  jle::plateReactionInWorld(plate, r, Vector3d(0.3, 0.5, 0.0), force, moment);
  expectVector(force, Vector3d(0.0, 0.0, 700.0), kTol);
  expectVector(moment, Vector3d::Zero(), kTol);
  // About the world origin: (0.3, 0.5, 0) x (0, 0, 700) = (350, -210, 0).
  jle::plateReactionInWorld(plate, r, Vector3d::Zero(), force, moment);
  expectVector(moment, Vector3d(350.0, -210.0, 0.0), 1e-10);  // 350 N m: a few ulps of it
}

// Contact starts at the threshold (20 N by default) of force pressing into the plate.
// Below it the reading has no COP but still acts as measured: 19.9 N pressing with the
// moment (-1, 0.5, 0) about the plate origin (the world's) gives the foot (-1, 0, 19.9)
// and, about (1, 2, 3), (1, -0.5, 0) + (-1, -2, -3) x (-1, 0, 19.9) = (1, -0.5, 0) +
// (-39.8, 22.9, -2) = (-38.8, 22.4, -2). With the foot pulling on the plate (or not
// touching it) every decoded quantity and the reaction are zero.
TEST(ForcePlate, ContactThreshold) {
  jle::ForcePlateConfig plate;
  ASSERT_EQ(plate.contact_threshold, 20.0);
  const Vector3d moment(-1.0, 0.5, 0.0);
  EXPECT_TRUE(jle::readForcePlate(plate, Vector3d(0.0, 0.0, -20.0), moment).contact);
  for (const double fz : {-19.9, 0.0, 300.0}) {
    const jle::PlateReading r = jle::readForcePlate(plate, Vector3d(1.0, 0.0, fz), moment);
    const bool pressing = fz < 0.0;
    EXPECT_FALSE(r.contact) << fz;
    EXPECT_EQ(r.loaded, pressing) << fz;
    EXPECT_EQ(r.cop_plate, Vector3d::Zero()) << fz;
    EXPECT_EQ(r.force_on_foot_plate, pressing ? Vector3d(-1.0, 0.0, 19.9) : Vector3d::Zero()) << fz;
    Vector3d force(9, 9, 9), reaction_moment(9, 9, 9);
    jle::plateReactionInWorld(plate, r, Vector3d(1, 2, 3), force, reaction_moment);
    EXPECT_EQ(force, pressing ? Vector3d(-1.0, 0.0, 19.9) : Vector3d::Zero()) << fz;
    if (pressing)
      expectVector(reaction_moment, Vector3d(-38.8, 22.4, -2.0), 1e-14);  // 3 m x 20 N: 1e-14
    else
      EXPECT_EQ(reaction_moment, Vector3d::Zero()) << fz;
  }
  // A zero threshold still needs a force pressing in.
  plate.contact_threshold = 0.0;
  EXPECT_FALSE(jle::readForcePlate(plate, Vector3d(0.0, 0.0, 0.0), moment).contact);
  EXPECT_TRUE(jle::readForcePlate(plate, Vector3d(0.0, 0.0, -0.5), Vector3d::Zero()).contact);
}

TEST(ForcePlate, NonFiniteInputIsNoContact) {
  jle::ForcePlateConfig plate;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Vector3d good_force(0.0, 0.0, -700.0), good_moment(-140.0, 70.0, 0.0);
  for (int i = 0; i < 3; ++i)
    for (const double bad : {nan, inf, -inf}) {
      Vector3d f = good_force, m = good_moment;
      f[i] = bad;
      const jle::PlateReading rf = jle::readForcePlate(plate, f, good_moment);
      EXPECT_FALSE(rf.contact) << "force " << i << " " << bad;
      EXPECT_EQ(rf.normal_force, 0.0);
      m[i] = bad;
      const jle::PlateReading rm = jle::readForcePlate(plate, good_force, m);
      EXPECT_FALSE(rm.contact) << "moment " << i << " " << bad;
      EXPECT_TRUE(rm.cop_plate.allFinite());
      EXPECT_TRUE(rm.moment_on_foot_plate.allFinite());
    }
}

// A foot of m = 2 kg (COM at (0.1, 0, -0.05)) on a fixed ankle about y at the world
// origin, at rest, standing on a z-up plate whose surface (and origin) is at z = -0.08.
// The foot presses m g down at (0.2, 0, -0.08): the plate reports F = (0, 0, -m g) and
// M = (0.2, 0, 0) x F = (0, 0.2 m g, 0). The ankle holds the rest: F_ankle = 0 (the
// reaction carries the weight) and, about the ankle, M + (0.2, 0, -0.08) x (0, 0, m g)
// + (0.1, 0, -0.05) x (0, 0, -m g) = 0: M = (0, 0.1 m g, 0), the effort 0.1 m g.
template <typename Scalar>
void expectFootHeldByThePlate(double tol) {
  const std::string urdf =
      "<robot name=\"foot\"><link name=\"world\"/><link name=\"foot\"><inertial>"
      "<origin xyz=\"0.1 0 -0.05\"/><mass value=\"2\"/>"
      "<inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/>"
      "</inertial></link><joint name=\"ankle\" type=\"revolute\"><parent link=\"world\"/>"
      "<child link=\"foot\"/><axis xyz=\"0 1 0\"/>"
      "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint></robot>";
  const jle::Model<Scalar> model = jle::modelFromUrdfString(urdf).cast<Scalar>();
  jle::Data<Scalar> data(model);
  const jle::VectorX<Scalar> zero = jle::VectorX<Scalar>::Zero(model.nq);
  const double g = 9.80665, m = 2.0;
  jle::forwardKinematics(model, data, zero, zero, zero,
                         Eigen::Matrix<Scalar, 3, 1>(0, 0, static_cast<Scalar>(-g)));
  jle::ForcePlateConfig plate;
  plate.link = "foot";
  plate.p_world_plate = Vector3d(0.0, 0.0, -0.08);
  plate.contact_threshold = 5.0;  // [N], below the foot's 19.6 N
  const jle::PlateReading reading =
      jle::readForcePlate(plate, Vector3d(0.0, 0.0, -m * g), Vector3d(0.0, 0.2 * m * g, 0.0));
  ASSERT_TRUE(reading.contact);
  jle::applyPlateReaction(model, data, model.frameIndex("foot"), plate, reading);
  jle::inverseDynamics(model, data);
  const int s = model.segmentOfJoint("ankle");
  const jle::Wrench<Scalar> w = jle::jointWrench(model, data, s, jle::WrenchFrame::kWorld);
  expectVector(w.force.template cast<double>(), Vector3d::Zero(), tol * m * g);
  expectVector(w.moment.template cast<double>(), Vector3d(0.0, 0.1 * m * g, 0.0), tol * m * g);
  EXPECT_NEAR(static_cast<double>(data.effort[s]), 0.1 * m * g, tol * m * g);

  // A reading that is not loaded: nothing is applied, the ankle carries the whole weight.
  jle::forwardKinematics(model, data, zero, zero, zero,
                         Eigen::Matrix<Scalar, 3, 1>(0, 0, static_cast<Scalar>(-g)));
  jle::applyPlateReaction(model, data, model.frameIndex("foot"), plate, jle::PlateReading());
  jle::inverseDynamics(model, data);
  EXPECT_NEAR(
      static_cast<double>(jle::jointWrench(model, data, s, jle::WrenchFrame::kWorld).force.z()),
      m * g, tol * m * g);
}

// Tolerances relative to m g: a few roundings of numbers of order 20 in double (1e-14);
// in float the model and the kinematics carry about 1e-7 each (1e-6).
TEST(ForcePlate, ReactionHoldsTheFootInDouble) { expectFootHeldByThePlate<double>(1e-14); }
TEST(ForcePlate, ReactionHoldsTheFootInFloat) { expectFootHeldByThePlate<float>(1e-6); }

}  // namespace
