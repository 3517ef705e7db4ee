// Closed-form checks of the joint loads: every expected number is worked out here from
// textbook mechanics (pendulums, the double pendulum's equations of motion, a chain at
// rest, a free rigid body, the planar foot of Federico & Alhasadi 2022 section 6), never
// taken from the library. Also: malformed models are refused naming the culprit.
//
// Tolerances: the library and the closed forms evaluate the same physics along different
// sums of products, so they agree to a few units of double rounding (2.2e-16) times the
// magnitude of the largest term in the sum. Each comparison below is relative to that
// magnitude (`scale`); the largest error measured over all the cases of this file is
// 8e-16 of it (3.7 eps, the kept-fixed-joint arm; most cases stay under 2 eps), and the
// bound 1e-12 leaves a margin of 1000 while still catching any wrong term, which would
// be of the order of the scale itself.
#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/papers_foot.hpp>
#include <jle_testing/random_models.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using VecX = jle::VectorX<double>;
using testing::AllOf;
using testing::HasSubstr;

constexpr double kG = 9.80665;  // [m/s^2]
// Relative bound of every comparison (see the file comment).
constexpr double kRel = 1e-12;

// ---------------------------------------------------------------------------------
// URDF text builders: numbers printed with 17 significant digits, so the model reads
// back exactly the doubles the closed forms use.

std::string num(double x) {
  std::ostringstream os;
  os << std::setprecision(17) << x;
  return os.str();
}

