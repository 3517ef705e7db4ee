// The online estimator: exact where its differentiator is exact, wrench resampling,
// signs, stale policies, bad stamps, decimation, a floating base from its pose alone.
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace {

const std::string kData = JLE_TEST_DATA;

jle::Model<double> ur5() { return jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf"); }

jle::EstimatorConfig finiteDifferences() {
  jle::EstimatorConfig c;
  c.differentiator.type = jle::DifferentiatorType::kFiniteDifference;
  return c;
}

// q_i(t) = a_i + b_i t + c_i t^2: the 3-point difference is exact for it.
struct Quadratic {
  double t0 = 5.0;
  Eigen::VectorXd q(const jle::Model<double>& m, double t) const {
    Eigen::VectorXd out(m.nq);
    for (int i = 0; i < m.nq; ++i)
      out[i] = 0.1 * i - 0.3 + (0.5 - 0.2 * i) * (t - t0) + 0.7 * std::cos(i) * (t - t0) * (t - t0);
    return out;
  }
  Eigen::VectorXd qd(const jle::Model<double>& m, double t) const {
    Eigen::VectorXd out(m.nq);
    for (int i = 0; i < m.nq; ++i) out[i] = (0.5 - 0.2 * i) + 1.4 * std::cos(i) * (t - t0);
    return out;
  }
  Eigen::VectorXd qdd(const jle::Model<double>& m, double) const {
    Eigen::VectorXd out(m.nq);
    for (int i = 0; i < m.nq; ++i) out[i] = 1.4 * std::cos(i);
    return out;
  }
};

TEST(Estimator, ExactWithExactDifferentiatorAndWrenchResampling) {
  const jle::Model<double> model = ur5();
  jle::EstimatorConfig config = finiteDifferences();
  jle::WrenchInputConfig tool;
  tool.name = "ft";
  tool.link = "tool0";
  config.wrenches.push_back(tool);
  jle::Estimator estimator(model, config);
  const Quadratic traj;
  // A wrench linear in time, sampled at 2.5 kHz out of phase with 1 kHz joint samples:
  // linear interpolation reproduces it exactly at the joint stamps.
  auto force = [](double t) { return Eigen::Vector3d(3.0 + 2.0 * t, -1.0 + 0.5 * t, 4.0 - t); };
  auto moment = [](double t) { return Eigen::Vector3d(0.2 * t, 0.1, -0.3 + 0.05 * t); };
  jle::Data<double> reference(model);
  int published = 0;
  double tw = 4.9997;
  for (int k = 0; k < 200; ++k) {
    const double t = 5.0 + 1e-3 * k + 2e-4 * std::sin(k);  // jittered
    while (tw <= t + 1e-3) {
      estimator.addWrench(0, tw, force(tw), moment(tw));
      tw += 4e-4;
    }
    const Eigen::VectorXd q = traj.q(model, t);
    const jle::SampleStatus status = estimator.addJointSample(t, q.data());
    if (status != jle::SampleStatus::kPublished) continue;
    ++published;
    ASSERT_EQ(estimator.last().stamp(), t);
    jle::forwardKinematics(model, reference, q, traj.qd(model, t), traj.qdd(model, t),
                           config.gravity_world);
    jle::addExternalWrench(model, reference, model.frameIndex("tool0"), force(t), moment(t),
                           jle::WrenchFrame::kLocal);
    jle::inverseDynamics(model, reference);
    for (int s : model.moving_segments) {
      // Rounding of the 3-point formula at dt = 1 ms: ~1e-13 rad/s^2 on qdd, times
      // inertias O(1): 1e-9 relative to the load scale is a wide margin.
      const double scale = 1.0 + reference.force[s].norm() + reference.moment[s].norm();
      EXPECT_LT((estimator.last().data().force[s] - reference.force[s]).norm(), 1e-9 * scale);
      EXPECT_LT((estimator.last().data().moment[s] - reference.moment[s]).norm(), 1e-9 * scale);
    }
  }
  EXPECT_EQ(published, 198);
}

TEST(Estimator, SignFlipsAForcePlate) {
  const jle::Model<double> model = ur5();
  jle::EstimatorConfig config = finiteDifferences();
  jle::WrenchInputConfig plate;
  plate.name = "plate";
  plate.link = "tool0";
  plate.sign = -1.0;
  config.wrenches.push_back(plate);
  jle::Estimator estimator(model, config);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq);
  estimator.addWrench(0, 0.0, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6));
  for (int k = 0; k < 3; ++k) estimator.addJointSample(1e-3 * k, q.data());
  // The held value passes through the filter's weights (summing to 1 up to rounding).
  EXPECT_LT((estimator.last().appliedWrench(0).force - Eigen::Vector3d(-1, -2, -3)).norm(), 1e-13);
  EXPECT_LT((estimator.last().appliedWrench(0).moment - Eigen::Vector3d(-4, -5, -6)).norm(), 1e-13);
}

