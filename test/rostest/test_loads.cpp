// Node tests of the loads themselves (loads.test): the real joint_load_estimator node,
// driven through its topics under a simulated clock, must publish the loads that the core
// library computes from the exact trajectory (q, qd, qdd known in closed form here).
//
// Every node of loads.test lives in its own namespace (/fd, /epoch, /sg, /tf_wrench,
// /floating); the tests send samples one at a time and wait for each publication, so the
// node's input queues never overflow and the order of events is the order of sending.
#include "node_test_common.hpp"

#include <joint_load_estimator/io/portable_random.hpp>

#include <geometry_msgs/TransformStamped.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>

namespace {

using namespace jle_test;

const std::string kData = JLE_TEST_DATA;
const std::string kUr5 = kData + "/urdf/chains/ur5_chain.urdf";
const std::string kPanda = kData + "/urdf/chains/panda_chain.urdf";
const std::string kTwoLink = std::string(JLE_ROSTEST_DIR) + "/two_link_floating.urdf";

/// q = q0 + v0 s + a s^2 / 2, s = time since `origin` (exact nanosecond arithmetic, so the
/// positions are those of a robot sampled at the true stamps).
struct Quadratic {
  ros::Time origin;
  VectorXd q0, v0, a;
  double s(const ros::Time& t) const { return (t - origin).toSec(); }
  VectorXd q(const ros::Time& t) const { return q0 + v0 * s(t) + 0.5 * a * s(t) * s(t); }
  VectorXd qd(const ros::Time& t) const { return v0 + a * s(t); }
};

/// A smooth trajectory: q_j = c_j + sum_m A_jm sin(w_m s + phi_jm), with its derivatives.
struct SumOfSines {
  ros::Time origin;
  VectorXd c;
  Eigen::MatrixXd amplitude, phase;  // joints x components
  Eigen::VectorXd omega;             // [rad/s] per component
  VectorXd derivative(const ros::Time& t, int order) const {
    const double s = (t - origin).toSec();
    VectorXd out = order == 0 ? c : VectorXd::Zero(c.size());
    for (int j = 0; j < c.size(); ++j)
      for (int m = 0; m < omega.size(); ++m)
        // d^n/ds^n sin(x) = sin(x + n pi/2).
        out[j] += amplitude(j, m) * std::pow(omega[m], order) *
                  std::sin(omega[m] * s + phase(j, m) + order * M_PI / 2);
    return out;
  }
};

// Stamps 1 ms apart with +-0.3 ms of jitter (whole nanoseconds, fixed seed).
std::vector<ros::Time> jitteredStamps(const ros::Time& first, int n, unsigned seed) {
  jle::PortableRandom random(seed);
  std::vector<ros::Time> stamps{first};
  for (int k = 1; k < n; ++k) {
    const int jitter = random.index(600001) - 300000;  // [ns]
    stamps.push_back(stamps.back() + ros::Duration(0, 1000000 + jitter));
  }
  return stamps;
}

// The q, q-dot, q-ddot the message's loads were computed from: the 3-point estimate, exact
// for a quadratic, so the trajectory's own, to rounding (positions to 1e-12 rad; the
// differences amplify it by 1 / dt and 4 / dt^2: 1e-9 rad/s, 1e-7 rad/s^2, see kExactRel;
// a sample off by one is 1e-3 or more); friction off: no motor_effort.
void expectCoordinates(const joint_load_estimator::JointLoads& msg, const VectorXd& q,
                       const VectorXd& qd, const VectorXd& qdd) {
  const std::size_t n = static_cast<std::size_t>(q.size());
  ASSERT_EQ(msg.position.size(), n);
  ASSERT_EQ(msg.velocity.size(), n);
  ASSERT_EQ(msg.acceleration.size(), n);
  for (std::size_t j = 0; j < n; ++j) {
    const Eigen::Index i = static_cast<Eigen::Index>(j);
    EXPECT_NEAR(msg.position[j], q[i], 1e-12) << msg.name[j];
    EXPECT_NEAR(msg.velocity[j], qd[i], 1e-9) << msg.name[j];
    EXPECT_NEAR(msg.acceleration[j], qdd[i], 1e-7) << msg.name[j];
  }
  EXPECT_TRUE(msg.motor_effort.empty());
}

// Drives `node` (finite_difference: 3-point warm-up) with a quadratic trajectory at
// `stamps` and returns the largest relative deviation from the reference over all the
// publications; checks that each stamp after the warm-up is published exactly once with
// the joint state's stamp and its measured efforts.
double runQuadratic(NodeUnderTest& node, Reference& ref, const Quadratic& traj,
                    const std::vector<ros::Time>& stamps) {
  const std::size_t before = node.loads().size();
  double worst = 0.0;
  for (std::size_t k = 0; k < stamps.size(); ++k) {
    const ros::Time& t = stamps[k];
    sensor_msgs::JointState js = jointState(t, ref.model.coordinate_names, traj.q(t));
    for (int j = 0; j < ref.model.nq; ++j) js.effort.push_back(10.0 * j + 0.001 * k);
    node.send(js);
    if (k < 2) continue;  // the 3-point filter's warm-up
    const auto msg = node.loads().waitForStamp(t);
    if (!msg) {
      ADD_FAILURE() << node.name() << ": no loads stamped " << t << " (sample " << k << ")";
      return 1.0;
    }
    EXPECT_EQ(msg->header.stamp, t);
    ref.compute(traj.q(t), traj.qd(t), traj.a);
    worst = std::max(worst, ref.relativeError(*msg));
    // The measured effort of each joint, paired with the same stamp; names are the
    // model's moving joints, which here are its coordinates in the same order.
    EXPECT_EQ(msg->name, ref.model.coordinate_names);
    for (std::size_t j = 0; j < msg->measured_effort.size() && j < js.effort.size(); ++j)
      EXPECT_EQ(msg->measured_effort[j], js.effort[j]) << msg->name[j];
    expectCoordinates(*msg, traj.q(t), traj.qd(t), traj.a);
  }
  // One publication per sample after the warm-up: nothing from the warm-up samples.
  EXPECT_EQ(node.loads().size() - before, stamps.size() - 2);
  return worst;
}

Quadratic ur5Quadratic(const ros::Time& origin) {
  Quadratic traj;
  traj.origin = origin;
  traj.q0.resize(6);
  traj.v0.resize(6);
  traj.a.resize(6);
  traj.q0 << 0.3, -1.1, 1.4, -0.9, 1.2, 0.4;
  traj.v0 << 0.8, -0.5, 1.2, 0.9, -1.1, 1.5;
  traj.a << 2.0, -3.0, 4.0, -1.5, 5.0, -6.0;
  return traj;
}

// Tolerance of the exactness tests. The 3-point formula is exact for a quadratic, so the
// node's loads differ from the reference by rounding alone: positions |q| < 3 rad rounded
// to 2.2e-16 relative (< 7e-16 rad), amplified by the second difference (~4 / dt^2 <=
// 8e6 /s^2 for steps >= 0.7 ms), give qdd errors up to ~5e-9 rad/s^2 (the node's time
// axis starts at its first stamp, so the stamps add nothing comparable). Through the
// inertias about the joints (< 0.5 kg m^2) that is < 3e-9 N m against joint wrench norms
// |F| + |M| >= 2 (the lightest wrist): relative ~1e-9 if every rounding fell the same
// way; measured 6e-11 (UR5), 1.5e-10 (floating base, whose base position adds its own).
// Any wrong term (a missing Coriolis term, a stamp off by one sample) is 1e-2 or more.
constexpr double kExactRel = 1e-9;

TEST(Loads, FiniteDifferenceIsExactForConstantAccelerations) {
  NodeUnderTest node("fd");
  ASSERT_TRUE(node.connect());
  Reference ref(kUr5);
  ASSERT_EQ(ref.model.nq, 6);
  const ros::Time origin(5, 0);
  const double worst = runQuadratic(node, ref, ur5Quadratic(origin), jitteredStamps(origin, 40, 1));
  std::printf("finite_difference, UR5, stamps near 5 s: largest relative error %.3g\n", worst);
  EXPECT_LT(worst, kExactRel);
}

// The same at stamps of today's wall clock (1.7e9 s since 1970), as a robot without
// simulation or a bag recorded from one stamps its joint states. A double holds such a
// time to 2.4e-7 s only: differentiating with it would make qdd wrong by ~v * 2.4e-7 s *
// 4 / dt^2 ~ 1 rad/s^2, and the published stamp would not be the joint state's.
TEST(Loads, FiniteDifferenceIsExactAtWallClockStamps) {
  NodeUnderTest node("epoch");
  ASSERT_TRUE(node.connect());
  Reference ref(kUr5);
  const ros::Time origin(1700000000, 123456789);
  const double worst = runQuadratic(node, ref, ur5Quadratic(origin), jitteredStamps(origin, 40, 2));
  std::printf("finite_difference, UR5, stamps near 1.7e9 s: largest relative error %.3g\n", worst);
  EXPECT_LT(worst, kExactRel);
}

// A Savitzky-Golay filter (window W = 9, order 2, delay 0: causal), fed only
// positions of a sum of sines at 1 kHz. Its error is truncation, predictable from the
// Taylor series of the signal about the newest sample t: the least-squares quadratic over
// the W samples at t + h (s + c), s = -(W-1)/2..(W-1)/2, c = -(W-1)/2 (the window's
// centre, in samples), fits the cubic Taylor term (s + c)^3 with s^3 ~ alpha s
// (alpha = S4/S2, Sn = sum s^n), so its derivatives at t are off by
//   qdd: c h q'''                       = -4 h q'''    (the fit lags by (W-1)/2 samples)
//   qd:  (alpha - 3 c^2) h^2 q''' / 6   = -6.0 h^2 q'''
// and the quartic term (s^4 ~ a + b s^2, b = (W S6 - S2 S4) / (W S4 - S2^2)) adds
//   qdd: (2 b + 12 c^2) h^2 q'''' / 24  = +9.4 h^2 q''''.
// The loads are affine in qdd and smooth in qd, so their predicted error is
// ID(q, qd + dqd, qdd + dqdd) - ID(q, qd, qdd). The next terms are smaller by another
// factor ~ (W/2)^2 (h w)^2 ~ 1e-3 at w = 4.4 rad/s; the test asserts that every component's
// error is the prediction to within 1% of the joint's largest predicted component
// (+1e-6 N, N m for components that are ~0): a filter with another lag, window or weight
// would miss by the whole prediction. Measured (500 samples, 492 publications): largest
// effort error 0.043 N m (of efforts up to 24 N m: the lag is 4 ms of change of the
// acceleration); largest deviation from the prediction 1.3e-4 of it.
TEST(Loads, SavitzkyGolayConvergesToTheTruncationBound) {
  NodeUnderTest node("sg");
  ASSERT_TRUE(node.connect());
  Reference ref(kPanda);
  const int n = ref.model.nq;
  ASSERT_EQ(n, 7);
  SumOfSines traj;
  traj.origin = ros::Time(20, 0);
  traj.c.resize(n);
  traj.c << 0.1, -0.4, 0.2, -2.0, 0.3, 1.6, 0.5;
  traj.omega.resize(3);
  traj.omega << 2 * M_PI * 0.3, 2 * M_PI * 0.5, 2 * M_PI * 0.7;
  traj.amplitude.resize(n, 3);
  traj.phase.resize(n, 3);
  for (int j = 0; j < n; ++j)
    for (int m = 0; m < 3; ++m) {
      traj.amplitude(j, m) = 0.2 / (m + 1) * (1.0 + 0.1 * j);
      traj.phase(j, m) = 0.7 * j + 1.3 * m;
    }
  // The truncation coefficients of the window (see above).
  const int window = 9;
  const double h = 1e-3;
  const double c = -0.5 * (window - 1);
  double S2 = 0.0, S4 = 0.0, S6 = 0.0;
  for (int k = 0; k < window; ++k) {
    const double x = k + c;
    S2 += x * x;
    S4 += x * x * x * x;
    S6 += x * x * x * x * x * x;
  }
  const double alpha = S4 / S2;
  const double b = (window * S6 - S2 * S4) / (window * S4 - S2 * S2);
  const double dqdd_3 = c * h, dqd_3 = (alpha - 3 * c * c) * h * h / 6,
               dqdd_4 = (2 * b + 12 * c * c) * h * h / 24;

  const int samples = 500;
  double worst_effort = 0.0, worst_fraction = 0.0, largest_effort = 0.0;
  jle::Data<double> predicted_data(ref.model);
  for (int k = 0; k < samples; ++k) {
    const ros::Time t = traj.origin + ros::Duration(0, 1000000 * k);
    node.send(jointState(t, ref.model.coordinate_names, traj.derivative(t, 0)));
    if (k < window - 1) continue;
    const auto msg = node.loads().waitForStamp(t);
    ASSERT_TRUE(msg) << "no loads stamped " << t;
    const VectorXd q = traj.derivative(t, 0), qd = traj.derivative(t, 1),
                   qdd = traj.derivative(t, 2), q3 = traj.derivative(t, 3),
                   q4 = traj.derivative(t, 4);
    jle::forwardKinematics(ref.model, predicted_data, q, VectorXd(qd + dqd_3 * q3),
                           VectorXd(qdd + dqdd_3 * q3 + dqdd_4 * q4), ref.gravity);
    jle::inverseDynamics(ref.model, predicted_data);
    ref.compute(q, qd, qdd);
    for (std::size_t j = 0; j < msg->name.size(); ++j) {
      const std::size_t s = static_cast<std::size_t>(ref.model.segmentOfJoint(msg->name[j]));
      const auto& w = msg->wrench[j];
      Eigen::Matrix<double, 7, 1> got, truth, predicted;
      got << w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z, msg->effort[j];
      truth << ref.data.force[s], ref.data.moment[s], ref.data.effort[s];
      predicted << predicted_data.force[s], predicted_data.moment[s], predicted_data.effort[s];
      const Eigen::Matrix<double, 7, 1> error = got - truth, expected = predicted - truth;
      const double size = expected.cwiseAbs().maxCoeff();
      const double deviation = (error - expected).cwiseAbs().maxCoeff();
      EXPECT_LE(deviation, 0.01 * size + 1e-6)
          << msg->name[j] << " at " << t << ": error " << error.transpose() << ", predicted "
          << expected.transpose();
      worst_effort = std::max(worst_effort, std::abs(error[6]));
      largest_effort = std::max(largest_effort, std::abs(truth[6]));
      if (size > 1e-4) worst_fraction = std::max(worst_fraction, deviation / size);
    }
  }
  EXPECT_EQ(node.loads().size(), static_cast<std::size_t>(samples - (window - 1)));
  std::printf(
      "savitzky_golay 9/2/0, panda, 1 kHz sum of sines: largest effort error %.4g N m "
      "(largest effort %.3g N m); largest deviation from the prediction %.2g of it\n",
      worst_effort, largest_effort, worst_fraction);
}

// A wrench whose header.frame_id is a frame the URDF does not have ("ft_sensor"), known
// only to tf2 through a static transform from the tool link: the node must apply it as
// the same wrench expressed in the tool link's frame.
TEST(Loads, WrenchInATf2FrameEqualsTheSameWrenchInTheLinkFrame) {
  NodeUnderTest node("tf_wrench");
  ASSERT_TRUE(node.connect());
  ros::Publisher wrench_pub =
      nh().advertise<geometry_msgs::WrenchStamped>("/tf_wrench/wrench", 100);
  ASSERT_TRUE(waitForSubscriber(wrench_pub, node.name()));

  // tool0 -> ft_sensor: 90 degrees about z, offset (0.01, -0.02, 0.05) m.
  tf2_ros::StaticTransformBroadcaster static_broadcaster;
  geometry_msgs::TransformStamped X;
  X.header.stamp = ros::Time(30, 0);
  X.header.frame_id = "tool0";
  X.child_frame_id = "ft_sensor";
  X.transform.translation.x = 0.01;
  X.transform.translation.y = -0.02;
  X.transform.translation.z = 0.05;
  X.transform.rotation.w = std::sqrt(0.5);
  X.transform.rotation.z = std::sqrt(0.5);
  static_broadcaster.sendTransform(X);
  // The broadcaster's latched message reaches each listener as it connects; connecting
  // takes a few hundred ms (XML-RPC), longer than this test's samples: wait for the
  // node's listener through a handle on the same (shared, latched) publication.
  ros::Publisher tf_static = nh().advertise<tf2_msgs::TFMessage>("/tf_static", 100, true);
  ASSERT_TRUE(waitForSubscriber(tf_static, node.name()));

  // The wrench in ft_sensor: f = (3, -1, 12) N, m = (0.2, 0.1, -0.3) N m. In tool0, by
  // hand: R (x, y, z) = (-y, x, z), so f = (1, 3, 12) and R m = (-0.1, 0.2, -0.3); the
  // moment moves to the tool0 origin by adding p x f = (0.01, -0.02, 0.05) x (1, 3, 12)
  // = (-0.39, -0.07, 0.05): m = (-0.49, 0.13, -0.25).
  const Vector3d f_link(1.0, 3.0, 12.0), m_link(-0.49, 0.13, -0.25);

  Reference ref(kUr5);
  VectorXd q(6);
  q << 0.2, -1.0, 1.3, -0.5, 0.8, -0.3;
  const VectorXd zero = VectorXd::Zero(6);
  ref.compute(q, zero, zero, jle::BaseState<double>(), "tool0", f_link, m_link);
  jle::Data<double> unloaded(ref.model);
  jle::rnea(ref.model, unloaded, q, zero, zero, ref.gravity);

  // The wrench and the joint states at the same stamps, the wrench a few samples ahead
  // so that the node holds it when the joint state comes. Until the node's tf2 listener
  // (its own thread) has stored the transform, the node drops the wrench and its loads
  // carry none: wait for the loads to carry it, then require every later publication to.
  const ros::Time start(30, 0);
  auto stamp = [&](int k) { return start + ros::Duration(0, 1000000 * k); };
  auto sendWrench = [&](int k) {
    geometry_msgs::WrenchStamped w;
    w.header.stamp = stamp(k);
    w.header.frame_id = "ft_sensor";
    w.wrench.force.x = 3.0;
    w.wrench.force.y = -1.0;
    w.wrench.force.z = 12.0;
    w.wrench.torque.x = 0.2;
    w.wrench.torque.y = 0.1;
    w.wrench.torque.z = -0.3;
    wrench_pub.publish(w);
  };
  const int lead = 5;
  for (int k = 0; k < lead; ++k) sendWrench(k);
  int first_loaded = -1;
  double worst = 0.0;
  for (int k = 0; k < 300 && (first_loaded < 0 || k < first_loaded + 20); ++k) {
    sendWrench(k + lead);
    node.send(jointState(stamp(k), ref.model.coordinate_names, q));
    if (k < 2) continue;
    const auto msg = node.loads().waitForStamp(stamp(k));
    ASSERT_TRUE(msg) << "no loads stamped " << stamp(k);
    const double error = ref.relativeError(*msg);
    if (first_loaded < 0 && error < kExactRel) first_loaded = k;
    if (first_loaded >= 0) worst = std::max(worst, error);
  }
  ASSERT_GE(first_loaded, 0) << "the loads never carried the wrench given in ft_sensor";
  std::printf("wrench in a tf2 frame: carried from sample %d, largest relative error %.3g\n",
              first_loaded, worst);
  EXPECT_LT(worst, kExactRel);
  // The wrench matters: without it the loads are far from these.
  const int wrist = ref.model.segmentOfJoint("wrist_3_joint");
  EXPECT_GT((unloaded.force[wrist] - ref.data.force[wrist]).norm(), 10.0);
}

// ---------------------------------------------------------------------------------
// Floating base: the base pose comes from tf2 (world -> torso), its velocity and
// acceleration are estimated by the same filter as the joints.

class FloatingBase : public ::testing::Test {
 protected:
  FloatingBase()
      : node_("floating"),
        ref_(kTwoLink, true),
        residual_("/floating/joint_load_estimator/base_residual"),
        tf_pub_(nh().advertise<tf2_msgs::TFMessage>("/tf", 100)) {}