std::string vec(const Vec3& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

Mat3 inertiaMatrix(double ixx, double iyy, double izz, double ixy = 0.0, double ixz = 0.0,
                   double iyz = 0.0) {
  Mat3 I;
  I << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  return I;
}

// URDF rpy: fixed-axis roll, pitch, yaw, R = Rz(yaw) Ry(pitch) Rx(roll).
Mat3 rpyMatrix(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

// Rotation by `angle` about the unit vector `axis`, in the plane z = 0 when axis = z.
Mat3 rotation(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

struct Inertial {
  double mass = 0.0;
  Vec3 xyz = Vec3::Zero();      ///< centre of mass in the link frame [m]
  Vec3 rpy = Vec3::Zero();      ///< orientation of the inertia axes in the link frame
  Mat3 inertia = Mat3::Zero();  ///< about the centre of mass, inertia axes [kg m^2]
};

std::string link(const std::string& name) { return "<link name=\"" + name + "\"/>\n"; }

std::string link(const std::string& name, const Inertial& in) {
  const Mat3& I = in.inertia;
  return "<link name=\"" + name + "\"><inertial><origin xyz=\"" + vec(in.xyz) + "\" rpy=\"" +
         vec(in.rpy) + "\"/><mass value=\"" + num(in.mass) + "\"/><inertia ixx=\"" + num(I(0, 0)) +
         "\" ixy=\"" + num(I(0, 1)) + "\" ixz=\"" + num(I(0, 2)) + "\" iyy=\"" + num(I(1, 1)) +
         "\" iyz=\"" + num(I(1, 2)) + "\" izz=\"" + num(I(2, 2)) + "\"/></inertial></link>\n";
}

std::string joint(const std::string& name, const std::string& type, const std::string& parent,
                  const std::string& child, const Vec3& xyz = Vec3::Zero(),
                  const Vec3& rpy = Vec3::Zero(), const Vec3& axis = Vec3::UnitZ(),
                  const std::string& extra = "") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent +
         "\"/><child link=\"" + child + "\"/><origin xyz=\"" + vec(xyz) + "\" rpy=\"" + vec(rpy) +
         "\"/><axis xyz=\"" + vec(axis) + "\"/>" + extra + "</joint>\n";
}

std::string robot(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<robot name=\"closed_form\">\n" + body + "</robot>\n";
}

// ---------------------------------------------------------------------------------
// Comparison: each component of `actual` within kRel * scale of `expected`.

void expectNear(const Vec3& actual, const Vec3& expected, double scale, const std::string& what) {
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(actual[k], expected[k], kRel * scale) << what << ", component " << k;
}

VecX vecx(std::initializer_list<double> values) {
  VecX v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index k = 0;
  for (double x : values) v[k++] = x;
  return v;
}

// Newton-Euler of one rigid body turning about a fixed axis u through the joint origin,
// every quantity in the body frame: omega = qd u, alpha = qdd u, a_G = alpha x c +
// omega x (omega x c); the joint supplies F = m (a_G - g) and, about the joint origin,
// M = J_G alpha + omega x J_G omega + c x F (Euler's equations moved from x_G).
struct Loads {
  Vec3 force, moment;
};

Loads fixedAxisBody(double m, const Vec3& c, const Mat3& J_com, const Vec3& u, double qd,
                    double qdd, const Vec3& g_body) {
  const Vec3 w = qd * u;
  const Vec3 al = qdd * u;
  const Vec3 a_com = al.cross(c) + w.cross(w.cross(c));
  Loads out;
  out.force = m * (a_com - g_body);
  out.moment = J_com * al + w.cross(J_com * w) + c.cross(out.force);
  return out;
}

// ---------------------------------------------------------------------------------
// Single pendulum.

// A rod of mass m with its centre of mass at distance l along x, turning about z, with
// gravity along -y: q is the angle of the rod above the horizontal.
TEST(SinglePendulum, AboutZWithGravityAlongMinusY) {
  const double m = 2.3, l = 0.45;
  // Products of inertia make the bearing moments (x, y) non-zero.
  const Mat3 J = inertiaMatrix(0.05, 0.06, 0.04, 0.001, 0.003, -0.002);
  Inertial rod{m, Vec3(l, 0, 0), Vec3::Zero(), J};
  const jle::Model<double> model = jle::modelFromUrdfString(
      robot(link("world") + link("rod", rod) + joint("hinge", "revolute", "world", "rod")));
  ASSERT_EQ(model.nq, 1);
  const int s = model.segmentOfJoint("hinge");
  jle::Data<double> data(model);
  const Vec3 gravity(0, -kG, 0);

  jle_test::Random rng(11);
  jle_test::UniformIn angle(-M_PI, M_PI), rate(-6.0, 6.0), acc(-40.0, 40.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double q = angle(rng), qd = rate(rng), qdd = acc(rng);
    jle::forwardKinematics(model, data, vecx({q}), vecx({qd}), vecx({qdd}), gravity);
    jle::inverseDynamics(model, data);

    // Textbook: tau = (I_zz + m l^2) qdd + m g l cos q.
    const double tau = (J(2, 2) + m * l * l) * qdd + m * kG * l * std::cos(q);
    const double scale = (J(2, 2) + m * l * l) * std::abs(qdd) + m * kG * l;
    EXPECT_NEAR(data.effort[s], tau, kRel * scale) << "q " << q;

    // Child frame (x along the rod): centripetal -m l qd^2 and tangential m l qdd, plus
    // gravity (0, -g, 0) seen from the rod, (-g sin q, -g cos q, 0), taken to the left.
    const Vec3 F(m * (-l * qd * qd + kG * std::sin(q)), m * (l * qdd + kG * std::cos(q)), 0.0);
    // Bearing moments of a body with products of inertia turning about z:
    // J alpha + omega x J omega = (Ixz qdd - Iyz qd^2, Iyz qdd + Ixz qd^2, Izz qdd),
    // plus the moment l Fy of the joint force about the joint origin.
    const Vec3 M(J(0, 2) * qdd - J(1, 2) * qd * qd, J(1, 2) * qdd + J(0, 2) * qd * qd,
                 J(2, 2) * qdd + l * F.y());
    const double force_scale = m * (l * qd * qd + l * std::abs(qdd) + kG);
    expectNear(data.force[s], F, force_scale, "force");
    expectNear(data.moment[s], M, scale + J.norm() * qd * qd + l * force_scale, "moment");
  }
}

// A rod hanging down (centre of mass at distance l along -z), turning about y, gravity
// along -z: q is the angle from the vertical.
TEST(SinglePendulum, HangingAboutYWithGravityAlongMinusZ) {
  const double m = 0.8, l = 0.3;
  const Mat3 J = inertiaMatrix(0.011, 0.012, 0.004);
  Inertial rod{m, Vec3(0, 0, -l), Vec3::Zero(), J};
  const jle::Model<double> model = jle::modelFromUrdfString(
      robot(link("world") + link("rod", rod) +
            joint("hinge", "revolute", "world", "rod", Vec3::Zero(), Vec3::Zero(), Vec3::UnitY())));
  const int s = model.segmentOfJoint("hinge");
  jle::Data<double> data(model);
  const Vec3 gravity(0, 0, -kG);

  jle_test::Random rng(12);
  jle_test::UniformIn angle(-M_PI, M_PI), rate(-6.0, 6.0), acc(-40.0, 40.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double q = angle(rng), qd = rate(rng), qdd = acc(rng);
    jle::forwardKinematics(model, data, vecx({q}), vecx({qd}), vecx({qdd}), gravity);
    jle::inverseDynamics(model, data);

    // Textbook: tau = (I_yy + m l^2) qdd + m g l sin q.
    const double tau = (J(1, 1) + m * l * l) * qdd + m * kG * l * std::sin(q);
    const double scale = (J(1, 1) + m * l * l) * std::abs(qdd) + m * kG * l;
    EXPECT_NEAR(data.effort[s], tau, kRel * scale) << "q " << q;

    // Child frame: the rod pulls along +z (towards the joint) with the tension
    // m (l qd^2 + g cos q); the tangential force along x is -m (l qdd + g sin q).
    const Vec3 F(-m * (l * qdd + kG * std::sin(q)), 0.0, m * (l * qd * qd + kG * std::cos(q)));
    const Vec3 M(0.0, tau, 0.0);
    const double force_scale = m * (l * qd * qd + l * std::abs(qdd) + kG);
    expectNear(data.force[s], F, force_scale, "force");
    expectNear(data.moment[s], M, scale, "moment");
  }
}

// ---------------------------------------------------------------------------------
// Planar double pendulum (Spong, Hutchinson & Vidyasagar, "Robot Modeling and Control",
// section 7.3): q1 absolute from the x axis, q2 relative, gravity along -y.

TEST(DoublePendulum, MatchesTextbookEquationsOfMotion) {
  const double m1 = 1.7, l1 = 0.6, lc1 = 0.27, I1 = 0.061;
  const double m2 = 1.1, lc2 = 0.22, I2 = 0.034;
  Inertial link1{m1, Vec3(lc1, 0, 0), Vec3::Zero(), inertiaMatrix(0.004, 0.060, I1)};
  Inertial link2{m2, Vec3(lc2, 0, 0), Vec3::Zero(), inertiaMatrix(0.002, 0.033, I2)};
  const jle::Model<double> model =
      jle::modelFromUrdfString(robot(link("world") + link("link1", link1) + link("link2", link2) +
                                     joint("shoulder", "revolute", "world", "link1") +
                                     joint("elbow", "revolute", "link1", "link2", Vec3(l1, 0, 0))));
  ASSERT_EQ(model.nq, 2);
  ASSERT_EQ(model.coordinate_names, (std::vector<std::string>{"shoulder", "elbow"}));
  const int s1 = model.segmentOfJoint("shoulder"), s2 = model.segmentOfJoint("elbow");
  jle::Data<double> data(model);

  jle_test::Random rng(21);
  jle_test::UniformIn angle(-M_PI, M_PI), rate(-5.0, 5.0), acc(-30.0, 30.0);
  for (int trial = 0; trial < 100; ++trial) {
    const double q1 = angle(rng), q2 = angle(rng);
    const double qd1 = rate(rng), qd2 = rate(rng), qdd1 = acc(rng), qdd2 = acc(rng);
    jle::forwardKinematics(model, data, vecx({q1, q2}), vecx({qd1, qd2}), vecx({qdd1, qdd2}),
                           Vec3(0, -kG, 0));
    jle::inverseDynamics(model, data);

    // M(q) qdd + C(q, qd) qd + G(q) = tau.
    const double c2 = std::cos(q2);
    const double M11 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2 * l1 * lc2 * c2) + I1 + I2;
    const double M12 = m2 * (lc2 * lc2 + l1 * lc2 * c2) + I2;
    const double M22 = m2 * lc2 * lc2 + I2;
    const double h = -m2 * l1 * lc2 * std::sin(q2);
    const double G1 = (m1 * lc1 + m2 * l1) * kG * std::cos(q1) + m2 * lc2 * kG * std::cos(q1 + q2);
    const double G2 = m2 * lc2 * kG * std::cos(q1 + q2);
    const double tau1 = M11 * qdd1 + M12 * qdd2 + h * qd2 * qd2 + 2 * h * qd1 * qd2 + G1;
    const double tau2 = M12 * qdd1 + M22 * qdd2 - h * qd1 * qd1 + G2;

    const double scale1 = std::abs(M11 * qdd1) + std::abs(M12 * qdd2) + std::abs(h * qd2 * qd2) +
                          std::abs(2 * h * qd1 * qd2) + std::abs(G1);
    const double scale2 =
        std::abs(M12 * qdd1) + std::abs(M22 * qdd2) + std::abs(h * qd1 * qd1) + std::abs(G2);
    EXPECT_NEAR(data.effort[s1], tau1, kRel * scale1) << "trial " << trial;
    EXPECT_NEAR(data.effort[s2], tau2, kRel * scale2) << "trial " << trial;
  }
}

// ---------------------------------------------------------------------------------
// A chain hanging straight down at rest: every joint carries the weight of everything
// below it, and no moment (all centres of mass on the vertical through the joints).

TEST(HangingChain, JointForceIsTheWeightBelowAndMomentsVanish) {
  // Links hang along -z; joint origins turn the frames about z only (yaw), so every
  // child frame keeps z vertical at rest. j3 is a vertical slider, j4 turns about the
  // vertical, so neither q3 nor q4 moves a centre of mass off the vertical.
  const std::vector<double> mass = {1.5, 1.2, 0.9, 0.6, 0.4};
  const std::vector<std::string> types = {"revolute", "revolute", "prismatic", "revolute",
                                          "revolute"};
  const std::vector<Vec3> axes = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), Vec3::UnitZ(),
                                  Vec3(1, 1, 0)};
  const std::vector<double> yaw = {0.0, 0.5, -1.1, 0.3, 2.0};
  const std::vector<double> length = {0.0, 0.4, 0.3, 0.25, 0.4};  // from the previous joint
  std::string body = link("world");
  for (int k = 0; k < 5; ++k) {
    const std::string name = "l" + std::to_string(k + 1);
    Inertial in{mass[k], Vec3(0, 0, -0.1 - 0.02 * k), Vec3(0.1 * k, 0.2, -0.3),
                inertiaMatrix(0.01 + 0.001 * k, 0.012, 0.005)};
    body += link(name, in);
    body += joint("j" + std::to_string(k + 1), types[k], k == 0 ? "world" : "l" + std::to_string(k),
                  name, Vec3(0, 0, -length[k]), Vec3(0, 0, yaw[k]), axes[k]);
  }
  // A lumped weight on l3, also on its vertical.
  body += link("l3_weight",
               Inertial{0.35, Vec3(0, 0, -0.07), Vec3::Zero(), inertiaMatrix(0.001, 0.001, 0.001)});
  body += joint("j3_weight", "fixed", "l3", "l3_weight", Vec3(0, 0, -0.05), Vec3(0, 0, 0.9));
  const jle::Model<double> model = jle::modelFromUrdfString(robot(body));
  ASSERT_EQ(model.nq, 5);
  jle::Data<double> data(model);

  // At rest; the slider extended, the vertical joint turned.
  const VecX q = vecx({0.0, 0.0, 0.12, 0.8, 0.0});
  const VecX zero = VecX::Zero(5);
  jle::forwardKinematics(model, data, q, zero, zero, Vec3(0, 0, -kG));
  jle::inverseDynamics(model, data);

  const double total_weight = (1.5 + 1.2 + 0.9 + 0.35 + 0.6 + 0.4) * kG;
  const std::vector<double> weight_below = {total_weight, (1.2 + 0.9 + 0.35 + 0.6 + 0.4) * kG,
                                            (0.9 + 0.35 + 0.6 + 0.4) * kG, (0.6 + 0.4) * kG,
                                            0.4 * kG};
  // Moments: the weights times lever arms of up to 2 m would be ~ total_weight * 2.
  const double moment_scale = total_weight * 2.0;
  for (int k = 0; k < 5; ++k) {
    const std::string name = "j" + std::to_string(k + 1);
    const int s = model.segmentOfJoint(name);
    expectNear(data.force[s], Vec3(0, 0, weight_below[k]), total_weight, name + " force");
    expectNear(data.moment[s], Vec3::Zero(), moment_scale, name + " moment");
    // Only the slider carries its load along its axis.
    const double effort = types[k] == "prismatic" ? weight_below[k] : 0.0;
    EXPECT_NEAR(data.effort[s], effort, kRel * total_weight) << name;
  }
  // The world holds the whole chain.
  expectNear(data.force[0], Vec3(0, 0, total_weight), total_weight, "base force");
  expectNear(data.moment[0], Vec3::Zero(), moment_scale, "base moment");
}

