// The sensor joints' unit (sensor_joints.hpp): the prediction kept at the sensor's joint,
// the measurement substituted for the joints proximal to it, the residual, and the
// refused configurations, on an arm at rest against numbers worked by hand.
#include <joint_load_estimator/estimation/estimator.hpp>  // WrenchInputConfig
#include <joint_load_estimator/estimation/sensor_joints.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace {

using Eigen::Vector3d;

// An arm turning about y at the base origin; at its end (0.5, 0, 0) a force/torque
// sensor at a fixed joint, its frame turned by +90 deg about z; beyond it a 1 kg tool
// whose centre of mass is at (0.1, 0, 0) of the sensor frame.
const char* const kArm = R"(<?xml version="1.0"?>
<robot name="sensor_on_an_arm">
  <link name="base"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="100" velocity="5"/></joint>
  <link name="arm"><inertial><origin xyz="0.3 0 0"/><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="ft_joint" type="fixed"><parent link="arm"/><child link="ft"/><origin xyz="0.5 0 0" rpy="0 0 1.5707963267948966"/></joint>
  <link name="ft"/>
  <joint name="tool_joint" type="fixed"><parent link="ft"/><child link="tool"/><origin xyz="0.04 0 0"/></joint>
  <link name="tool"><inertial><origin xyz="0.06 0 0"/><mass value="1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
</robot>)";
constexpr double kG = 9.80665;
// Rounding: the measurement passes through the 3-point filter (weights summing to 1
// within ~1e-12 relative) and a few dozen operations on loads of ~10 N, 1 N m.
constexpr double kTol = 1e-10;

jle::Model<double> arm(bool keep_sensor = true) {
  jle::ModelOptions options;
  if (keep_sensor) options.keep_fixed_joints = {"ft_joint"};
  return jle::modelFromUrdfString(kArm, options);
}

jle::WrenchInputConfig sensor(const std::string& joint = "ft_joint", const std::string& link = "") {
  jle::WrenchInputConfig c;
  c.name = "ft";
  c.sensor_joint = joint;
  c.link = link;
  return c;
}

// The arm at rest at q [rad], the measurement (f, m) filtered in channels 0..5 of a 3-point
// bank, and the backward pass with the sensors' hook.
struct Rig {
  Rig() : model(arm()), data(model), sensors(model.nsegments()), bank(threePoint(), 6) {
    jle::WrenchInputConfig tool;
    tool.name = tool.link = "tool";
    EXPECT_EQ(sensors.add(model, tool, 6), -1);  // an applied wrench: no segment
    segment = sensors.add(model, sensor(), 0);
  }
  static jle::DifferentiatorConfig threePoint() {
    jle::DifferentiatorConfig d;
    d.type = jle::DifferentiatorType::kFiniteDifference;
    return d;
  }
  void solve(double q, const Vector3d& f, const Vector3d& m, bool used) {
    const double x[6] = {f.x(), f.y(), f.z(), m.x(), m.y(), m.z()};
    for (int k = 0; k < 3; ++k) bank.update(1.0 + 1e-3 * k, x);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
    jle::forwardKinematics(model, data, Eigen::VectorXd(Eigen::VectorXd::Constant(1, q)), zero,
                           zero, Vector3d(0.0, 0.0, -kG));
    sensors.setUsed(1, used);
    std::vector<int> all;
    for (int i = 0; i < model.nsegments(); ++i) all.push_back(i);
    jle::inverseDynamics(model, data, all, [&](int i) { sensors.atSegment(data, model, i, bank); });
  }

  jle::Model<double> model;
  jle::Data<double> data;
  jle::SensorJoints sensors;
  jle::DifferentiatorBank bank;
  int segment = -1;
};

// What the proximal side exerts on the tool at rest (sensor frame, about its origin):
// with the arm at q the sensor frame is Ry(q) Rz(90 deg), where gravity is
// g (0, -sin q, -cos q); the tool's weight is held by m g (0, sin q, cos q), at the
// centre of mass (0.1, 0, 0): the moment (0, -0.1 m g cos q, 0.1 m g sin q).
void heldTool(double q, Vector3d& f, Vector3d& m) {
  f = kG * Vector3d(0.0, std::sin(q), std::cos(q));
  m = Vector3d(0.1, 0.0, 0.0).cross(f);
}