  void SetUp() override {
    ASSERT_TRUE(node_.connect());
    ASSERT_TRUE(residual_.connectTo(node_.name()));
    // The node's tf2 listener connected: no pose is lost.
    ASSERT_TRUE(waitForSubscriber(tf_pub_, node_.name()));
  }

  struct Motion {
    Eigen::Quaterniond orientation;
    Vector3d p0, v0, a;  // base position, world frame
    Quadratic joints;
  };

  void sendPose(const Motion& m, const ros::Time& t) {
    geometry_msgs::TransformStamped X;
    X.header.stamp = t;
    X.header.frame_id = "world";
    X.child_frame_id = "torso";
    const double s = (t - m.joints.origin).toSec();
    const Vector3d p = m.p0 + m.v0 * s + 0.5 * m.a * s * s;
    X.transform.translation.x = p.x();
    X.transform.translation.y = p.y();
    X.transform.translation.z = p.z();
    X.transform.rotation.w = m.orientation.w();
    X.transform.rotation.x = m.orientation.x();
    X.transform.rotation.y = m.orientation.y();
    X.transform.rotation.z = m.orientation.z();
    tf2_msgs::TFMessage msg;
    msg.transforms.push_back(X);
    tf_pub_.publish(msg);
  }

  // Runs `samples` samples 1 ms apart from the motion's origin; checks the loads and the
  // base residual against the reference at every publication. Returns the largest
  // relative errors of the loads and of the residual.
  std::pair<double, double> run(const Motion& m, int samples) {
    auto stamp = [&](int k) { return m.joints.origin + ros::Duration(0, 1000000 * k); };
    // Every pose on tf2 first: the node's listener stores them on its own thread, and a
    // joint state whose pose it does not hold yet is dropped.
    for (int k = 0; k < samples; ++k) sendPose(m, stamp(k));
    double worst_loads = 0.0, worst_residual = 0.0;
    int published = 0, residuals = 0;
    for (int k = 0; k < samples; ++k) {
      const ros::Time t = stamp(k);
      node_.send(jointState(t, ref_.model.coordinate_names, m.joints.q(t)));
      if (k < 2) continue;
      // Until the first publication, a sample may have come before its pose (dropped):
      // wait a little for each, then go on; from then on every sample is published.
      const auto loads = node_.loads().waitForStamp(t, published == 0 ? 0.1 : kTimeout);
      if (!loads && published == 0 && k < 20) continue;
      if (!loads) {
        ADD_FAILURE() << "no loads stamped " << t;
        break;
      }
      ++published;
      const double s = (t - m.joints.origin).toSec();
      jle::BaseState<double> base;
      base.R_world_base = m.orientation.toRotationMatrix();
      base.p_world_base = m.p0 + m.v0 * s + 0.5 * m.a * s * s;
      base.v_world = m.v0 + m.a * s;
      base.a_world = m.a;
      ref_.compute(m.joints.q(t), m.joints.qd(t), m.joints.a, base);
      worst_loads = std::max(worst_loads, ref_.relativeError(*loads));

      // The residual is published only to subscribers; the node may learn of ours a
      // little after we learn of it, so it is required from the first one received on.
      geometry_msgs::WrenchStamped::ConstPtr residual;
      if (!residual_.msgs().empty())
        waitFor([&] {
          for (const auto& r : residual_.msgs())
            if (r->header.stamp == t) residual = r;
          return residual != nullptr;
        });
      if (!residual_.msgs().empty() && !residual) {
        ADD_FAILURE() << "no base residual stamped " << t;
        break;
      }
      if (!residual) continue;
      ++residuals;
      EXPECT_EQ(residual->header.frame_id, "torso");
      const Vector3d f(residual->wrench.force.x, residual->wrench.force.y,
                       residual->wrench.force.z);
      const Vector3d n(residual->wrench.torque.x, residual->wrench.torque.y,
                       residual->wrench.torque.z);
      const double scale = ref_.data.force[0].norm() + ref_.data.moment[0].norm();
      worst_residual = std::max(worst_residual, (f - ref_.data.force[0]).norm() / scale);
      worst_residual = std::max(worst_residual, (n - ref_.data.moment[0]).norm() / scale);
      last_residual_force_ = f;
    }
    EXPECT_GE(published, samples - 10) << "loads published";
    EXPECT_GE(residuals, published - 5) << "base residuals received";
    return {worst_loads, worst_residual};
  }