// ---------------------------------------------------------------------------------
// A free rigid body in space (floating base), with a wrench applied at a handle.

struct FreeBody {
  double m = 3.7;
  Vec3 com = Vec3(0.05, -0.02, 0.11);  // body frame
  Vec3 inertial_rpy = Vec3(0.3, -0.2, 0.9);
  Mat3 J_inertial = inertiaMatrix(0.09, 0.07, 0.05, 0.004, -0.002, 0.003);
  Vec3 handle_xyz = Vec3(0.2, 0.1, -0.05);  // handle frame in the body frame
  Vec3 handle_rpy = Vec3(0.4, 0.1, -0.7);

  std::string links() const {
    return link("body", Inertial{m, com, inertial_rpy, J_inertial}) + link("handle") +
           joint("handle_joint", "fixed", "body", "handle", handle_xyz, handle_rpy);
  }
};

// Both ways of declaring a floating base: the option, or a `floating` joint from a
// massless world link.
std::vector<jle::Model<double>> freeBodyModels(const FreeBody& b) {
  jle::ModelOptions floating;
  floating.floating_base = true;
  std::vector<jle::Model<double>> out;
  out.push_back(jle::modelFromUrdfString(robot(b.links()), floating));
  out.push_back(jle::modelFromUrdfString(
      robot(link("world") + b.links() + joint("free", "floating", "world", "body"))));
  return out;
}

