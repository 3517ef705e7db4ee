// Node tests of the force plates (plates.test): the real joint_load_estimator node with
// a foot standing on a plate. The paper's planar foot (Federico & Alhasadi 2022,
// section 6) through the node, with a fixed ankle and a plate pose from the config, and
// with a floating, accelerating shank whose pose (and the plate's) comes from tf2; the
// sign conventions with hand-worked numbers; the contact threshold; effort_per_kg.
#include "node_test_common.hpp"

#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <Eigen/Geometry>

#include <cstdio>

namespace {

using namespace jle_test;
using Eigen::Vector2d;
using geometry_msgs::PointStamped;
using geometry_msgs::WrenchStamped;

constexpr double kG = 9.80665;

geometry_msgs::WrenchStamped plateMessage(const ros::Time& stamp, const std::string& frame,
                                          const Vector3d& f, const Vector3d& m) {
  WrenchStamped w;
  w.header.stamp = stamp;
  w.header.frame_id = frame;
  w.wrench.force.x = f.x();
  w.wrench.force.y = f.y();
  w.wrench.force.z = f.z();
  w.wrench.torque.x = m.x();
  w.wrench.torque.y = m.y();
  w.wrench.torque.z = m.z();
  return w;
}

Vector3d force(const JointLoads& msg) {
  return Vector3d(msg.wrench[0].force.x, msg.wrench[0].force.y, msg.wrench[0].force.z);
}
Vector3d torque(const JointLoads& msg) {
  return Vector3d(msg.wrench[0].torque.x, msg.wrench[0].torque.y, msg.wrench[0].torque.z);
}

double cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// ---------------------------------------------------------------------------------
// The planar foot of section 6 (planar_foot.urdf), in the x-y plane with gravity along
// -y: mass m, inertia J_G about G, the ankle A (the joint origin, the foot frame's
// origin), G = (0.075, -0.05) and the point P where the plate's force F_P acts,
// P = G + (b, -d), in the foot frame, which turns by theta about z. The 3x3 system:
//   F_A = m a_G - F_P - m g
//   M_A = J_G theta_dd - (xi_A x F_A)_z - (xi_P x F_P)_z,   xi = point - x_G.
// The plate lies in the lab with its surface at y = -0.02: its frame is the world's
// turned by -90 degrees about x (plate z = world y, plate y = world -z), its origin 0.04
// below the surface (surface_height 0.04) at (0.2, -0.06, 0) (plus the shank's offset in
// the floating setup). The plate measures -F_P acting at P, in its frame, moment about
// its origin.
struct PaperFoot {
  const double m = 1.2, J_G = 0.0065, b = 0.11, d = 0.04;
  const Vector2d G_foot{0.075, -0.05};
  const Vector2d ankle_shank{0.05, 0.08};
  const Vector3d plate_origin_shank{0.2, -0.06, 0.0};
  const double surface_y_shank = -0.02;
  // theta = theta0 + v s + a s^2 / 2; base (shank) position p0 + bv s + ba s^2 / 2, no rotation.
  const double theta0 = -0.1, v = 0.8, a = -3.0;
  Vector2d base0 = Vector2d::Zero(), base_v = Vector2d::Zero(), base_a = Vector2d::Zero();
  ros::Time origin;

  double s(const ros::Time& t) const { return (t - origin).toSec(); }
  double theta(const ros::Time& t) const { return theta0 + v * s(t) + 0.5 * a * s(t) * s(t); }
  Vector2d base(const ros::Time& t) const {
    return base0 + base_v * s(t) + 0.5 * base_a * s(t) * s(t);
  }
  // The force on the foot at P [N], world: linear in time (a rising stance).
  Vector2d F_P(const ros::Time& t) const {
    return Vector2d(40.0 + 200.0 * s(t), 650.0 + 500.0 * s(t));
  }
  Eigen::Matrix2d Q(const ros::Time& t) const {
    return Eigen::Rotation2Dd(theta(t)).toRotationMatrix();
  }
  Vector2d P_world(const ros::Time& t) const {
    return base(t) + ankle_shank + Q(t) * (G_foot + Vector2d(b, -d));
  }
  Vector3d plateOrigin(const ros::Time& t0) const {
    return plate_origin_shank + Vector3d(base(t0).x(), base(t0).y(), 0.0);
  }

