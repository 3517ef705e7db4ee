// What JointLoads carries beside the loads (pipeline.hpp LoadsRecord): the q, q-dot,
// q-ddot the loads were computed from, against an independent filter bank fed the same
// samples and against closed forms; and the optional friction term (friction.hpp) of the
// motor effort, against its closed form on a 1-joint model, exactly absent when off.
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/io/csv.hpp>
#include <joint_load_estimator/model/friction.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

using jle::Outcome;
using jle::Stamp;

constexpr Stamp kStart = 1700000000000000000;  // [ns]
const std::vector<double> kNone;

// A pendulum about y (1.5 kg, 0.4 m) with viscous damping 0.5 N m s/rad and Coulomb
// friction 2 N m, and a second joint without <dynamics>, mimicking the first (x -2, +0.1).
const char* const kPendulum = R"(<robot name="pendulum">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.4 0 0"/><mass value="1.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link>
  <link name="tip"><inertial><origin xyz="0.1 0 0"/><mass value="0.2"/>
    <inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.0001"/></inertial></link>
  <joint name="swing" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="100" velocity="10"/>
    <dynamics damping="0.5" friction="2.0"/></joint>
  <joint name="wrist" type="revolute"><parent link="arm"/><child link="tip"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="100"
    velocity="10"/><mimic joint="swing" multiplier="-2" offset="0.1"/></joint>
</robot>)";

// q(t) = 0.3 - 0.8 t + 1.1 t^2 [rad], t [s]: the 3-point difference is exact; q-dot
// crosses zero at t = 0.8 / 2.2 = 0.364 s, inside the 0.5 s run.
double q(double t) { return 0.3 - 0.8 * t + 1.1 * t * t; }
double qd(double t) { return -0.8 + 2.2 * t; }
constexpr double kQdd = 2.2;

jle::Settings settings(jle::DifferentiatorType type) {
  jle::Settings s;
  s.estimator.differentiator.type = type;
  if (type == jle::DifferentiatorType::kFiniteDifference) s.estimator.differentiator.window = 3;
  return s;
}

// Feeds q(t) at 1 kHz for 0.5 s; calls check(record, t) for every published sample.
template <typename Check>
int run(jle::Pipeline& pipeline, Check check) {
  int published = 0;
  for (int k = 0; k < 500; ++k) {
    const Stamp stamp = kStart + 1000000 * static_cast<Stamp>(k);
    const Outcome o = pipeline.onJointState(stamp, stamp, {"swing"}, {q(1e-3 * k)}, kNone, kNone);
    if (o != Outcome::kPublished) continue;
    ++published;
    check(pipeline.record(), static_cast<double>(pipeline.record().stamp - kStart) * 1e-9);
  }
  return published;
}

TEST(Outputs, UrdfDynamicsIsReadIntoTheModel) {
  const jle::Model<double> model = jle::modelFromUrdfString(kPendulum);
  const int swing = model.segmentOfJoint("swing"), wrist = model.segmentOfJoint("wrist");
  EXPECT_EQ(model.damping[swing], 0.5);
  EXPECT_EQ(model.friction[swing], 2.0);
  EXPECT_EQ(model.damping[wrist], 0.0);  // no <dynamics>
  EXPECT_EQ(model.friction[wrist], 0.0);
  EXPECT_EQ(model.damping[0], 0.0);
  const jle::Model<float> single = model.cast<float>();
  EXPECT_EQ(single.friction[swing], 2.0f);
}

// The coordinates of the record are the filter's (an independent bank over the same
// samples at the same times, default Kalman filter: same arithmetic, so equal), a mimic
// joint's mapped from its leader's (q = -2 q_leader + 0.1).
TEST(Outputs, RecordCarriesTheFiltersCoordinates) {
  const jle::Model<double> model = jle::modelFromUrdfString(kPendulum);
  jle::Pipeline pipeline(model, settings(jle::DifferentiatorType::kKalman), nullptr);
  jle::DifferentiatorBank bank(jle::DifferentiatorConfig(), 1);
  ASSERT_EQ(pipeline.record().joint, (std::vector<std::string>{"swing", "wrist"}));
  int compared = 0;
  for (int k = 0; k < 500; ++k) {
    const Stamp stamp = kStart + 1000000 * static_cast<Stamp>(k);
    const double x = q(1e-3 * k);
    const bool ready = bank.update(static_cast<double>(stamp - kStart) * 1e-9, &x);
    const Outcome o = pipeline.onJointState(stamp, stamp, {"swing"}, {x}, kNone, kNone);
    ASSERT_EQ(o == Outcome::kPublished, ready) << k;
    if (!ready) continue;
    const jle::LoadsRecord& r = pipeline.record();
    EXPECT_EQ(r.position[0], bank.value(0)) << k;
    EXPECT_EQ(r.velocity[0], bank.rate(0)) << k;
    EXPECT_EQ(r.acceleration[0], bank.accel(0)) << k;
    // The mimic: rounding of one product and sum, 1e-15.
    EXPECT_NEAR(r.position[1], -2.0 * bank.value(0) + 0.1, 1e-15) << k;
    EXPECT_NEAR(r.velocity[1], -2.0 * bank.rate(0), 1e-15 * std::abs(bank.rate(0))) << k;
    EXPECT_NEAR(r.acceleration[1], -2.0 * bank.accel(0), 1e-15 * std::abs(bank.accel(0))) << k;
    EXPECT_TRUE(r.motor_effort.empty());  // friction off by default
    ++compared;
  }
  EXPECT_EQ(compared, 500 - bank.warmup() + 1);  // after the filter's warm-up
}