TEST(FreeBody, ResidualIsNewtonEulerMinusAppliedWrenchAndWeight) {
  const FreeBody b;
  const Vec3 gravity(0, 0, -kG);
  for (const jle::Model<double>& model : freeBodyModels(b)) {
    ASSERT_TRUE(model.floating_base);
    ASSERT_EQ(model.nq, 0);
    ASSERT_EQ(model.link_name[0], "body");
    jle::Data<double> data(model);
    const int handle = model.frameIndex("handle");
    jle_test::Random rng(31);
    for (int trial = 0; trial < 30; ++trial) {
      const jle::BaseState<double> base = jle_test::randomBase(rng, 2.0, 1.0, 4.0, 10.0, 20.0);
      const Vec3 F = rng.vector(50.0), M = rng.vector(10.0);  // world, at handle
      jle::forwardKinematics(model, data, VecX(), VecX(), VecX(), gravity, base);
      jle::addExternalWrench(model, data, handle, F, M, jle::WrenchFrame::kWorld);
      jle::inverseDynamics(model, data);

      // By hand, world frame, moments about the body origin O.
      const Mat3& R = base.R_world_base;
      const Vec3& w = base.omega_world;
      const Vec3& al = base.alpha_world;
      const Vec3 c = R * b.com;  // O -> G
      const Vec3 a_G = base.a_world + al.cross(c) + w.cross(w.cross(c));
      const Mat3 R_inertia = R * rpyMatrix(b.inertial_rpy);
      const Mat3 J = R_inertia * b.J_inertial * R_inertia.transpose();
      const Vec3 r_handle = R * b.handle_xyz;  // O -> handle
      const Vec3 F_res = b.m * a_G - F - b.m * gravity;
      const Vec3 M_res = J * al + w.cross(J * w) + c.cross(b.m * a_G) - (r_handle.cross(F) + M) -
                         c.cross(b.m * gravity);

      const double force_scale = b.m * (a_G.norm() + kG) + F.norm();
      const double moment_scale = J.norm() * (al.norm() + w.squaredNorm()) +
                                  c.norm() * force_scale + r_handle.norm() * F.norm() + M.norm();
      expectNear(R * data.force[0], F_res, force_scale, "residual force");
      expectNear(R * data.moment[0], M_res, moment_scale, "residual moment");
    }
  }
}

TEST(FreeBody, MotionCausedByTheAppliedWrenchLeavesNoResidual) {
  const FreeBody b;
  const Vec3 gravity(0, 0, -kG);
  for (const jle::Model<double>& model : freeBodyModels(b)) {
    jle::Data<double> data(model);
    const int handle = model.frameIndex("handle");
    jle_test::Random rng(32);
    for (int trial = 0; trial < 30; ++trial) {
      const jle::BaseState<double> base = jle_test::randomBase(rng, 2.0, 1.0, 4.0, 10.0, 20.0);

      // The wrench that, with gravity, causes exactly this motion: Newton and Euler
      // about O, moved to the handle and expressed in the handle frame.
      const Mat3& R = base.R_world_base;
      const Vec3& w = base.omega_world;
      const Vec3& al = base.alpha_world;
      const Vec3 c = R * b.com;
      const Vec3 a_G = base.a_world + al.cross(c) + w.cross(w.cross(c));
      const Mat3 R_inertia = R * rpyMatrix(b.inertial_rpy);
      const Mat3 J = R_inertia * b.J_inertial * R_inertia.transpose();
      const Vec3 r_handle = R * b.handle_xyz;
      const Vec3 F_world = b.m * (a_G - gravity);
      const Vec3 M_O = J * al + w.cross(J * w) + c.cross(F_world);
      const Vec3 M_world = M_O - r_handle.cross(F_world);
      const Mat3 R_world_handle = R * rpyMatrix(b.handle_rpy);

      jle::forwardKinematics(model, data, VecX(), VecX(), VecX(), gravity, base);
      jle::addExternalWrench(model, data, handle, Vec3(R_world_handle.transpose() * F_world),
                             Vec3(R_world_handle.transpose() * M_world), jle::WrenchFrame::kLocal);
      jle::inverseDynamics(model, data);

      const double force_scale = F_world.norm() + b.m * kG;
      const double moment_scale = M_O.norm() + J.norm() * (al.norm() + w.squaredNorm()) +
                                  (c.norm() + r_handle.norm()) * force_scale;
      expectNear(data.force[0], Vec3::Zero(), force_scale, "residual force");
      expectNear(data.moment[0], Vec3::Zero(), moment_scale, "residual moment");
    }
  }
}

// ---------------------------------------------------------------------------------
// The 2-D foot of Federico & Alhasadi (2022), section 6: a foot of mass m and inertia
// J_G about its centre of mass G turns by theta(t) about a fixed ankle A, and a force
// plate pushes on it with F_P at the centre of pressure P. In the plane the 6x6
// system reduces to 3x3 and the gyroscopic term vanishes:
//   F_A = m a_G - F_P - m g
//   M_A = J_G theta_dd - (xi_A x F_A)_z - (xi_P x F_P)_z,   xi = point - x_G.
// The foot, its motion and these equations: papers_foot.hpp.

using jle_test::cross2;

TEST(PlanarFoot, AnkleWrenchMatchesThePapersPlanarEquations) {
  const jle_test::PapersFoot foot;
  const jle::Model<double> model = jle::modelFromUrdfString(foot.urdf());
  const int s = model.segmentOfJoint("ankle");
  const int cop = model.frameIndex("cop");
  jle::Data<double> data(model);
  for (int k = 0; k <= 40; ++k) {
    const jle_test::PapersFoot::Instant i = foot.at(k);
    const double t = i.t;
    jle::forwardKinematics(model, data, vecx({i.theta}), vecx({i.theta_d}), vecx({i.theta_dd}),
                           Vec3(foot.g.x(), foot.g.y(), 0));
    jle::addExternalWrench(model, data, cop, Vec3(i.F_P.x(), i.F_P.y(), 0), Vec3(Vec3::Zero()),
                           jle::WrenchFrame::kWorld);
    jle::inverseDynamics(model, data);
    const jle::Wrench<double> W = jle::jointWrench(model, data, s, jle::WrenchFrame::kWorld);

    EXPECT_NEAR(W.force.x(), i.F_A.x(), kRel * i.force_scale) << "t " << t;
    EXPECT_NEAR(W.force.y(), i.F_A.y(), kRel * i.force_scale) << "t " << t;
    EXPECT_NEAR(W.moment.z(), i.M_A, kRel * i.moment_scale) << "t " << t;
    // Nothing leaves the plane.
    EXPECT_NEAR(W.force.z(), 0.0, kRel * i.force_scale) << "t " << t;
    EXPECT_NEAR(W.moment.x(), 0.0, kRel * i.moment_scale) << "t " << t;
    EXPECT_NEAR(W.moment.y(), 0.0, kRel * i.moment_scale) << "t " << t;
    EXPECT_NEAR(data.effort[s], i.M_A, kRel * i.moment_scale) << "t " << t;
  }
}