  // What the plate measures at t: -F_P at P, in the plate frame (R^T v = (vx, -vz, vy)),
  // moment about the plate origin O.
  WrenchStamped plate(const ros::Time& t, const Vector3d& O) const {
    const Vector3d f_world(-F_P(t).x(), -F_P(t).y(), 0.0);
    const Vector3d P(P_world(t).x(), P_world(t).y(), 0.0);
    const Vector3d m_world = (P - O).cross(f_world);
    auto toPlate = [](const Vector3d& w) { return Vector3d(w.x(), -w.z(), w.y()); };
    return plateMessage(t, "force_plate_1", toPlate(f_world), toPlate(m_world));
  }

  // The expected centre of pressure in the plate frame: where F_P's line of action
  // through P meets the surface y = surface (world), then (x - Ox, -(z - Oz), y - Oy).
  Vector3d cop(const ros::Time& t, const Vector3d& O, double surface_world) const {
    const Vector2d P = P_world(t), F = F_P(t);
    const double lambda = (surface_world - P.y()) / F.y();
    const Vector2d C = P + lambda * F;
    return Vector3d(C.x() - O.x(), 0.0, C.y() - O.y());
  }

  struct Expected {
    Vector3d force_foot, moment_foot;  // ankle wrench on the foot, foot frame, about A
    double force_scale, moment_scale;
  };
  Expected ankle(const ros::Time& t) const {
    const double th_d = v + a * s(t), th_dd = a;
    const Eigen::Matrix2d R = Q(t);
    const Vector2d r = R * G_foot;  // ankle -> G, world
    // a_G: the ankle's (the base's) acceleration + tangential + centripetal.
    const Vector2d a_G = base_a + Vector2d(-th_dd * r.y() - th_d * th_d * r.x(),
                                           th_dd * r.x() - th_d * th_d * r.y());
    const Vector2d g(0.0, -kG);
    const Vector2d xi_A = -r, xi_P = R * Vector2d(b, -d);
    const Vector2d F_A = m * a_G - F_P(t) - m * g;
    const double M_A = J_G * th_dd - cross2(xi_A, F_A) - cross2(xi_P, F_P(t));
    Expected e;
    const Vector2d F_A_foot = R.transpose() * F_A;
    e.force_foot = Vector3d(F_A_foot.x(), F_A_foot.y(), 0.0);
    e.moment_foot = Vector3d(0.0, 0.0, M_A);
    e.force_scale = m * (a_G.norm() + kG) + F_P(t).norm();
    e.moment_scale = J_G * std::abs(th_dd) + r.norm() * F_A.norm() + xi_P.norm() * F_P(t).norm();
    return e;
  }
};

// Tolerance of the paper's foot: the node's finite differences are exact for the
// quadratic theta and base position, and the plate is sampled at the joint stamps (the
// filter's value at a sample is the sample): every difference is rounding. theta ~ 0.1
// rad rounded to 1.4e-17, over (2 ms)^2 / 4: qdd off by < 1e-11 rad/s^2 (the base
// position likewise, < 1e-10 m/s^2); the plate's moment (~200 N m about an origin 0.3 m
// away) is decoded to a COP by one division and carried back: ~1e-13 of it. Relative to
// the loads' scale (|F| ~ 700 N, |M| ~ 100 N m) that is < 1e-12; 1e-9 leaves room and
// still catches any wrong term (a sign, the moment taken about the COP instead of the
// plate origin, a missing base acceleration: 1e-3 or more).
constexpr double kExactRel = 1e-9;

// Checks one publication against the closed form; returns its largest relative error.
double checkPaper(const PaperFoot& foot, const JointLoads& msg, const ros::Time& t) {
  const PaperFoot::Expected e = foot.ankle(t);
  EXPECT_EQ(msg.name.size(), 1u);
  if (msg.name.size() != 1) return 1.0;
  EXPECT_EQ(msg.name[0], "ankle");
  const double ef = (force(msg) - e.force_foot).cwiseAbs().maxCoeff() / e.force_scale;
  const double em = (torque(msg) - e.moment_foot).cwiseAbs().maxCoeff() / e.moment_scale;
  const double ee = std::abs(msg.effort[0] - e.moment_foot.z()) / e.moment_scale;
  return std::max(ef, std::max(em, ee));
}

// Fixed ankle, plate pose from the config: every sample after the 3-point warm-up.
TEST(Plates, PapersPlanarFootThroughTheNode) {
  NodeUnderTest node("paper");
  ASSERT_TRUE(node.connect());
  ros::Publisher plate_pub = nh().advertise<WrenchStamped>("/paper/plate", 1000);
  ASSERT_TRUE(waitForSubscriber(plate_pub, node.name()));
  Recorder<PointStamped> cop("/paper/joint_load_estimator/cop/plate1");
  ASSERT_TRUE(cop.connectTo(node.name()));

  PaperFoot foot;
  foot.origin = ros::Time(10, 0);
  const Vector3d O = foot.plateOrigin(foot.origin);
  const int n = 40, lead = 5;
  auto stamp = [&](int k) { return foot.origin + ros::Duration(0, 2000000 * k); };
  // The plate samples `lead` samples ahead of the joint states. The first ones may reach
  // the node after its first joint states (the connections are distinct): the loads
  // are required to carry the plate from the first publication that does, at most a
  // few samples in, and exactly from then on.
  for (int k = 0; k < lead; ++k) plate_pub.publish(foot.plate(stamp(k), O));
  int first = -1;
  double worst = 0.0, worst_cop = 0.0;
  for (int k = 0; k < n; ++k) {
    if (k + lead < n) plate_pub.publish(foot.plate(stamp(k + lead), O));
    const ros::Time t = stamp(k);
    node.send(jointState(t, {"ankle"}, VectorXd::Constant(1, foot.theta(t))));
    if (k < 2) continue;
    const auto msg = node.loads().waitForStamp(t);
    ASSERT_TRUE(msg) << "no loads stamped " << t;
    const double error = checkPaper(foot, *msg, t);
    if (first < 0) {
      if (error >= kExactRel) {
        ASSERT_LT(k, 8) << "the loads do not carry the plate";
        continue;
      }
      first = k;
    }
    worst = std::max(worst, error);
    // effort_per_kg with body_mass -1: the URDF's mass, the foot's 1.2 kg.
    ASSERT_EQ(msg->effort_per_kg.size(), 1u);
    EXPECT_NEAR(msg->effort_per_kg[0], msg->effort[0] / 1.2, 1e-15 * std::abs(msg->effort[0]));
    // The COP, published before the loads on its own topic.
    PointStamped::ConstPtr c;
    ASSERT_TRUE(waitFor([&] {
      for (const auto& p : cop.msgs())
        if (p->header.stamp == t) c = p;
      return c != nullptr;
    })) << "no COP stamped "
        << t;
    EXPECT_EQ(c->header.frame_id, "force_plate_1");
    const Vector3d expected = foot.cop(t, O, foot.surface_y_shank);
    // The COP: rounding of one division (|M| / |F| ~ 0.3 m): 1e-12 m.
    worst_cop = std::max(
        worst_cop, (Vector3d(c->point.x, c->point.y, c->point.z) - expected).cwiseAbs().maxCoeff());
    EXPECT_NEAR(c->point.z, 0.04, 1e-15) << "the COP lies on the surface";
  }
  std::printf(
      "paper's foot, fixed ankle: exact from sample %d, largest relative error %.3g, "
      "COP error %.3g m\n",
      first, worst, worst_cop);
  EXPECT_LT(worst, kExactRel);
  EXPECT_LT(worst_cop, 1e-12);
}

// The shank a floating base accelerating in the plane, its pose on /tf; the plate's pose
// from /tf_static (world -> force_plate_1). The same closed form with the ankle's
// acceleration added to a_G.
TEST(Plates, PapersPlanarFootOnAFloatingShankWithTheLabPlateFromTf) {
  NodeUnderTest node("floating");
  ASSERT_TRUE(node.connect());
  ros::Publisher plate_pub = nh().advertise<WrenchStamped>("/floating/plate", 1000);
  ros::Publisher tf_pub = nh().advertise<tf2_msgs::TFMessage>("/tf", 1000);
  ASSERT_TRUE(waitForSubscriber(plate_pub, node.name()));
  ASSERT_TRUE(waitForSubscriber(tf_pub, node.name()));

  PaperFoot foot;
  foot.origin = ros::Time(20, 0);
  foot.base0 = Vector2d(0.3, 0.5);
  foot.base_v = Vector2d(1.2, -0.1);
  foot.base_a = Vector2d(-2.0, 4.0);
  const Vector3d O = foot.plateOrigin(foot.origin);  // the plate stays where the shank began

  tf2_ros::StaticTransformBroadcaster static_broadcaster;
  geometry_msgs::TransformStamped X;
  X.header.stamp = foot.origin;
  X.header.frame_id = "world";
  X.child_frame_id = "force_plate_1";
  X.transform.translation.x = O.x();
  X.transform.translation.y = O.y();
  X.transform.translation.z = O.z();
  X.transform.rotation.x = -std::sqrt(0.5);  // -90 degrees about x
  X.transform.rotation.w = std::sqrt(0.5);
  static_broadcaster.sendTransform(X);
  ros::Publisher tf_static = nh().advertise<tf2_msgs::TFMessage>("/tf_static", 100, true);
  ASSERT_TRUE(waitForSubscriber(tf_static, node.name()));

  const int n = 60, lead = 5;
  auto stamp = [&](int k) { return foot.origin + ros::Duration(0, 2000000 * k); };
  auto sendPose = [&](int k) {
    geometry_msgs::TransformStamped B;
    B.header.stamp = stamp(k);
    B.header.frame_id = "world";
    B.child_frame_id = "shank";
    B.transform.translation.x = foot.base(stamp(k)).x();
    B.transform.translation.y = foot.base(stamp(k)).y();
    B.transform.rotation.w = 1.0;
    tf2_msgs::TFMessage msg;
    msg.transforms.push_back(B);
    tf_pub.publish(msg);
  };
  for (int k = 0; k < n; ++k) sendPose(k);
  for (int k = 0; k < lead; ++k) plate_pub.publish(foot.plate(stamp(k), O));
  // Until the node's tf2 listener (its own thread) holds the plate's and the shank's
  // poses, it drops what it cannot place: wait for the first publication that carries
  // the plate, then require every later one to be exact.
  int first = -1, published = 0;
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    if (k + lead < n) plate_pub.publish(foot.plate(stamp(k + lead), O));
    const ros::Time t = stamp(k);
    node.send(jointState(t, {"ankle"}, VectorXd::Constant(1, foot.theta(t))));
    if (k < 2) continue;
    const auto msg = node.loads().waitForStamp(t, first < 0 ? 0.1 : kTimeout);
    if (!msg) {
      ASSERT_LT(first, 0) << "no loads stamped " << t;
      continue;
    }
    const double error = checkPaper(foot, *msg, t);
    if (first < 0 && error < kExactRel) first = k;
    if (first >= 0) {
      worst = std::max(worst, error);
      ++published;
    }
    EXPECT_TRUE(msg->effort_per_kg.empty()) << "body_mass 0: no effort_per_kg";
  }
  ASSERT_GE(first, 0) << "the loads never carried the plate";
  std::printf(
      "paper's foot, floating shank, plate from tf2: exact from sample %d, %d samples, "
      "largest relative error %.3g\n",
      first, published, worst);
  EXPECT_GE(published, 30);
  EXPECT_LT(worst, kExactRel);
}