TEST(Estimator, StalePolicies) {
  const jle::Model<double> model = ur5();
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq);
  const Eigen::Vector3d f(10, 0, 0), m(0, 0, 1);
  for (jle::StalePolicy policy :
       {jle::StalePolicy::kHold, jle::StalePolicy::kZero, jle::StalePolicy::kStop}) {
    jle::EstimatorConfig config = finiteDifferences();
    jle::WrenchInputConfig ft;
    ft.name = "ft";
    ft.link = "tool0";
    ft.timeout = 0.05;
    ft.stale_policy = policy;
    config.wrenches.push_back(ft);
    jle::Estimator estimator(model, config);
    estimator.addWrench(0, 0.0, f, m);
    jle::SampleStatus status = jle::SampleStatus::kWarmingUp;
    for (int k = 0; k <= 40; ++k) status = estimator.addJointSample(1e-3 * k, q.data());
    ASSERT_EQ(status, jle::SampleStatus::kPublished);  // 40 ms < 50 ms timeout
    EXPECT_FALSE(estimator.last().stale(0));
    for (int k = 41; k <= 100; ++k) status = estimator.addJointSample(1e-3 * k, q.data());
    EXPECT_TRUE(estimator.last().stale(0));
    switch (policy) {
      case jle::StalePolicy::kHold:
        EXPECT_EQ(status, jle::SampleStatus::kPublished);
        EXPECT_LT((estimator.last().appliedWrench(0).force - f).norm(), 1e-13);
        break;
      case jle::StalePolicy::kZero:
        EXPECT_EQ(status, jle::SampleStatus::kPublished);
        EXPECT_EQ(estimator.last().appliedWrench(0).force, Eigen::Vector3d::Zero());
        break;
      case jle::StalePolicy::kStop: EXPECT_EQ(status, jle::SampleStatus::kStale); break;
    }
  }
}

TEST(Estimator, BadStampsAndValuesAreDroppedWithoutLosingTheNextSample) {
  const jle::Model<double> model = ur5();
  jle::Estimator estimator(model, finiteDifferences());
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq);
  EXPECT_EQ(estimator.addJointSample(0.000, q.data()), jle::SampleStatus::kWarmingUp);
  EXPECT_EQ(estimator.addJointSample(0.001, q.data()), jle::SampleStatus::kWarmingUp);
  EXPECT_EQ(estimator.addJointSample(0.001, q.data()), jle::SampleStatus::kDuplicate);
  EXPECT_EQ(estimator.addJointSample(0.0005, q.data()), jle::SampleStatus::kOutOfOrder);
  q[2] = std::nan("");
  EXPECT_EQ(estimator.addJointSample(0.0015, q.data()), jle::SampleStatus::kNonFinite);
  q[2] = 0.0;
  EXPECT_EQ(estimator.addJointSample(0.002, q.data()), jle::SampleStatus::kPublished);
  estimator.reset();  // a jump back of time
  EXPECT_EQ(estimator.addJointSample(0.000, q.data()), jle::SampleStatus::kWarmingUp);
}

TEST(Estimator, DecimationComputesEveryNthSample) {
  const jle::Model<double> model = ur5();
  jle::EstimatorConfig config = finiteDifferences();
  config.decimation = 3;
  jle::Estimator estimator(model, config);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq);
  int published = 0, decimated = 0;
  for (int k = 0; k < 32; ++k) {
    const jle::SampleStatus s = estimator.addJointSample(1e-3 * k, q.data());
    published += s == jle::SampleStatus::kPublished;
    decimated += s == jle::SampleStatus::kDecimated;
  }
  EXPECT_EQ(published, 10);  // 30 ready samples, every third
  EXPECT_EQ(decimated, 20);
}

TEST(Estimator, UnknownLinkIsNamed) {
  jle::EstimatorConfig config;
  jle::WrenchInputConfig bad;
  bad.name = "ft";
  bad.link = "no_such_link";
  config.wrenches.push_back(bad);
  try {
    jle::Estimator estimator(ur5(), config);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_link"), std::string::npos);
  }
}

TEST(Estimator, FloatingBaseTwistAndAccelerationFromItsPose) {
  // A single floating body spinning at a constant rate w about a fixed axis while its
  // origin accelerates uniformly. Its quaternion is smooth (sines of w t / 2), so a
  // centred quartic fit at 1 kHz recovers omega and alpha (= 0) up to its truncation,
  // O(h^4 w^5) = 3e-11 rad/s and O(h^4 w^6 / h) ~ 6e-8 rad/s^2 here, plus rounding
  // amplified by 1/h^2 on alpha: bounds 1e-9 and 1e-6.
  const std::string xml = R"(<robot name="r">
    <link name="body"><inertial><origin xyz="0.1 0 0"/><mass value="2"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.25"/></inertial></link>
  </robot>)";
  jle::ModelOptions options;
  options.floating_base = true;
  const jle::Model<double> model = jle::modelFromUrdfString(xml, options);
  jle::EstimatorConfig config;
  config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
  config.differentiator.window = 9;
  config.differentiator.order = 4;
  config.differentiator.delay = 4;
  jle::Estimator estimator(model, config);
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2).normalized();
  const double w = 2.0;
  const Eigen::Vector3d a0(0.5, -0.2, 1.0);
  for (int k = 0; k < 100; ++k) {
    const double t = 1e-3 * k;
    jle::BasePose pose;
    pose.position = 0.5 * a0 * t * t;
    pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(w * t, axis));
    if (estimator.addJointSample(t, nullptr, &pose) != jle::SampleStatus::kPublished) continue;
    const jle::Data<double>& d = estimator.last().data();
    EXPECT_LT((jle::omegaWorld(d, 0) - w * axis).norm(), 1e-9);
    EXPECT_LT(jle::alphaWorld(d, 0).norm(), 1e-6);
    const Eigen::Vector3d expected_a = a0;
    const Eigen::Vector3d a_origin = d.R_world[0] * d.acc[0] + config.gravity_world;
    EXPECT_LT((a_origin - expected_a).norm(), 1e-8);
  }
}

}  // namespace