// ---------------------------------------------------------------------------------
// Prismatic and mimic joints.

TEST(Prismatic, SliderCarriesItsWeightAndItsInertia) {
  const double m = 2.5;
  const Vec3 c(0.03, -0.04, 0.12);
  Inertial slider{m, c, Vec3(0.2, 0.0, 0.1), inertiaMatrix(0.02, 0.03, 0.015)};
  const Vec3 gravity(0, 0, -kG);
  jle_test::Random rng(41);
  jle_test::UniformIn pos(-0.5, 0.5), rate(-2.0, 2.0), acc(-20.0, 20.0);

  // Vertical slider: effort = m (qdd + g); then a slider inclined at cos(a) = 0.8 from the
  // vertical: effort = m (qdd + g cos a), the textbook inclined plane.
  for (const Vec3& u : {Vec3(0, 0, 1), Vec3(0, 0.6, 0.8)}) {
    const jle::Model<double> model = jle::modelFromUrdfString(robot(
        link("world") + link("slider", slider) +
        joint("lift", "prismatic", "world", "slider", Vec3(0.1, -0.2, 0.3), Vec3::Zero(), u)));
    const int s = model.segmentOfJoint("lift");
    jle::Data<double> data(model);
    for (int trial = 0; trial < 20; ++trial) {
      const double q = pos(rng), qd = rate(rng), qdd = acc(rng);
      jle::forwardKinematics(model, data, vecx({q}), vecx({qd}), vecx({qdd}), gravity);
      jle::inverseDynamics(model, data);
      const double scale = m * (std::abs(qdd) + kG);
      EXPECT_NEAR(data.effort[s], m * (qdd + kG * u.z()), kRel * scale) << "q " << q;
      // No rotation: the frame keeps the world's axes; F = m (qdd u - g), acting at the
      // origin of the slider frame, its moment about it c x F.
      const Vec3 F = m * (qdd * u - gravity);
      expectNear(data.force[s], F, scale, "force");
      expectNear(data.moment[s], c.cross(F), c.norm() * scale, "moment");
    }
  }
}

// A slider running along a turning arm (the planar R-P arm, gravity along -y): theta
// turns the arm about z, the slider's centre is at r along it. From the Lagrangian
// T = (I1 + m1 lc1^2 + I2 + m2 r^2) theta_d^2 / 2 + m2 r_d^2 / 2,
// V = (m1 lc1 + m2 r) g sin(theta):
//   tau = (I1 + m1 lc1^2 + I2 + m2 r^2) theta_dd + 2 m2 r r_d theta_d
//         + (m1 lc1 + m2 r) g cos(theta)
//   f = m2 (r_dd - r theta_d^2 + g sin(theta))
// with the Coriolis term 2 m2 r r_d theta_d in tau.
TEST(Prismatic, SliderOnATurningArmFeelsCoriolis) {
  const double m1 = 1.6, lc1 = 0.3, I1 = 0.05, m2 = 0.9, I2 = 0.004;
  const Inertial arm{m1, Vec3(lc1, 0, 0), Vec3::Zero(), inertiaMatrix(0.002, 0.049, I1)};
  const Inertial slider{m2, Vec3::Zero(), Vec3::Zero(), inertiaMatrix(0.003, 0.0025, I2)};
  const jle::Model<double> model = jle::modelFromUrdfString(robot(
      link("world") + link("arm", arm) + link("slider", slider) +
      joint("turn", "revolute", "world", "arm") +
      joint("slide", "prismatic", "arm", "slider", Vec3::Zero(), Vec3::Zero(), Vec3::UnitX())));
  const int s1 = model.segmentOfJoint("turn"), s2 = model.segmentOfJoint("slide");
  jle::Data<double> data(model);

  jle_test::Random rng(43);
  jle_test::UniformIn angle(-M_PI, M_PI), radius(0.1, 0.8), rate(-4.0, 4.0), acc(-30.0, 30.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double th = angle(rng), r = radius(rng);
    const double thd = rate(rng), rd = rate(rng), thdd = acc(rng), rdd = acc(rng);
    jle::forwardKinematics(model, data, vecx({th, r}), vecx({thd, rd}), vecx({thdd, rdd}),
                           Vec3(0, -kG, 0));
    jle::inverseDynamics(model, data);

    const double inertia = I1 + m1 * lc1 * lc1 + I2 + m2 * r * r;
    const double coriolis = 2 * m2 * r * rd * thd;
    const double gravity = (m1 * lc1 + m2 * r) * kG * std::cos(th);
    const double tau = inertia * thdd + coriolis + gravity;
    const double f = m2 * (rdd - r * thd * thd + kG * std::sin(th));
    const double tau_scale = inertia * std::abs(thdd) + std::abs(coriolis) + std::abs(gravity);
    const double f_scale = m2 * (std::abs(rdd) + r * thd * thd + kG);
    EXPECT_NEAR(data.effort[s1], tau, kRel * tau_scale) << "trial " << trial;
    EXPECT_NEAR(data.effort[s2], f, kRel * f_scale) << "trial " << trial;
    // Across the slide (the arm's y axis): tangential and Coriolis accelerations and the
    // weight's component.
    const double across = m2 * (r * thdd + 2 * rd * thd + kG * std::cos(th));
    EXPECT_NEAR(data.force[s2].y(), across,
                kRel * m2 * (r * std::abs(thdd) + std::abs(2 * rd * thd) + kG))
        << "trial " << trial;
  }
}