// ---------------------------------------------------------------------------------
// Signs, by hand (standing_foot.urdf, q = 0, at rest: the foot frame is the world's).
// Ankle A = (0.1, 0, 0.08), foot mass 1 kg at G = A + (0.05, 0, -0.05). The plate frame
// is the world's translated to O = (0.3, 0.2, -0.04); its surface is 0.04 above O
// (world z = 0). The foot presses on the plate at the COP c = (-0.15, -0.19, 0.04) (plate
// frame; world (0.15, 0.01, 0)) with f = (50, -30, -700) N (into the plate: -z) and
// twists it by a free moment of 2 N m about +z. The plate reports the moment about O:
//   c x f = (-0.19 * -700 - 0.04 * -30, 0.04 * 50 - -0.15 * -700, -0.15 * -30 - -0.19 * 50)
//         = (134.2, -103, 14),   + (0, 0, 2) = (134.2, -103, 16).
// Decoded with the surface 0.04 above O, the COP is c again: x = (h fx - my) / fz =
// (2 + 103) / -700 = -0.15, y = (mx + h fy) / fz = (134.2 - 1.2) / -700 = -0.19. (Taking
// the moment as about the surface, h = 0, would give (-0.1471, -0.1917).)
// The foot receives F = -f = (-50, 30, 700) at c and -2 N m about z. The ankle wrench on
// the foot balances it and the weight (at rest):
//   F_A = -F - m g = (50, -30, -700 + 9.80665) = (50, -30, -690.19335)
//   M_A = -[(c - A) x F + (0, 0, -2) + (G - A) x m g]
//       = -[(9.4, -31, 2) + (0, 0, -2) + (0, 0.4903325, 0)] = (-9.4, 30.5096675, 0)
// with c - A = (0.05, 0.01, -0.08). The effort (axis y) is 30.5096675 N m.
// Below the threshold (20 N) the reading acts as measured, without a COP: f = (1, 0, -15)
// with m = (0.3, -0.2, 0) about O gives the foot (-1, 0, 15) and, about A,
// (-0.3, 0.2, 0) + (O - A) x (-1, 0, 15) = (2.7, -2.68, 0.2) with O - A = (0.2, 0.2, -0.12):
// F_A = (1, 0, -15 + 9.80665) = (1, 0, -5.19335),
// M_A = -[(2.7, -2.68, 0.2) + (0, 0.4903325, 0)] = (-2.7, 2.1896675, -0.2).
TEST(Plates, SignsByHand) {
  NodeUnderTest node("sign");
  ASSERT_TRUE(node.connect());
  ros::Publisher plate_pub = nh().advertise<WrenchStamped>("/sign/plate", 1000);
  ASSERT_TRUE(waitForSubscriber(plate_pub, node.name()));
  Recorder<PointStamped> cop("/sign/joint_load_estimator/cop/plate1");
  ASSERT_TRUE(cop.connectTo(node.name()));

  const Vector3d f_contact(50.0, -30.0, -700.0), m_contact(134.2, -103.0, 16.0);
  // 15 N pressing (below the 20 N threshold), with a moment: no COP, the wrench acts.
  const Vector3d f_noise(1.0, 0.0, -15.0), m_noise(0.3, -0.2, 0.0);
  // Phases of 10 samples: contact, below the threshold, contact again.
  const ros::Time start(40, 0);
  const int n = 30;
  auto stamp = [&](int k) { return start + ros::Duration(0, 1000000 * k); };
  auto inContact = [](int k) { return k < 10 || k >= 20; };
  auto sendPlate = [&](int k) {
    plate_pub.publish(plateMessage(stamp(k), "plate_sign", inContact(k) ? f_contact : f_noise,
                                   inContact(k) ? m_contact : m_noise));
  };
  // Rounding only (constant inputs, q = 0): 1e-12 of the 700 N and 30 N m.
  const double tol_f = 1e-12 * 700.0, tol_m = 1e-12 * 100.0;
  // The plate `lead` samples ahead; the loads must carry it from the first publication
  // that does (at most a few samples in: see the paper's test), exactly from then on.
  const int lead = 5;
  for (int k = 0; k < lead; ++k) sendPlate(k);
  int first = -1;
  for (int k = 0; k < n; ++k) {
    if (k + lead < n) sendPlate(k + lead);
    const ros::Time t = stamp(k);
    node.send(jointState(t, {"ankle"}, VectorXd::Zero(1)));
    if (k < 2) continue;
    const auto msg = node.loads().waitForStamp(t);
    ASSERT_TRUE(msg) << "no loads stamped " << t;
    const Vector3d F = force(*msg), M = torque(*msg);
    if (first < 0) {
      if (std::abs(F.x() - 50.0) > tol_f) {
        ASSERT_LT(k, 8) << "the loads do not carry the plate";
        continue;
      }
      first = k;
    }
    if (inContact(k)) {
      EXPECT_NEAR(F.x(), 50.0, tol_f) << k;
      EXPECT_NEAR(F.y(), -30.0, tol_f) << k;
      EXPECT_NEAR(F.z(), -690.19335, tol_f) << k;
      EXPECT_NEAR(M.x(), -9.4, tol_m) << k;
      EXPECT_NEAR(M.y(), 30.5096675, tol_m) << k;
      EXPECT_NEAR(M.z(), 0.0, tol_m) << k;
      EXPECT_NEAR(msg->effort[0], 30.5096675, tol_m) << k;
    } else {
      EXPECT_NEAR(F.x(), 1.0, tol_f) << k;
      EXPECT_NEAR(F.y(), 0.0, tol_f) << k;
      EXPECT_NEAR(F.z(), -5.19335, tol_f) << k;
      EXPECT_NEAR(M.x(), -2.7, tol_m) << k;
      EXPECT_NEAR(M.y(), 2.1896675, tol_m) << k;
      EXPECT_NEAR(M.z(), -0.2, tol_m) << k;
      EXPECT_NEAR(msg->effort[0], 2.1896675, tol_m) << k;
    }
    // body_mass 70 kg.
    ASSERT_EQ(msg->effort_per_kg.size(), 1u);
    EXPECT_NEAR(msg->effort_per_kg[0], msg->effort[0] / 70.0, 1e-15 * std::abs(msg->effort[0]));
  }
  // The COPs: one per published sample in contact, none below the threshold. The last
  // stamp's COP came after all the others (one connection keeps the order).
  ASSERT_TRUE(waitFor(
      [&] { return !cop.msgs().empty() && cop.msgs().back()->header.stamp == stamp(n - 1); }));
  int in_contact = 0;
  for (const auto& c : cop.msgs()) {
    if (c->header.stamp < stamp(first)) continue;
    const int k = static_cast<int>(std::lround((c->header.stamp - start).toSec() * 1000.0));
    EXPECT_TRUE(inContact(k)) << "a COP published below the threshold, sample " << k;
    EXPECT_EQ(c->header.frame_id, "plate_sign");
    // One division: 1e-15 m.
    EXPECT_NEAR(c->point.x, -0.15, 1e-15);
    EXPECT_NEAR(c->point.y, -0.19, 1e-15);
    EXPECT_NEAR(c->point.z, 0.04, 1e-15);
    ++in_contact;
  }
  EXPECT_EQ(in_contact, 10 - first + 10);  // samples first..9 and 20..29
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_plates");
  return RUN_ALL_TESTS();
}
