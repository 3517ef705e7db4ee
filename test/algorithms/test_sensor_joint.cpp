// A force/torque sensor at a fixed joint (WrenchInputConfig::sensor_joint): its
// prediction, its residual and the substitution of its reading for the joints
// proximal to it, against numbers worked by hand for wrist_sensor_arm.urdf and
// against the backward pass with the unmodelled contact applied as an external
// wrench.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <jle_testing/wrist_sensor_arm.hpp>
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/estimation/sensor_sign.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

using jle_test::wrist_sensor_arm::j2EffortAtRest;
using jle_test::wrist_sensor_arm::kG;
using jle_test::wrist_sensor_arm::staticReading;
const std::string kUrdf = jle_test::wrist_sensor_arm::urdf();
const Vector3d kTip = jle_test::wrist_sensor_arm::tip();  // sensor frame [m]
// Rounding: the readings pass through the 3-point filter, whose weights for
// samples 1 ms apart sum to one only to ~1e-12 (measured 2e-12 relative on the
// ~8 N reading), plus a few dozen operations on loads of order 10 N, 1 N m.
constexpr double kExact = 1e-10;

jle::Model<double> arm() {
  jle::ModelOptions options;
  options.keep_fixed_joints = {"ft_joint"};
  return jle::modelFromUrdfFile(kUrdf, options);
}

jle::EstimatorConfig sensorConfig() {
  jle::EstimatorConfig c;
  c.differentiator.type = jle::DifferentiatorType::kFiniteDifference;
  jle::WrenchInputConfig ft;
  ft.name = "ft";
  ft.sensor_joint = "ft_joint";
  c.wrenches.push_back(ft);
  return c;
}

// Feeds constant q and a constant reading until the estimator publishes.
void feedStill(jle::Estimator& e, const VectorXd& q, const Vector3d& f, const Vector3d& m) {
  for (int k = 0; k < 3; ++k) {
    const double t = 1.0 + 1e-3 * k;
    e.addWrench(0, t, f, m);
    const jle::SampleStatus status = e.addJointSample(t, q.data());
    if (k == 2) {
      ASSERT_EQ(status, jle::SampleStatus::kPublished);
    }
  }
}

// The loads with the contact (force c at the tool tip, sensor axes) applied as
// an external wrench: the other way of getting what the sensor substitution
// must give.
void referenceWithContact(const jle::Model<double>& model, jle::Data<double>& data,
                          const VectorXd& q, const VectorXd& qd, const VectorXd& qdd,
                          const Vector3d& c) {
  jle::forwardKinematics(model, data, q, qd, qdd, Vector3d(0, 0, -kG));
  jle::addExternalWrench(model, data, model.frameIndex("tool_tip"), c, Vector3d(Vector3d::Zero()),
                         jle::WrenchFrame::kLocal);
  jle::inverseDynamics(model, data);
}

TEST(SensorJoint, ReadingEqualToPredictionGivesZeroResidual) {
  const jle::Model<double> model = arm();
  jle::Estimator e(model, sensorConfig());
  const VectorXd q = (VectorXd(2) << 0.4, 0.3).finished();
  Vector3d f, m;
  staticReading(q[1], f, m);
  feedStill(e, q, f, m);
  ASSERT_GE(e.layout().sensorSegment(0), 0);
  EXPECT_TRUE(e.last().sensorUsed(0));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(e.last().predictedWrench(0).force[i], f[i], kExact);
    EXPECT_NEAR(e.last().predictedWrench(0).moment[i], m[i], kExact);
    EXPECT_NEAR(e.last().sensorResidual(0).force[i], 0.0, kExact);
    EXPECT_NEAR(e.last().sensorResidual(0).moment[i], 0.0, kExact);
  }
}

// An unmodelled push c on the tool tip: the sensor reads the prediction minus c
// (moved to its origin); the residual is (-c, -p_tip x c), the wrench the tool
// exerts on what pushes it, and the joint loads are those with c applied.
TEST(SensorJoint, UnmodelledContactIsTheResidualAndLoadsTheProximalJoints) {
  const jle::Model<double> model = arm();
  const VectorXd q = (VectorXd(2) << 0.4, 0.3).finished();
  const Vector3d c(3.0, -2.0, 5.0);
  Vector3d f, m;
  staticReading(q[1], f, m);
  const Vector3d f_read = f - c, m_read = m - kTip.cross(c);

  // Closed form of the effort of j2 at rest: minus the moment about its axis of
  // the weights of link2 and the tool and of the contact (frame of link1 turned
  // by q1, which leaves gravity and the axis y alone).
  const double tau2 = j2EffortAtRest(q[1], c);

  for (int variant = 0; variant < 3; ++variant) {
    SCOPED_TRACE(variant == 0 ? "all joints" : variant == 1 ? "pruned to j1" : "float");
    jle::EstimatorConfig config = sensorConfig();
    if (variant == 1) config.joints = {"j1"};
    if (variant == 2) config.precision = jle::Precision::kFloat;
    // Float: 24-bit arithmetic on loads of ~10 N m.
    const double tol = variant == 2 ? 1e-5 : kExact;
    jle::Estimator e(model, config);
    feedStill(e, q, f_read, m_read);
    const jle::Wrench<double> r = e.last().sensorResidual(0);
    const Vector3d moment_expected = -kTip.cross(c);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(r.force[i], -c[i], tol);
      EXPECT_NEAR(r.moment[i], moment_expected[i], tol);
    }
    jle::Data<double> ref(model);
    referenceWithContact(model, ref, q, VectorXd::Zero(2), VectorXd::Zero(2), c);
    for (const char* joint : {"j1", "j2"}) {
      if (variant == 1 && std::string(joint) == "j2") continue;
      const int s = model.segmentOfJoint(joint);
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(e.last().data().force[s][i], ref.force[s][i], tol) << joint;
        EXPECT_NEAR(e.last().data().moment[s][i], ref.moment[s][i], tol) << joint;
      }
    }
    if (variant != 1) {
      EXPECT_NEAR(e.last().data().effort[model.segmentOfJoint("j2")], tau2, tol);
    }
  }
}

