// Node tests of predicted against measured (consistency.test): a wrist
// force/torque sensor at the fixed joint ft_joint of wrist_sensor_arm.urdf,
// with a 0.8 kg tool beyond it. The residual (~consistency/ft_joint) of a
// reading equal to the prediction, of an unmodelled contact (worked by hand),
// the loads of the joints proximal to the sensor, the bias calibration
// (~calibrate_bias) of a biased noisy sensor and its reuse by a second node
// through bias_file, and the floating base's residual diagnostic.
#include <geometry_msgs/TransformStamped.h>
#include <joint_load_estimator/CalibrateBias.h>
#include <signal.h>
#include <sys/wait.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <fstream>
#include <functional>
#include <future>
#include <sstream>

#include "node_test_common.hpp"

#include <jle_testing/wrist_sensor_arm.hpp>
#include <joint_load_estimator/io/portable_random.hpp>

namespace {

using namespace jle_test;
using Eigen::Vector2d;
using geometry_msgs::WrenchStamped;

using jle_test::wrist_sensor_arm::j2EffortAtRest;
using jle_test::wrist_sensor_arm::kG;
using jle_test::wrist_sensor_arm::staticReading;
const std::string kUrdf = jle_test::wrist_sensor_arm::urdf();
const Vector3d kTip = jle_test::wrist_sensor_arm::tip();  // ft_sensor frame [m]
const Vector2d kStill(0.4, 0.3);                          // the still posture [rad]

// Rounding of a still posture: the 3-point filter's weights sum to one to
// ~1e-12 on readings of ~8 N (test_sensor_joint.cpp).
constexpr double kStillTol = 1e-9;
// Moving (quadratic, 3-point differences exact): second differences of samples
// 1 ms apart lose ~1e-16 / 1e-6 of the acceleration, times masses and lever
// arms ~1.
constexpr double kMovingTol = 1e-7;

Vector3d force(const WrenchStamped& w) {
  return Vector3d(w.wrench.force.x, w.wrench.force.y, w.wrench.force.z);
}
Vector3d torque(const WrenchStamped& w) {
  return Vector3d(w.wrench.torque.x, w.wrench.torque.y, w.wrench.torque.z);
}

// A still or moving posture and the sensor's reading at a stamp.
struct Sample {
  VectorXd q;
  Vector3d f, m;
};

// The still posture and the reading of the tool's weight alone, at any stamp.
Sample still(const ros::Time&) {
  Sample s{kStill, {}, {}};
  staticReading(kStill[1], s.f, s.m);
  return s;
}

// One sensor node: its joint states, its sensor topic, its residual.
class SensorNode {
 public:
  explicit SensorNode(const std::string& ns)
      : node(ns),
        wrench_pub(nh().advertise<WrenchStamped>("/" + ns + "/ft/wrench", 1000)),
        residual("/" + ns + "/joint_load_estimator/consistency/ft_joint"),
        names{"j1", "j2"} {}

  ::testing::AssertionResult connect() {
    const ::testing::AssertionResult ok = node.connect();
    if (!ok) return ok;
    if (!waitForSubscriber(wrench_pub, node.name()))
      return ::testing::AssertionFailure() << node.name() << " did not subscribe to ft/wrench";
    if (!residual.connectTo(node.name()))
      return ::testing::AssertionFailure() << "no connection to the residual of " << node.name();
    return ::testing::AssertionSuccess();
  }