TEST(Mimic, LeaderAndFollowerAreTwoPendulumsOnOneCoordinate) {
  // Two independent pendulums about z hanging from the world, gravity along -y; the
  // follower turns by k q + o.
  const double mA = 1.4, lA = 0.35, IA = 0.02;
  const double mB = 0.6, lB = 0.2, IB = 0.007;
  const double k = -1.5, o = 0.3;
  Inertial a{mA, Vec3(lA, 0, 0), Vec3::Zero(), inertiaMatrix(0.003, 0.019, IA)};
  Inertial b{mB, Vec3(lB, 0, 0), Vec3::Zero(), inertiaMatrix(0.001, 0.0065, IB)};
  const std::string mimic =
      "<mimic joint=\"lead\" multiplier=\"" + num(k) + "\" offset=\"" + num(o) + "\"/>";
  const jle::Model<double> model = jle::modelFromUrdfString(
      robot(link("world") + link("a", a) + link("b", b) + joint("lead", "revolute", "world", "a") +
            joint("follow", "revolute", "world", "b", Vec3(0, 0.5, 0), Vec3::Zero(), Vec3::UnitZ(),
                  mimic)));
  ASSERT_EQ(model.nq, 1);
  ASSERT_EQ(model.coordinate_names, std::vector<std::string>{"lead"});
  const int sA = model.segmentOfJoint("lead"), sB = model.segmentOfJoint("follow");
  jle::Data<double> data(model);

  jle_test::Random rng(42);
  jle_test::UniformIn angle(-M_PI, M_PI), rate(-5.0, 5.0), acc(-30.0, 30.0);
  for (int trial = 0; trial < 30; ++trial) {
    const double q = angle(rng), qd = rate(rng), qdd = acc(rng);
    jle::forwardKinematics(model, data, vecx({q}), vecx({qd}), vecx({qdd}), Vec3(0, -kG, 0));
    jle::inverseDynamics(model, data);
    const double tauA = (IA + mA * lA * lA) * qdd + mA * kG * lA * std::cos(q);
    const double tauB = (IB + mB * lB * lB) * k * qdd + mB * kG * lB * std::cos(k * q + o);
    EXPECT_NEAR(data.effort[sA], tauA, kRel * ((IA + mA * lA * lA) * std::abs(qdd) + mA * kG * lA));
    EXPECT_NEAR(data.effort[sB], tauB,
                kRel * ((IB + mB * lB * lB) * std::abs(k * qdd) + mB * kG * lB));
  }
}

// ---------------------------------------------------------------------------------
// Lumped fixed joints.