  Motion motion(const ros::Time& origin) const {
    Motion m;
    m.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Vector3d::UnitZ()) *
                                       Eigen::AngleAxisd(-0.1, Vector3d::UnitY()) *
                                       Eigen::AngleAxisd(0.2, Vector3d::UnitX()));
    m.p0 = Vector3d(0.3, -0.2, 0.1);
    m.v0.setZero();
    m.a.setZero();
    m.joints.origin = origin;
    m.joints.q0 = Eigen::Vector2d(0.4, -0.7);
    m.joints.v0 = Eigen::Vector2d::Zero();
    m.joints.a = Eigen::Vector2d::Zero();
    return m;
  }

  NodeUnderTest node_;
  Reference ref_;
  Recorder<geometry_msgs::WrenchStamped> residual_;
  ros::Publisher tf_pub_;
  Vector3d last_residual_force_ = Vector3d::Zero();
};

// At rest, the world holds the whole weight: the base residual's force is m_total g
// upwards, expressed in the torso frame, m_total = 3 + 1.5 + 1 = 5.5 kg.
TEST_F(FloatingBase, AtRestTheResidualCarriesTheWeight) {
  const Motion m = motion(ros::Time(40, 0));
  const auto worst = run(m, 20);
  std::printf("floating base at rest: largest relative error loads %.3g, residual %.3g\n",
              worst.first, worst.second);
  EXPECT_LT(worst.first, kExactRel);
  EXPECT_LT(worst.second, kExactRel);
  const Vector3d weight_torso =
      m.orientation.toRotationMatrix().transpose() * Vector3d(0.0, 0.0, 5.5 * 9.80665);
  // The residual's error is that of the loads (kExactRel, see above) of 54 N.
  EXPECT_NEAR((last_residual_force_ - weight_torso).norm(), 0.0, kExactRel * 54.0);
}

// The base translating with a constant acceleration, the joints with constant
// accelerations: finite differences are exact, so are the loads and the residual.
TEST_F(FloatingBase, ConstantAccelerationIsExact) {
  Motion m = motion(ros::Time(50, 0));
  m.v0 = Vector3d(0.3, -0.2, 0.5);
  m.a = Vector3d(1.5, 2.0, -3.0);
  m.joints.v0 = Eigen::Vector2d(1.0, -0.8);
  m.joints.a = Eigen::Vector2d(-4.0, 6.0);
  const auto worst = run(m, 30);
  std::printf("floating base accelerating: largest relative error loads %.3g, residual %.3g\n",
              worst.first, worst.second);
  EXPECT_LT(worst.first, kExactRel);
  EXPECT_LT(worst.second, kExactRel);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_loads");
  return RUN_ALL_TESTS();
}