  // Sends samples 1 ms apart from `origin` (each wrench `kLead` samples ahead
  // of the joint state of its stamp, so that the node holds it when the joint
  // state comes; no more than its timeout plus ten joint periods ahead of the
  // joint states, or it is a rogue stamp: docs/node.md "Time stamps") and calls check(t, residual)
  // for every residual, until `samples` are sent or stop() holds. Returns the number of residuals
  // checked (all but the warm-up and the first few that came before their reading).
  static constexpr int kLead = 5;
  int run(
      const ros::Time& origin, int samples, const std::function<Sample(const ros::Time&)>& at,
      const std::function<void(const ros::Time&, const WrenchStamped&)>& check,
      const std::function<bool()>& stop = [] { return false; }) {
    auto stamp = [&](int k) { return origin + ros::Duration(0, 1000000 * k); };
    auto sendWrench = [&](int k) {
      const Sample s = at(stamp(k));
      WrenchStamped w;
      w.header.stamp = stamp(k);
      w.header.frame_id = "ft_sensor";
      w.wrench.force = tf2::toMsg(s.f, w.wrench.force);
      w.wrench.torque = tf2::toMsg(s.m, w.wrench.torque);
      wrench_pub.publish(w);
    };
    // The run's first joint state before its first readings: a reading is taken only
    // within its timeout plus ten joint periods ahead of the joint states (docs/node.md "Time
    // stamps"), and a run starts seconds after the last one, so readings sent first
    // would be rogue or not depending on which connection the node serves first.
    node.send(jointState(stamp(0), names, at(stamp(0)).q));
    waitFor([] { return false; }, 0.05);
    for (int k = 0; k < kLead; ++k) sendWrench(k);
    int checked = 0;
    for (int k = 0; k < samples && !stop(); ++k) {
      const ros::Time t = stamp(k);
      sendWrench(k + kLead);
      if (k > 0) node.send(jointState(t, names, at(t).q));
      if (k < 2) continue;  // the 3-point filter's warm-up
      // The first wrenches of a run may come after its first joint states
      // (another connection): with a 0.5 ms timeout and the stop policy
      // (consistency.test) the node publishes nothing until it holds the
      // reading of the sample's stamp. So each sample waits a little until the
      // first residual, then every one must come.
      WrenchStamped::ConstPtr r;
      waitFor(
          [&] {
            for (auto it = residual.msgs().rbegin(); it != residual.msgs().rend() && !r; ++it)
              if ((*it)->header.stamp == t) r = *it;
            return r != nullptr;
          },
          checked == 0 ? 0.1 : kTimeout);
      if (!r && checked == 0 && k < 20) continue;
      if (!r) {
        ADD_FAILURE() << node.name() << ": no residual stamped " << t;
        break;
      }
      EXPECT_EQ(r->header.frame_id, "ft_sensor");
      check(t, *r);
      ++checked;
    }
    return checked;
  }