// A link A turning about a tilted axis carries a link B on a fixed joint (offset and
// turned, B's inertia axes turned again). Combined by hand with the parallel-axis
// theorem, A + B is one body: its loads are the fixed-axis Newton-Euler closed form, and
// the same as those of a URDF with a single link holding the combined inertia.
TEST(LumpedFixedJoint, EqualsOneLinkWithTheCombinedInertia) {
  const Vec3 u = Vec3(0.3, -0.5, 0.8).normalized();
  const Vec3 j_xyz(0.1, 0.2, 0.3), j_rpy(0.2, -0.1, 0.4);
  const Inertial A{1.3, Vec3(0.1, 0.02, -0.03), Vec3(0.1, 0.2, 0.3),
                   inertiaMatrix(0.012, 0.010, 0.007, 0.0005, -0.0003, 0.0002)};
  const Inertial B{0.7, Vec3(0.03, 0.01, 0.02), Vec3(0.4, -0.2, 0.1),
                   inertiaMatrix(0.004, 0.003, 0.0025, -0.0002, 0.0001, 0.0003)};
  const Vec3 bolt_xyz(0.25, -0.05, 0.1), bolt_rpy(-0.3, 0.5, 0.2);

  // By hand, in A's frame.
  const Mat3 R_bolt = rpyMatrix(bolt_rpy);
  const Vec3 cA = A.xyz, cB = bolt_xyz + R_bolt * B.xyz;
  const Mat3 RA = rpyMatrix(A.rpy), RB = R_bolt * rpyMatrix(B.rpy);
  const Mat3 JA = RA * A.inertia * RA.transpose(), JB = RB * B.inertia * RB.transpose();
  const double m = A.mass + B.mass;
  const Vec3 c = (A.mass * cA + B.mass * cB) / m;
  auto parallel = [](double mk, const Vec3& d) {
    return Mat3(mk * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
  };
  const Mat3 J = JA + parallel(A.mass, cA - c) + JB + parallel(B.mass, cB - c);

  const std::string hinge = joint("hinge", "revolute", "world", "a", j_xyz, j_rpy, u);
  const jle::Model<double> lumped =
      jle::modelFromUrdfString(robot(link("world") + link("a", A) + link("b", B) + hinge +
                                     joint("bolt", "fixed", "a", "b", bolt_xyz, bolt_rpy)));
  const jle::Model<double> single = jle::modelFromUrdfString(
      robot(link("world") + link("a", Inertial{m, c, Vec3::Zero(), J}) + hinge));
  ASSERT_EQ(lumped.nsegments(), 2);
  const int sl = lumped.segmentOfJoint("hinge"), ss = single.segmentOfJoint("hinge");
  jle::Data<double> dl(lumped), ds(single);
  const Vec3 gravity(0, 0, -kG);
  const Mat3 R_joint = rpyMatrix(j_rpy);

  jle_test::Random rng(51);
  jle_test::UniformIn angle(-M_PI, M_PI), rate(-6.0, 6.0), acc(-40.0, 40.0);
  for (int trial = 0; trial < 30; ++trial) {
    const double q = angle(rng), qd = rate(rng), qdd = acc(rng);
    jle::forwardKinematics(lumped, dl, vecx({q}), vecx({qd}), vecx({qdd}), gravity);
    jle::inverseDynamics(lumped, dl);
    jle::forwardKinematics(single, ds, vecx({q}), vecx({qd}), vecx({qdd}), gravity);
    jle::inverseDynamics(single, ds);

    const Mat3 R_world_a = R_joint * rotation(u, q);
    const Loads e = fixedAxisBody(m, c, J, u, qd, qdd, R_world_a.transpose() * gravity);
    const double force_scale = m * (c.norm() * (qd * qd + std::abs(qdd)) + kG);
    const double moment_scale = J.norm() * (qd * qd + std::abs(qdd)) + c.norm() * force_scale;
    expectNear(dl.force[sl], e.force, force_scale, "lumped force");
    expectNear(dl.moment[sl], e.moment, moment_scale, "lumped moment");
    expectNear(ds.force[ss], e.force, force_scale, "single force");
    expectNear(ds.moment[ss], e.moment, moment_scale, "single moment");
    EXPECT_NEAR(dl.effort[sl], u.dot(e.moment), kRel * moment_scale);
  }
}

// A planar arm world -j1-> a -sensor (fixed, kept)-> b -j2-> c, gravity along -y: the
// wrench across the sensor mount is the weight and inertial load of b and c, with its
// moment about the mount, worked out from the planar kinematics of b and c.
TEST(KeptFixedJoint, SensorWrenchIsTheDistalNewtonEuler) {
  const double mA = 2.0, mB = 0.5, mC = 1.1;
  const double IB = 0.0011, IC = 0.013;  // I_zz [kg m^2]
  const Vec3 cA(0.2, 0.01, 0), cB(0.03, -0.02, 0), cC(0.18, 0.03, 0);
  const double LA = 0.4, LB = 0.08, psi = 0.35;  // mount offset and yaw, j2 offset in b
  const std::string body =
      link("world") + link("a", Inertial{mA, cA, Vec3::Zero(), inertiaMatrix(0.01, 0.03, 0.035)}) +
      link("b", Inertial{mB, cB, Vec3::Zero(), inertiaMatrix(0.0005, 0.0007, IB)}) +
      link("c", Inertial{mC, cC, Vec3::Zero(), inertiaMatrix(0.002, 0.012, IC)}) +
      joint("j1", "revolute", "world", "a") +
      joint("sensor", "fixed", "a", "b", Vec3(LA, 0, 0), Vec3(0, 0, psi)) +
      joint("j2", "revolute", "b", "c", Vec3(LB, 0, 0));
  jle::ModelOptions options;
  options.keep_fixed_joints = {"sensor"};
  const jle::Model<double> model = jle::modelFromUrdfString(robot(body), options);
  ASSERT_EQ(model.nsegments(), 4);
  ASSERT_EQ(model.nq, 2);
  const int s = model.segmentOfJoint("sensor");
  EXPECT_EQ(model.joint_type[s], jle::JointType::kFixed);
  jle::Data<double> data(model);
  const Eigen::Vector2d g(0, -kG);

  jle_test::Random rng(52);
  jle_test::UniformIn angle(-M_PI, M_PI), rate(-5.0, 5.0), acc(-30.0, 30.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double q1 = angle(rng), q2 = angle(rng);
    const double qd1 = rate(rng), qd2 = rate(rng), qdd1 = acc(rng), qdd2 = acc(rng);
    jle::forwardKinematics(model, data, vecx({q1, q2}), vecx({qd1, qd2}), vecx({qdd1, qdd2}),
                           Vec3(g.x(), g.y(), 0));
    jle::inverseDynamics(model, data);

    // Planar rigid-body kinematics: a_P = a_O + alpha z x (P - O) - omega^2 (P - O).
    auto rot = [](double a) { return Eigen::Rotation2Dd(a).toRotationMatrix(); };
    auto accel = [](const Eigen::Vector2d& a_O, double w, double al, const Eigen::Vector2d& r) {
      return Eigen::Vector2d(a_O.x() - al * r.y() - w * w * r.x(),
                             a_O.y() + al * r.x() - w * w * r.y());
    };
    const double phiB = q1 + psi, phiC = q1 + psi + q2;
    const double wB = qd1, alB = qdd1, wC = qd1 + qd2, alC = qdd1 + qdd2;
    const Eigen::Vector2d x_S = rot(q1) * Eigen::Vector2d(LA, 0);
    const Eigen::Vector2d r_SB = rot(phiB) * cB.head<2>();
    const Eigen::Vector2d r_SJ = rot(phiB) * Eigen::Vector2d(LB, 0);
    const Eigen::Vector2d r_JC = rot(phiC) * cC.head<2>();
    const Eigen::Vector2d a_S = accel(Eigen::Vector2d::Zero(), qd1, qdd1, x_S);
    const Eigen::Vector2d a_GB = accel(a_S, wB, alB, r_SB);
    const Eigen::Vector2d a_J = accel(a_S, wB, alB, r_SJ);
    const Eigen::Vector2d a_GC = accel(a_J, wC, alC, r_JC);
    const Eigen::Vector2d FB = mB * (a_GB - g), FC = mC * (a_GC - g);
    const Eigen::Vector2d F_world = FB + FC;
    const double M_z = IB * alB + IC * alC + cross2(r_SB, FB) + cross2(r_SJ + r_JC, FC);
    const Eigen::Vector2d F_b = rot(-phiB) * F_world;  // in the sensor (b) frame

    const double force_scale = FB.norm() + FC.norm();
    const double moment_scale = IB * std::abs(alB) + IC * std::abs(alC) + r_SB.norm() * FB.norm() +
                                (r_SJ + r_JC).norm() * FC.norm();
    expectNear(data.force[s], Vec3(F_b.x(), F_b.y(), 0), force_scale, "sensor force");
    expectNear(data.moment[s], Vec3(0, 0, M_z), moment_scale, "sensor moment");
    EXPECT_EQ(data.effort[s], 0.0);
  }
}

// ---------------------------------------------------------------------------------
// Bad models are refused with a message naming the culprit.

// A valid two-link robot with `arm` replaced, or with extra elements.
std::string twoLinks(const std::string& arm_inertial, const std::string& extra = "",
                     const std::string& shoulder_axis = "0 0 1") {
  return "<robot name=\"r\">"
         "<link name=\"base\"><inertial><mass value=\"1\"/>"
         "<inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial>"
         "</link>"
         "<link name=\"arm\">" +
         arm_inertial +
         "</link>"
         "<joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/>"
         "<child link=\"arm\"/><axis xyz=\"" +
         shoulder_axis + "\"/></joint>" + extra + "</robot>";
}

std::string inertial(const std::string& mass, const std::string& ixx, const std::string& iyy,
                     const std::string& izz, const std::string& ixy = "0") {
  return "<inertial><mass value=\"" + mass + "\"/><inertia ixx=\"" + ixx + "\" ixy=\"" + ixy +
         "\" ixz=\"0\" iyy=\"" + iyy + "\" iyz=\"0\" izz=\"" + izz + "\"/></inertial>";
}

// An arm that is sound: 2 kg, a valid inertia.
std::string soundArm() { return inertial("2", "0.1", "0.1", "0.1"); }

// A joint `name` of `type` from the arm to link `child`, `inside` within the element.
std::string armJoint(const std::string& name, const std::string& type, const std::string& child,
                     const std::string& inside = "") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"arm\"/><child link=\"" +
         child + "\"/>" + inside + "</joint>";
}