// With exact 3-point differences of a quadratic, the record holds the closed form
// (rounding of the differences over 1 ms: 1e-9 rad/s^2 on 2.2).
TEST(Outputs, CoordinatesOfAnExactlyDifferentiableMotion) {
  const jle::Model<double> model = jle::modelFromUrdfString(kPendulum);
  jle::Pipeline pipeline(model, settings(jle::DifferentiatorType::kFiniteDifference), nullptr);
  const int n = run(pipeline, [](const jle::LoadsRecord& r, double t) {
    EXPECT_NEAR(r.position[0], q(t), 1e-12);
    EXPECT_NEAR(r.velocity[0], qd(t), 1e-9);
    EXPECT_NEAR(r.acceleration[0], kQdd, 1e-6);
  });
  EXPECT_EQ(n, 498);
}

TEST(Outputs, FrictionEffortClosedForm) {
  // Odd, zero at rest; tanh(1) = 0.76159415595576489 at one velocity scale.
  EXPECT_EQ(jle::frictionEffort(0.5, 2.0, 0.0, 0.01), 0.0);
  EXPECT_NEAR(jle::frictionEffort(0.5, 2.0, 0.01, 0.01), 0.005 + 2.0 * 0.76159415595576489, 1e-15);
  EXPECT_EQ(jle::frictionEffort(0.5, 2.0, -0.3, 0.01), -jle::frictionEffort(0.5, 2.0, 0.3, 0.01));
  // Far from rest: viscous + Coulomb (tanh(30) = 1 in double).
  EXPECT_EQ(jle::frictionEffort(0.5, 2.0, 0.3, 0.01), 0.15 + 2.0);
}

// Friction on: motor_effort - effort = damping qd + friction tanh(qd / v0) with the exact
// qd of the motion (the closed form; the 3-point velocity is exact to 1e-9 rad/s, the
// tanh's slope friction / v0 = 40 N m s/rad turns that into 4e-8 N m); the mimic joint
// (no <dynamics>) has none. Off: empty, and the rigid-body outputs bit-identical.
TEST(Outputs, MotorEffortWithFrictionAndExactlyAbsentWithout) {
  const jle::Model<double> model = jle::modelFromUrdfString(kPendulum);
  jle::Settings on = settings(jle::DifferentiatorType::kFiniteDifference);
  on.friction.enabled = true;
  on.friction.velocity_scale = 0.05;
  jle::Pipeline with(model, on, nullptr);
  jle::Pipeline without(model, settings(jle::DifferentiatorType::kFiniteDifference), nullptr);
  std::vector<double> effort_on, force_on;
  int near_rest = 0;
  run(with, [&](const jle::LoadsRecord& r, double t) {
    ASSERT_EQ(r.motor_effort.size(), 2u);
    const double v = qd(t);
    EXPECT_NEAR(r.motor_effort[0] - r.effort[0], 0.5 * v + 2.0 * std::tanh(v / 0.05), 1e-7) << t;
    EXPECT_EQ(r.motor_effort[1], r.effort[1]) << t;
    if (std::abs(v) < 0.05) ++near_rest;
    effort_on.insert(effort_on.end(), r.effort.begin(), r.effort.end());
    force_on.push_back(r.force[0].z());
  });
  EXPECT_GE(near_rest, 40);  // the smooth sign is exercised: |qd| < v0 for 45 ms
  std::size_t i = 0, j = 0;
  run(without, [&](const jle::LoadsRecord& r, double) {
    EXPECT_TRUE(r.motor_effort.empty());
    ASSERT_LT(i + 1, effort_on.size());
    EXPECT_EQ(r.effort[0], effort_on[i++]);
    EXPECT_EQ(r.effort[1], effort_on[i++]);
    EXPECT_EQ(r.force[0].z(), force_on[j++]);
  });
  EXPECT_EQ(i, effort_on.size());
}

TEST(Outputs, VelocityScaleIsValidated) {
  jle::Settings s;
  s.friction.velocity_scale = 0.0;
  try {
    jle::validate(s);
    ADD_FAILURE() << "a zero velocity_scale was accepted";
  } catch (const jle::SettingsError& e) {
    EXPECT_NE(std::string(e.what()).find("'friction/velocity_scale'"), std::string::npos)
        << e.what();
  }
}

TEST(Outputs, JointLoadColumnsOfTheOutputs) {
  jle::LoadColumnLayout layout;
  layout.kinematics = true;
  layout.motor_effort = true;
  layout.plates = {"p"};
  const std::vector<std::string> names = jle::jointLoadColumns({"a", "b"}, layout);
  const std::vector<std::string> tail(names.begin() + 15, names.end());
  EXPECT_EQ(tail, (std::vector<std::string>{"a.q", "a.qd", "a.qdd", "b.q", "b.qd", "b.qdd",
                                            "a.motor_effort", "b.motor_effort", "plate@p.contact",
                                            "plate@p.cop_x", "plate@p.cop_y", "plate@p.cop_z"}));
}

}  // namespace