  NodeUnderTest node;
  ros::Publisher wrench_pub;
  Recorder<WrenchStamped> residual;
  std::vector<std::string> names;
};

// Waits for a consistency diagnostic of `node` (its full name) at `level` whose
// message contains `part`.
bool waitForConsistencyStatus(const std::string& node, std::uint8_t level,
                              const std::string& part) {
  const std::string name = node.substr(1) + ": consistency";
  return waitFor([&] {
    for (const auto& a : diagnostics().msgs())
      for (const auto& s : a->status)
        if (s.name == name && s.level == level && s.message.find(part) != std::string::npos)
          return true;
    return false;
  });
}

// ---------------------------------------------------------------------------------

// (1) A reading equal to the prediction: residual zero, still (closed form) and
// moving (the joint wrench of the exact motion, from the core, as a simulated
// sensor).
TEST(Consistency, ReadingEqualToPredictionGivesZeroResidual) {
  SensorNode arm("arm");
  ASSERT_TRUE(arm.connect());
  double worst = 0.0;
  const int n_still =
      arm.run(ros::Time(10, 0), 30, still, [&](const ros::Time&, const WrenchStamped& r) {
        worst = std::max({worst, force(r).cwiseAbs().maxCoeff(), torque(r).cwiseAbs().maxCoeff()});
      });
  EXPECT_GE(n_still, 20);
  std::printf("reading = prediction, still: largest residual component %.3g\n", worst);
  EXPECT_LT(worst, kStillTol);

  // Moving: q = q0 + v0 s + a s^2 / 2; 1 s after the still samples (a gap
  // beyond max_gap: the filter restarts).
  jle::ModelOptions options;
  options.keep_fixed_joints = {"ft_joint"};
  const jle::Model<double> model = jle::modelFromUrdfFile(kUrdf, options);
  jle::Data<double> data(model);
  const int s_ft = model.segmentOfJoint("ft_joint");
  const ros::Time origin(12, 0);
  const Vector2d q0(0.2, -0.4), v0(0.9, -1.2), a(3.0, 4.0);
  auto moving = [&](const ros::Time& t) {
    const double s = (t - origin).toSec();
    Sample out{q0 + v0 * s + 0.5 * a * s * s, {}, {}};
    jle::forwardKinematics(model, data, out.q, VectorXd(v0 + a * s), VectorXd(a),
                           Vector3d(0, 0, -kG));
    jle::inverseDynamics(model, data);
    out.f = data.force[s_ft];  // ft_sensor is the segment's frame, origin the
                               // joint's
    out.m = data.moment[s_ft];
    return out;
  };
  worst = 0.0;
  const int n_moving = arm.run(origin, 40, moving, [&](const ros::Time&, const WrenchStamped& r) {
    worst = std::max({worst, force(r).cwiseAbs().maxCoeff(), torque(r).cwiseAbs().maxCoeff()});
  });
  EXPECT_GE(n_moving, 30);
  std::printf("reading = prediction, moving: largest residual component %.3g\n", worst);
  EXPECT_LT(worst, kMovingTol);
  EXPECT_TRUE(
      waitForConsistencyStatus(arm.node.name(), diagnostic_msgs::DiagnosticStatus::OK, "agree"));
}

// (2) An unmodelled push c on the tool tip, not given to the node: the sensor
// reads the prediction minus c moved to its origin. The residual is (-c, -p_tip
// x c) in the sensor frame (the wrench the tool exerts on what pushes it); the
// joints proximal to the sensor carry the contact: j2's effort by hand, every
// load against the core with c applied.
TEST(Consistency, UnmodelledContact) {
  SensorNode arm("arm");
  ASSERT_TRUE(arm.connect());
  const Vector3d c(3.0, -2.0,
                   5.0);  // [N] on the tool tip, ft_sensor axes (|c| = 6.2 N)
  auto pushed = [&](const ros::Time& t) {
    Sample s = still(t);
    s.f -= c;
    s.m -= kTip.cross(c);
    return s;
  };
  const Vector3d m_expected = -kTip.cross(c);  // (-0.4, -0.6, 0) N m
  double worst = 0.0;
  const ros::Time origin(20, 0);
  const int n = arm.run(origin, 30, pushed, [&](const ros::Time&, const WrenchStamped& r) {
    worst = std::max({worst, (force(r) + c).cwiseAbs().maxCoeff(),
                      (torque(r) - m_expected).cwiseAbs().maxCoeff()});
  });
  EXPECT_GE(n, 20);
  std::printf("unmodelled contact: largest residual error %.3g\n", worst);
  EXPECT_LT(worst, kStillTol);

  // j2 at rest, in closed form (the weights of link2 and the tool, the push at the tip).
  const double tau2 = j2EffortAtRest(kStill[1], c);
  const auto loads = arm.node.loads().find(origin + ros::Duration(0, 1000000 * 29));
  ASSERT_TRUE(loads);
  ASSERT_EQ(loads->name.size(), 2u);
  EXPECT_EQ(loads->name[1], "j2");
  EXPECT_NEAR(loads->effort[1], tau2, kStillTol);
  Reference ref(kUrdf);
  ref.compute(kStill, VectorXd::Zero(2), VectorXd::Zero(2), jle::BaseState<double>(), "tool_tip",
              c);
  EXPECT_LT(ref.relativeError(*loads), kStillTol);
  EXPECT_TRUE(waitForConsistencyStatus(arm.node.name(), diagnostic_msgs::DiagnosticStatus::WARN,
                                       "residual force"));
}

// (2b) The sensor of (1) declared with sign -1: its still readings, negated by the
// sign, are the opposite of the prediction, and the diagnostics name the sensor and its
// sign (sensor_sign.hpp; the same readings with sign 1 agree, test (1)).
TEST(Consistency, AWrongSignIsNamed) {
  SensorNode flipped("flipped");
  ASSERT_TRUE(flipped.connect());
  const int n =
      flipped.run(ros::Time(15, 0), 40, still, [](const ros::Time&, const WrenchStamped&) {});
  EXPECT_GE(n, 30);
  EXPECT_TRUE(waitForConsistencyStatus(flipped.node.name(), diagnostic_msgs::DiagnosticStatus::WARN,
                                       "sign wrong"));
}

// ---------------------------------------------------------------------------------
// (3), (4) Bias calibration on /calib; the node started afterwards with the
// bias file.

const Vector3d kBiasForce(0.7, -0.4, 1.2);      // [N]
const Vector3d kBiasTorque(0.05, -0.03, 0.02);  // [N m]

// The still reading with the sensor's bias and no noise, at any stamp.
Sample stillWithBias(const ros::Time& t) {
  Sample s = still(t);
  s.f += kBiasForce;
  s.m += kBiasTorque;
  return s;
}
constexpr double kSigmaForce = 0.05;    // [N]
constexpr double kSigmaTorque = 0.005;  // [N m]
const std::string kCalibrate = "/calib/joint_load_estimator/calibrate_bias";
long g_calibration_samples = 0;  // N of the calibration, for the reload test

using joint_load_estimator::CalibrateBias;

// Calls the service on its own thread while `node` is fed `at` (the node must
// keep computing loads to collect its window). Returns the response.
CalibrateBias::Response calibrateWhile(SensorNode& node, const ros::Time& origin,
                                       const std::function<Sample(const ros::Time&)>& at,
                                       double duration, bool assume_still,
                                       const std::string& service = kCalibrate) {
  EXPECT_TRUE(ros::service::waitForService(service, 10000));
  std::future<CalibrateBias::Response> result = std::async(std::launch::async, [&] {
    CalibrateBias srv;
    srv.request.duration = duration;
    srv.request.assume_still = assume_still;
    EXPECT_TRUE(ros::service::call(service, srv));
    return srv.response;
  });
  auto ready = [&] {
    return result.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  };
  node.run(
      origin, 5000, at, [](const ros::Time&, const WrenchStamped&) {}, ready);
  return result.get();
}

TEST(Calibration, RefusedWhileMoving) {
  SensorNode calib("calib");
  ASSERT_TRUE(calib.connect());
  const ros::Time origin(30, 0);
  auto moving = [&](const ros::Time& t) {
    // 0.5 rad/s on j1, far above still_velocity (0.02 rad/s). The reading is
    // the static one (the centripetal terms, ~0.1 N, do not matter: the request
    // is refused).
    Sample s{kStill + Vector2d(0.5 * (t - origin).toSec(), 0.0), {}, {}};
    staticReading(kStill[1], s.f, s.m);
    return s;
  };
  const CalibrateBias::Response res = calibrateWhile(calib, origin, moving, 0.2, false);
  EXPECT_FALSE(res.success);
  EXPECT_NE(res.message.find("not still"), std::string::npos) << res.message;
  EXPECT_NE(res.message.find("j1"), std::string::npos) << res.message;
}

TEST(Calibration, RecoversTheBiasWithinItsNoise) {
  SensorNode calib("calib");
  ASSERT_TRUE(calib.connect());
  jle::PortableRandom random(20240611);
  auto biased = [&](const ros::Time& t) {
    Sample s = still(t);
    for (int i = 0; i < 3; ++i) {
      s.f[i] += kBiasForce[i] + kSigmaForce * random.gaussian();
      s.m[i] += kBiasTorque[i] + kSigmaTorque * random.gaussian();
    }
    return s;
  };
  const double duration = 0.5;  // 500 samples 1 ms apart
  const CalibrateBias::Response res =
      calibrateWhile(calib, ros::Time(40, 0), biased, duration, false);
  ASSERT_TRUE(res.success) << res.message;
  ASSERT_EQ(res.sensors.size(), 1u);
  EXPECT_EQ(res.sensors[0], "ft_joint");
  long n = 0;
  const std::size_t from = res.message.find("from ");
  ASSERT_NE(from, std::string::npos) << res.message;
  n = std::stol(res.message.substr(from + 5));
  EXPECT_GE(n, 500);  // the window spans 0.5 s of stamps: 501 samples
  g_calibration_samples = n;
  // The mean of n independent samples: |error| < 4 sigma / sqrt(n) per
  // component (a 4-sigma bound: each component fails with probability 6e-5, the
  // seed is fixed).
  const double bf = 4.0 * kSigmaForce / std::sqrt(n), bt = 4.0 * kSigmaTorque / std::sqrt(n);
  const geometry_msgs::Wrench& b = res.bias[0];
  const geometry_msgs::Wrench& sd = res.stddev[0];
  std::printf(
      "calibration from %ld samples: bias error force (%.3g %.3g %.3g) "
      "N (bound %.3g), "
      "torque (%.3g %.3g %.3g) N m (bound %.3g); spread force (%.3g "
      "%.3g %.3g) torque "
      "(%.3g %.3g %.3g)\n",
      n, b.force.x - kBiasForce.x(), b.force.y - kBiasForce.y(), b.force.z - kBiasForce.z(), bf,
      b.torque.x - kBiasTorque.x(), b.torque.y - kBiasTorque.y(), b.torque.z - kBiasTorque.z(), bt,
      sd.force.x, sd.force.y, sd.force.z, sd.torque.x, sd.torque.y, sd.torque.z);
  EXPECT_NEAR(b.force.x, kBiasForce.x(), bf);
  EXPECT_NEAR(b.force.y, kBiasForce.y(), bf);
  EXPECT_NEAR(b.force.z, kBiasForce.z(), bf);
  EXPECT_NEAR(b.torque.x, kBiasTorque.x(), bt);
  EXPECT_NEAR(b.torque.y, kBiasTorque.y(), bt);
  EXPECT_NEAR(b.torque.z, kBiasTorque.z(), bt);
  // The spread is the noise (finite differences pass readings through
  // unfiltered): the sample standard deviation of n = 500 is within 4 / sqrt(2
  // n) = 13 % of sigma.
  for (double s : {sd.force.x, sd.force.y, sd.force.z})
    EXPECT_NEAR(s, kSigmaForce, 0.13 * kSigmaForce);
  for (double s : {sd.torque.x, sd.torque.y, sd.torque.z})
    EXPECT_NEAR(s, kSigmaTorque, 0.13 * kSigmaTorque);

  std::string path;
  ASSERT_TRUE(ros::param::get("/consistency_test/bias_file", path));
  EXPECT_EQ(res.file, path);
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  EXPECT_NE(text.str().find("ft_joint:"), std::string::npos) << text.str();

  // Applied: noise-free readings with the bias now give a residual of the
  // estimate's error only (after the filter's 3-sample memory of readings from
  // before).
  const ros::Time origin(42, 0);
  double worst_f = 0.0, worst_m = 0.0;
  calib.run(origin, 20, stillWithBias, [&](const ros::Time&, const WrenchStamped& r) {
    worst_f = std::max(worst_f, force(r).cwiseAbs().maxCoeff());
    worst_m = std::max(worst_m, torque(r).cwiseAbs().maxCoeff());
  });
  EXPECT_LT(worst_f, bf + kStillTol);
  EXPECT_LT(worst_m, bt + kStillTol);
}

// A node started with bias_file = what the calibration wrote applies it from
// its first sample.
TEST(Calibration, ASecondNodeLoadsTheBiasFile) {
  ASSERT_GT(g_calibration_samples, 0) << "needs RecoversTheBiasWithinItsNoise";
  const std::string exe = JLE_NODE;
  const pid_t pid = fork();
  if (pid == 0) {
    execl(exe.c_str(), exe.c_str(), "__ns:=reload", "__name:=joint_load_estimator",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  ASSERT_GT(pid, 0);
  {
    SensorNode reload("reload");
    const bool connected = reload.connect();
    EXPECT_TRUE(connected);
    if (connected) {
      const double bf = 4.0 * kSigmaForce / std::sqrt(g_calibration_samples),
                   bt = 4.0 * kSigmaTorque / std::sqrt(g_calibration_samples);
      double worst_f = 0.0, worst_m = 0.0;
      const int n = reload.run(ros::Time(50, 0), 20, stillWithBias,
                               [&](const ros::Time&, const WrenchStamped& r) {
                                 worst_f = std::max(worst_f, force(r).cwiseAbs().maxCoeff());
                                 worst_m = std::max(worst_m, torque(r).cwiseAbs().maxCoeff());
                               });
      EXPECT_GE(n, 10);
      std::printf(
          "node started with the bias file: largest residual force "
          "%.3g N, torque %.3g N m\n",
          worst_f, worst_m);
      EXPECT_LT(worst_f, bf + kStillTol);
      EXPECT_LT(worst_m, bt + kStillTol);
    }
  }
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  std::string path;
  if (ros::param::get("/consistency_test/bias_file", path)) std::remove(path.c_str());
}

// ---------------------------------------------------------------------------------
// (5) Floating base: in free fall nothing but gravity acts (residual zero: OK);
// at rest the world must hold the whole weight (5.5 kg, 54 N > 10 % of it):
// WARN.

TEST(FloatingBase, ResidualDiagnostic) {
  NodeUnderTest node("floating");
  ASSERT_TRUE(node.connect());
  ros::Publisher tf_pub = nh().advertise<tf2_msgs::TFMessage>("/tf", 1000);
  ASSERT_TRUE(waitForSubscriber(tf_pub, node.name()));
  const std::vector<std::string> names{"hip", "knee"};
  const VectorXd q = Vector2d(0.4, -0.7);
  auto runBase = [&](const ros::Time& origin, const Vector3d& a, int samples) {
    auto stamp = [&](int k) { return origin + ros::Duration(0, 1000000 * k); };
    for (int k = 0; k < samples; ++k) {
      geometry_msgs::TransformStamped X;
      X.header.stamp = stamp(k);
      X.header.frame_id = "world";
      X.child_frame_id = "torso";
      const double s = 1e-3 * k;
      X.transform.translation.z = 1.0 + 0.5 * a.z() * s * s;
      X.transform.rotation.w = 1.0;
      tf2_msgs::TFMessage msg;
      msg.transforms.push_back(X);
      tf_pub.publish(msg);
    }
    int published = 0;
    for (int k = 0; k < samples; ++k) {
      node.send(jointState(stamp(k), names, q));
      if (k >= 2 && node.loads().waitForStamp(stamp(k), published == 0 ? 0.1 : kTimeout))
        ++published;
    }
    return published;
  };
  const std::string name = "floating/joint_load_estimator: consistency";
  EXPECT_GE(runBase(ros::Time(60, 0), Vector3d(0, 0, -kG), 60), 50);
  // Every diagnosis so far: free fall is consistent.
  int seen = 0;
  for (const auto& a : diagnostics().msgs())
    for (const auto& s : a->status)
      if (s.name == name) {
        ++seen;
        EXPECT_EQ(s.level, diagnostic_msgs::DiagnosticStatus::OK) << s.message;
      }
  EXPECT_GT(seen, 0);
  EXPECT_GE(runBase(ros::Time(70, 0), Vector3d::Zero(), 60), 50);
  EXPECT_TRUE(waitForConsistencyStatus(node.name(), diagnostic_msgs::DiagnosticStatus::WARN,
                                       "base residual force"));

  // No sensor here: calibrate_bias is refused, saying why.
  const std::string service = "/floating/joint_load_estimator/calibrate_bias";
  ASSERT_TRUE(ros::service::waitForService(service, 10000));
  CalibrateBias srv;
  srv.request.duration = 0.1;
  ASSERT_TRUE(ros::service::call(service, srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("no force/torque sensor"), std::string::npos)
      << srv.response.message;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "consistency_test");
  return RUN_ALL_TESTS();
}
