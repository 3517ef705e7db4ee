// Every saving of the estimator leaves the published loads unchanged: each test runs
// the same samples with the saving on and off and compares the loads it applies to.
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace {

const std::string kData = JLE_TEST_DATA;

// A planar arm (parallel z axes) with a massless link in the chain:
// test/data/urdf/planar_arm.urdf.
jle::Model<double> planarArm() { return jle::modelFromUrdfFile(kData + "/urdf/planar_arm.urdf"); }

// Runs n samples of a smooth trajectory (or a still robot) through an estimator and
// returns, per published sample, the concatenated loads of `joints`.
std::vector<std::vector<double>> run(const jle::Model<double>& model, jle::EstimatorConfig config,
                                     const std::vector<std::string>& joints, bool still,
                                     int n = 60) {
  jle::Estimator estimator(model, config);
  std::vector<std::vector<double>> out;
  Eigen::VectorXd q(model.nq);
  for (int k = 0; k < n; ++k) {
    const double t = 1e-3 * k;
    for (int i = 0; i < model.nq; ++i) q[i] = still ? 0.3 * i : 0.5 * std::sin(3 * t + i);
    for (int w = 0; w < static_cast<int>(config.wrenches.size()); ++w)
      estimator.addWrench(w, t, Eigen::Vector3d(1 + t, -2, 0.5), Eigen::Vector3d(0.1, t, -0.2));
    if (estimator.addJointSample(t, q.data()) != jle::SampleStatus::kPublished) continue;
    std::vector<double> loads;
    for (const std::string& j : joints) {
      const int s = model.segmentOfJoint(j);
      const jle::Data<double>& d = estimator.last().data();
      for (int c = 0; c < 3; ++c) loads.push_back(d.force[s][c]);
      for (int c = 0; c < 3; ++c) loads.push_back(d.moment[s][c]);
      loads.push_back(d.effort[s]);
    }
    out.push_back(loads);
  }
  return out;
}

std::vector<std::string> movingJoints(const jle::Model<double>& model) {
  std::vector<std::string> names;
  for (int s : model.moving_segments) names.push_back(model.joint_name[s]);
  return names;
}

jle::EstimatorConfig noSavings() {
  jle::EstimatorConfig c;
  c.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
  c.savings.prune = false;
  c.savings.massless_chains = false;
  c.savings.gyroscopic = false;
  c.savings.reuse_unchanged = false;
  c.savings.planar = jle::PlanarMode::kOff;  // test_planar.cpp covers it
  return c;
}

void expectIdentical(const std::vector<std::vector<double>>& a,
                     const std::vector<std::vector<double>>& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_FALSE(a.empty());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].size(), b[k].size());
    for (std::size_t i = 0; i < a[k].size(); ++i) EXPECT_EQ(a[k][i], b[k][i]) << k << " " << i;
  }
}

TEST(Savings, PruningToTheAskedJointsIsBitExact) {
  const jle::Model<double> talos = jle::modelFromUrdfFile(kData + "/urdf/talos_reduced.urdf");
  const std::vector<std::string> asked = {"leg_left_4_joint", "leg_left_5_joint",
                                          "arm_right_7_joint"};
  jle::EstimatorConfig pruned = noSavings(), full = noSavings();
  pruned.savings.prune = true;
  pruned.joints = asked;
  jle::Estimator probe(talos, pruned);
  // The saving applies: two legs' and an arm's worth of segments, not 33.
  EXPECT_LT(probe.layout().dynamicsSegments().size(), 6u);
  EXPECT_FALSE(
      probe.layout().coordinateNeeded(talos.coordinate[talos.segmentOfJoint("leg_right_4_joint")]));
  expectIdentical(run(talos, pruned, asked, false), run(talos, full, asked, false));
}

TEST(Savings, UnneededWrenchInputsAreSkipped) {
  const jle::Model<double> talos = jle::modelFromUrdfFile(kData + "/urdf/talos_reduced.urdf");
  jle::EstimatorConfig pruned = noSavings(), full = noSavings();
  for (jle::EstimatorConfig* c : {&pruned, &full}) {
    jle::WrenchInputConfig left, right;
    left.name = "left";
    left.link = "left_sole_link";
    right.name = "right";
    right.link = "right_sole_link";
    c->wrenches = {left, right};
  }
  pruned.savings.prune = true;
  pruned.joints = {"leg_left_4_joint"};
  jle::Estimator probe(talos, pruned);
  EXPECT_TRUE(probe.layout().inputNeeded(0));
  EXPECT_FALSE(probe.layout().inputNeeded(1));
  expectIdentical(run(talos, pruned, pruned.joints, false), run(talos, full, pruned.joints, false));
}