// The message of the ModelError that parsing `xml` throws ("" and a failure if none).
std::string refusal(const std::string& xml, const jle::ModelOptions& options = {}) {
  try {
    jle::modelFromUrdfString(xml, options);
  } catch (const jle::ModelError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted:\n" << xml;
  return "";
}

TEST(BadModel, ValidTemplateIsAccepted) {
  // The refusals below come from their one defect, not from the template.
  const jle::Model<double> model = jle::modelFromUrdfString(twoLinks(soundArm()));
  EXPECT_EQ(model.nq, 1);
  EXPECT_TRUE(model.warnings.empty());
}

TEST(BadModel, NegativeMass) {
  EXPECT_THAT(refusal(twoLinks(inertial("-2", "0.1", "0.1", "0.1"))),
              AllOf(HasSubstr("'arm'"), HasSubstr("negative mass")));
}

TEST(BadModel, InertiaNotPositiveSemiDefinite) {
  // Principal moments -1, 1, 3.
  EXPECT_THAT(refusal(twoLinks(inertial("2", "1", "1", "1", "2"))),
              AllOf(HasSubstr("'arm'"), HasSubstr("positive semi-definite")));
}

TEST(BadModel, TriangleInequality) {
  // 0.1 + 0.1 < 1: violated by 80%, far beyond the 5% default tolerance.
  EXPECT_THAT(refusal(twoLinks(inertial("2", "0.1", "0.1", "1"))),
              AllOf(HasSubstr("'arm'"), HasSubstr("triangle")));
  // 0.5 + 0.5 < 1.02: violated by 2%, accepted with a warning naming the link...
  const std::string slight = twoLinks(inertial("2", "0.5", "0.5", "1.02"));
  const jle::Model<double> model = jle::modelFromUrdfString(slight);
  ASSERT_EQ(model.warnings.size(), 1u);
  EXPECT_THAT(model.warnings[0], AllOf(HasSubstr("'arm'"), HasSubstr("triangle")));
  // ...and refused below a 1% tolerance.
  jle::ModelOptions strict;
  strict.triangle_tolerance = 0.01;
  EXPECT_THAT(refusal(slight, strict), AllOf(HasSubstr("'arm'"), HasSubstr("triangle")));
}

TEST(BadModel, ZeroLengthAxis) {
  EXPECT_THAT(refusal(twoLinks(soundArm(), "", "0 0 0")),
              AllOf(HasSubstr("'shoulder'"), HasSubstr("zero length")));
}

TEST(BadModel, LinkChildOfTwoJoints) {
  const std::string second =
      "<joint name=\"shortcut\" type=\"fixed\"><parent link=\"base\"/>"
      "<child link=\"arm\"/></joint>";
  EXPECT_THAT(refusal(twoLinks(soundArm(), second)),
              AllOf(HasSubstr("'arm'"), HasSubstr("'shoulder'"), HasSubstr("'shortcut'")));
}

TEST(BadModel, ClosedCycleUnreachableFromTheRoot) {
  const std::string cycle =
      "<link name=\"p\"/><link name=\"r\"/>"
      "<joint name=\"pr\" type=\"fixed\"><parent link=\"p\"/><child link=\"r\"/></joint>"
      "<joint name=\"rp\" type=\"fixed\"><parent link=\"r\"/><child link=\"p\"/></joint>";
  EXPECT_THAT(refusal(twoLinks(soundArm(), cycle)),
              AllOf(HasSubstr("'p'"), HasSubstr("'r'"), HasSubstr("loop")));
}

TEST(BadModel, TwoRoots) {
  EXPECT_THAT(refusal(twoLinks(soundArm(), "<link name=\"orphan\"/>")),
              AllOf(HasSubstr("'base'"), HasSubstr("'orphan'"), HasSubstr("root")));
}

TEST(BadModel, UnknownLinkInJoint) {
  EXPECT_THAT(refusal(twoLinks(soundArm(), armJoint("haunt", "fixed", "ghost"))),
              AllOf(HasSubstr("'haunt'"), HasSubstr("'ghost'")));
}

TEST(BadModel, MalformedXml) {
  EXPECT_THAT(refusal("<robot name=\"r\"><link name=\"a\"></robot>"), HasSubstr("malformed XML"));
}

TEST(BadModel, NonNumericAttribute) {
  EXPECT_THAT(refusal(twoLinks(inertial("heavy", "0.1", "0.1", "0.1"))),
              AllOf(HasSubstr("'arm'"), HasSubstr("'heavy'")));
  EXPECT_THAT(refusal(twoLinks(soundArm(), "", "0 0 one")),
              AllOf(HasSubstr("'shoulder'"), HasSubstr("'0 0 one'")));
}

TEST(BadModel, MimicOfUnknownJoint) {
  const std::string finger =
      "<link name=\"finger\"/>" +
      armJoint("finger_joint", "prismatic", "finger", "<mimic joint=\"no_such_joint\"/>");
  EXPECT_THAT(refusal(twoLinks(soundArm(), finger)),
              AllOf(HasSubstr("'finger_joint'"), HasSubstr("'no_such_joint'")));
}

TEST(BadModel, ZeroTotalMass) {
  EXPECT_THAT(refusal(robot(link("world") + link("a") + joint("j", "revolute", "world", "a"))),
              HasSubstr("total mass"));
}

TEST(BadModel, PlanarJoint) {
  const std::string plane = "<link name=\"puck\"/>" + armJoint("table", "planar", "puck");
  EXPECT_THAT(refusal(twoLinks(soundArm(), plane)),
              AllOf(HasSubstr("'table'"), HasSubstr("planar")));
}

TEST(BadModel, FloatingJointBelowTheRoot) {
  const std::string drone = "<link name=\"drone\"/>" + armJoint("hover", "floating", "drone");
  EXPECT_THAT(refusal(twoLinks(soundArm(), drone)),
              AllOf(HasSubstr("'hover'"), HasSubstr("floating")));
}

TEST(BadModel, MissingFileIsNamed) {
  try {
    jle::modelFromUrdfFile("/nonexistent/robot.urdf");
    ADD_FAILURE() << "a missing file was accepted";
  } catch (const jle::ModelError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/robot.urdf"));
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