// Moving (3-point differences are exact on a quadratic): a reading made of the
// prediction at the exact state minus the contact gives the contact back and
// the loads with the contact applied, at every sample.
TEST(SensorJoint, MovingWithContact) {
  const jle::Model<double> model = arm();
  jle::Estimator e(model, sensorConfig());
  jle::Data<double> ref(model);
  const int s_ft = model.segmentOfJoint("ft_joint");
  const Vector3d c(-1.0, 4.0, 2.0);
  const Eigen::Vector2d q0(0.2, -0.4), qd0(0.3, 0.8), qdd(1.5, -2.0);
  int checked = 0;
  for (int k = 0; k < 50; ++k) {
    const double t = 2.0 + 1e-3 * k, s = t - 2.0;
    const VectorXd qk = q0 + qd0 * s + 0.5 * qdd * s * s, qdk = qd0 + qdd * s;
    // What the sensor reads: the joint wrench of the exact motion with the
    // contact.
    referenceWithContact(model, ref, qk, qdk, qdd, c);
    e.addWrench(0, t, ref.force[s_ft], ref.moment[s_ft]);
    if (e.addJointSample(t, qk.data()) != jle::SampleStatus::kPublished) continue;
    const double ts = e.last().stamp() - 2.0;
    referenceWithContact(model, ref, q0 + qd0 * ts + 0.5 * qdd * ts * ts, qd0 + qdd * ts, qdd, c);
    const jle::Wrench<double> r = e.last().sensorResidual(0);
    // Second differences of samples 1 ms apart: rounding of ~1e-16 / 1e-6 on
    // qdd.
    const double tol = 1e-8;
    const Vector3d moment_expected = -kTip.cross(c);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(r.force[i], -c[i], tol);
      EXPECT_NEAR(r.moment[i], moment_expected[i], tol);
    }
    for (int s : model.moving_segments)
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(e.last().data().force[s][i], ref.force[s][i], tol);
        EXPECT_NEAR(e.last().data().moment[s][i], ref.moment[s][i], tol);
      }
    ++checked;
  }
  EXPECT_GE(checked, 45);
}

// The sign check (sensor_sign.hpp) through the message path: a still arm whose sensor
// reads the tool's weight. Declared with the right sign its readings agree with the
// prediction; a sensor that reports the other side's load (the same readings negated)
// is named; a push on the tool (a reading the prediction does not explain) is not taken
// for a wrong sign.
TEST(SensorJoint, AWrongSignIsNamedFromTheStillReadings) {
  const jle::Model<double> model = arm();
  jle::Settings settings;
  settings.estimator.wrenches = sensorConfig().wrenches;
  jle::WrenchTopicSettings topic;
  topic.topic = "ft";
  settings.wrenches.push_back(topic);
  const std::vector<double> q = {0.4, 0.3};
  Vector3d f, m;
  staticReading(q[1], f, m);
  const auto tally = [&](const Vector3d& force, const Vector3d& moment) {
    jle::Pipeline pipeline(model, settings, nullptr);
    jle::SignTally t;
    const std::vector<double> none;
    for (int k = 0; k < 200; ++k) {
      const jle::Stamp stamp = 1000000000 + 1000000 * static_cast<jle::Stamp>(k);
      pipeline.onWrench(0, stamp, stamp, "ft_sensor", force, moment);
      if (pipeline.onJointState(stamp, stamp, model.coordinate_names, q, none, none) ==
          jle::Outcome::kPublished)
        jle::tallySign(pipeline.record().inputs[0], topic.force_threshold, t);
    }
    return t;
  };
  const jle::SignTally right = tally(f, m);
  EXPECT_GE(right.decisive, 150);
  EXPECT_EQ(right.opposed, 0);
  EXPECT_EQ(jle::signWarning("ft_joint", 1.0, right), "");
  const jle::SignTally wrong = tally(-f, -m);
  EXPECT_EQ(wrong.opposed, wrong.decisive);
  const std::string warning = jle::signWarning("ft_joint", 1.0, wrong);
  EXPECT_NE(warning.find("sensor ft_joint"), std::string::npos) << warning;
  EXPECT_NE(warning.find("sign wrong"), std::string::npos) << warning;
  // A push of 3 N on the tool against its 7.8 N weight: a residual, not a wrong sign.
  const Vector3d push(0.0, 3.0, 0.0);
  const jle::SignTally pushed = tally(f - push, m - kTip.cross(push));
  EXPECT_EQ(pushed.opposed, 0);
  EXPECT_EQ(jle::signWarning("ft_joint", 1.0, pushed), "");
}

TEST(SensorJoint, RefusedConfigurations) {
  const jle::Model<double> model = arm();
  auto build = [&](const std::string& joint, const std::string& link) {
    jle::EstimatorConfig config = sensorConfig();
    config.wrenches[0].sensor_joint = joint;
    config.wrenches[0].link = link;
    jle::Estimator e(model, config);
  };
  EXPECT_NO_THROW(build("ft_joint", "ft_sensor"));
  EXPECT_THROW(build("j2", ""), std::invalid_argument);  // not fixed
  EXPECT_THROW(build("tool_joint", ""),
               std::invalid_argument);  // lumped, not kept
  EXPECT_THROW(build("ft_joint", "tool"),
               std::invalid_argument);  // not its child link
}

}  // namespace