TEST(SensorJoints, PredictionKeptMeasurementSubstituted) {
  Rig rig;
  ASSERT_TRUE(rig.sensors.any());
  ASSERT_EQ(rig.segment, rig.model.segmentOfJoint("ft_joint"));
  EXPECT_EQ(rig.sensors.segment(1), rig.segment);
  EXPECT_EQ(rig.sensors.segment(0), -1);
  const double q = 0.3;
  Vector3d f, m;
  heldTool(q, f, m);
  const Vector3d df(1.0, 2.0, 3.0), dm(0.1, -0.2, 0.3);
  rig.solve(q, f + df, m + dm, true);
  EXPECT_TRUE(rig.sensors.used(1));
  EXPECT_NEAR((rig.sensors.predicted(1).force - f).norm(), 0.0, kTol);
  EXPECT_NEAR((rig.sensors.predicted(1).moment - m).norm(), 0.0, kTol);
  // The sensor frame is the segment's own: the measurement lands unchanged.
  EXPECT_NEAR((rig.data.force[rig.segment] - (f + df)).norm(), 0.0, kTol);
  EXPECT_NEAR((rig.data.moment[rig.segment] - (m + dm)).norm(), 0.0, kTol);
  const jle::Wrench<double> r = rig.sensors.residual(1, rig.data);
  EXPECT_NEAR((r.force - df).norm(), 0.0, kTol);
  EXPECT_NEAR((r.moment - dm).norm(), 0.0, kTol);
  EXPECT_EQ(rig.sensors.residual(0, rig.data).force, Vector3d::Zero());  // not a sensor
}

// The proximal joint carries the measurement: the shoulder's effort (about y of the arm)
// changes by that of the difference carried from the sensor, at (0.5, 0, 0) turned by
// +90 deg about z: Rz(90) df = (-2, 1, 3), (0.5, 0, 0) x (-2, 1, 3) = (0, -1.5, 0.5),
// Rz(90) dm = (0.2, 0.1, 0.3): -1.5 + 0.1 = -1.4 N m about y.
TEST(SensorJoints, ProximalJointsCarryTheMeasurement) {
  const double q = 0.3;
  Vector3d f, m;
  heldTool(q, f, m);
  Rig kept, substituted;
  kept.solve(q, f + Vector3d(1.0, 2.0, 3.0), m + Vector3d(0.1, -0.2, 0.3), false);
  substituted.solve(q, f + Vector3d(1.0, 2.0, 3.0), m + Vector3d(0.1, -0.2, 0.3), true);
  EXPECT_FALSE(kept.sensors.used(1));
  EXPECT_EQ(kept.sensors.residual(1, kept.data).moment, Vector3d::Zero());  // unused
  const int shoulder = kept.model.segmentOfJoint("shoulder");
  EXPECT_NEAR(substituted.data.effort[shoulder] - kept.data.effort[shoulder], -1.4, kTol);
  // Unused, the prediction stays: the tool's weight, as held at the sensor.
  EXPECT_NEAR((kept.data.force[kept.segment] - f).norm(), 0.0, kTol);
}

TEST(SensorJoints, RefusedConfigurationsNameTheInput) {
  const jle::Model<double> model = arm();
  auto message = [](const jle::Model<double>& mdl,
                    const std::vector<jle::WrenchInputConfig>& inputs) {
    jle::SensorJoints sensors(mdl.nsegments());
    try {
      for (const jle::WrenchInputConfig& c : inputs) sensors.add(mdl, c, 0);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message(model, {sensor("ft_joint", "ft")}), "accepted");
  const std::string prefix = "wrench input 'ft': sensor_joint ";
  EXPECT_EQ(message(model, {sensor("shoulder")}), prefix + "'shoulder' is not a fixed joint");
  EXPECT_EQ(message(model, {sensor("tool_joint")}),
            prefix + "'tool_joint' is not a joint kept as a segment (keep_fixed_joints)");
  EXPECT_EQ(message(model, {sensor("ft_joint", "tool")}),
            prefix + "'ft_joint': link must be its child link 'ft', not 'tool'");
  EXPECT_EQ(message(model, {sensor(), sensor()}), prefix + "'ft_joint' has two sensor inputs");
  const jle::Model<double> lumped = arm(false);
  EXPECT_NE(message(lumped, {sensor()}).find("not a joint kept as a segment"), std::string::npos);
}

}  // namespace