TEST(Savings, MasslessChainsAreBitExact) {
  const jle::Model<double> arm = planarArm();
  EXPECT_FALSE(arm.has_inertia[arm.segmentOfJoint("j2")]);  // it applies here
  jle::EstimatorConfig on = noSavings(), off = noSavings();
  on.savings.massless_chains = true;
  expectIdentical(run(arm, on, movingJoints(arm), false), run(arm, off, movingJoints(arm), false));
}

TEST(Savings, GyroscopicTermSkippedOnlyWhereItVanishes) {
  const jle::Model<double> arm = planarArm();
  for (int s : arm.moving_segments) EXPECT_FALSE(arm.gyroscopic[s]);  // planar: all vanish
  const jle::Model<double> ur5 = jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf");
  int spatial = 0;
  for (int s : ur5.moving_segments) spatial += ur5.gyroscopic[s];
  EXPECT_GE(spatial, 4);  // a spatial arm: most segments keep the term
  jle::EstimatorConfig on = noSavings(), off = noSavings();
  on.savings.gyroscopic = true;
  for (const jle::Model<double>* m : {&arm, &ur5}) {
    // omega x J omega with omega along a principal axis evaluates to exact zeros.
    expectIdentical(run(*m, on, movingJoints(*m), false), run(*m, off, movingJoints(*m), false));
  }
}

TEST(Savings, UnchangedInputsReuseTheLastResult) {
  const jle::Model<double> ur5 = jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf");
  jle::EstimatorConfig on = noSavings(), off = noSavings();
  on.savings.reuse_unchanged = true;
  // A still robot: after the filter settles every sample repeats the last inputs.
  jle::Estimator probe(ur5, on);
  Eigen::VectorXd q = Eigen::VectorXd::Constant(ur5.nq, 0.2);
  int reused = 0;
  for (int k = 0; k < 40; ++k)
    if (probe.addJointSample(1e-3 * k, q.data()) == jle::SampleStatus::kPublished)
      reused += probe.last().reused();
  EXPECT_GT(reused, 20);
  expectIdentical(run(ur5, on, movingJoints(ur5), true), run(ur5, off, movingJoints(ur5), true));
  expectIdentical(run(ur5, on, movingJoints(ur5), false), run(ur5, off, movingJoints(ur5), false));
}

TEST(Savings, StaticThresholdsDropOnlyTermsThatAreZeroAtRest) {
  // Not exact in motion (hence off by default); at rest the static pass must equal the
  // full one: the velocity terms it drops are zero there. Rounding differs (terms of
  // 0 added or not): 1e-12 relative to the load scale.
  const jle::Model<double> ur5 = jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf");
  jle::EstimatorConfig on = noSavings(), off = noSavings();
  on.savings.static_velocity = 1e-3;
  on.savings.static_acceleration = 1e-3;
  const auto a = run(ur5, on, movingJoints(ur5), true);
  const auto b = run(ur5, off, movingJoints(ur5), true);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k)
    for (std::size_t i = 0; i < a[k].size(); ++i) EXPECT_NEAR(a[k][i], b[k][i], 1e-12 * 100.0);
}

TEST(Savings, FloatPrecisionAgreesWithinItsBound) {
  // float carries 24 bits: loads of O(100) N m agree to ~1e-5 relative (float vs long
  // double was measured at 6.4e-7 in test_invariance; 1e-5 leaves the filters' share).
  const jle::Model<double> ur5 = jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf");
  jle::EstimatorConfig f = noSavings(), d = noSavings();
  f.precision = jle::Precision::kFloat;
  const auto a = run(ur5, f, movingJoints(ur5), false);
  const auto b = run(ur5, d, movingJoints(ur5), false);
  ASSERT_EQ(a.size(), b.size());
  double scale = 0;
  for (const auto& row : b)
    for (double v : row) scale = std::max(scale, std::abs(v));
  for (std::size_t k = 0; k < a.size(); ++k)
    for (std::size_t i = 0; i < a[k].size(); ++i) EXPECT_NEAR(a[k][i], b[k][i], 1e-5 * scale);
}

}  // namespace
