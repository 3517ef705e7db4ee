// Numerical stability: the error bounds of the core and of the filters under the
// extremes that bench/stability.cpp sweeps (docs/studies/stability.md), asserted on
// representative points. The bounds and their margins are stated in
// stability_bounds.hpp, from the sweeps' measurements.
//
// The reference of the core's tests is the same computation in long double on the
// same inputs (the model and state in double, converted). Against quad precision its
// own error is below 2.5e-17 in every sweep, under 1/2000 of any double bound here.
#include <jle_testing/far_com.hpp>
#include <jle_testing/stability_bounds.hpp>

#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/random_models.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace {

namespace bounds = jle_test::bounds;
using jle_test::PrecisionComparison;
using jle_test::RandomModelSpec;
using jle_test::Scene;

const std::string kData = JLE_TEST_DATA;

// Worst errors of float and double over `models` random models (the bench's seeds) and
// `states` random states each.
PrecisionComparison<long double> measure(RandomModelSpec spec, int models, int states,
                                         double qd_scale = 1.0) {
  PrecisionComparison<long double> worst;
  for (int k = 0; k < models; ++k) {
    spec.seed = static_cast<std::uint32_t>(1000 + k);
    const jle::Model<double> model = jle::modelFromUrdfString(jle_test::randomUrdf(spec));
    jle_test::Precisions<long double> p(model);
    jle_test::Random rng(spec.seed);
    for (int s = 0; s < states; ++s) {
      Scene scene;
      scene.state = jle_test::randomState(model, rng, qd_scale, 5.0, spec.length);
      worst.merge(p.compare(scene));
    }
  }
  return worst;
}

// Wrench and moment within the generic bounds (stability_bounds.hpp: margin >= 6 over
// the worst measured point of the sweeps).
void expectGeneric(const PrecisionComparison<long double>& c) {
  EXPECT_LT(c.of_double.wrench, bounds::generic<double>());
  EXPECT_LT(c.of_double.moment, bounds::generic<double>());
  EXPECT_LT(c.of_float.wrench, bounds::generic<float>());
  EXPECT_LT(c.of_float.moment, bounds::generic<float>());
}

TEST(StabilityCore, ChainAndTreeErrorGrowsAtMostLinearlyWithTheirSize) {
  // Error of a chain of n joints below (300 + 3 n) eps: measured 1.5 eps at n = 1, 240
  // eps at n = 1000 (double); margin >= 5 at every measured n.
  for (bool tree : {false, true})
    for (int n : {10, 100, 1000}) {
      SCOPED_TRACE((tree ? "tree of " : "chain of ") + std::to_string(n));
      RandomModelSpec spec;
      spec.joints = n;
      spec.tree = tree;
      spec.prismatic_every = 4;
      const auto c = measure(spec, n == 1000 ? 1 : 3, 2);
      EXPECT_LT(c.of_double.wrench, bounds::chain<double>(n));
      EXPECT_LT(c.of_float.wrench, bounds::chain<float>(n));
      // A real error, not a zero from comparing a type with itself.
      EXPECT_GT(c.of_double.wrench, 0.0);
    }
}

TEST(StabilityCore, MassAndInertiaRatiosOf1e9) {
  for (bool inertia : {false, true}) {
    SCOPED_TRACE(inertia ? "inertia ratio 1e9" : "mass ratio 1e9");
    RandomModelSpec spec;
    spec.joints = 20;
    spec.tree = true;
    (inertia ? spec.inertia_ratio : spec.mass_ratio) = 1e9;
    expectGeneric(measure(spec, 4, 3));
  }
}

TEST(StabilityCore, TinyAndHugeLinks) {
  // The moment is checked on its own: at 0.1 mm it is 1e-4 of the force in the
  // 6-vector, which would hide its error.
  for (double L : {1e-4, 1e2}) {
    SCOPED_TRACE("links of " + std::to_string(L) + " m");
    RandomModelSpec spec;
    spec.joints = 8;
    spec.length = L;
    expectGeneric(measure(spec, 4, 3));
  }
}

TEST(StabilityCore, AngularVelocitiesOf1e3RadPerSecond) {
  RandomModelSpec spec;
  spec.joints = 12;
  spec.tree = true;
  expectGeneric(measure(spec, 4, 3, 1e3));
}

TEST(StabilityCore, IdealRods) {
  // Every link a rod whose moment about its own axis is exactly zero.
  RandomModelSpec spec;
  spec.joints = 10;
  spec.rod = -1.0;
  expectGeneric(measure(spec, 4, 3));
}

TEST(StabilityCore, SingularConfigurations) {
  // Nothing is inverted, so a kinematic singularity costs nothing. The wrench only: the
  // moment of a joint can vanish by symmetry (the UR5 stretched upwards, at rest), and
  // float's rounding of q = -pi/2 then leaves it no relative accuracy at all.
  struct Case {
    std::string file;
    std::vector<double> q;
  };
  const double h = M_PI / 2;
  const std::vector<Case> cases = {{"ur5_chain.urdf", {0.3, -1.1, 1.4, -0.7, 0.0, 0.9}},
                                   {"ur5_chain.urdf", {0, -h, 0, -h, 0, 0}},
                                   {"panda_chain.urdf", {0, 0, 0, 0, 0, 0, 0}}};
  for (const Case& c : cases) {
    const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/chains/" + c.file);
    jle_test::Precisions<long double> p(model);
    jle_test::Random rng(7);
    for (bool moving : {false, true}) {
      Scene scene;
      scene.state.q = Eigen::VectorXd::Map(c.q.data(), model.nq);
      scene.state.qd = Eigen::VectorXd::Zero(model.nq);
      scene.state.qdd = Eigen::VectorXd::Zero(model.nq);
      if (moving)
        for (int k = 0; k < model.nq; ++k) {
          scene.state.qd[k] = rng.uniform(-1.0, 1.0);
          scene.state.qdd[k] = rng.uniform(-5.0, 5.0);
        }
      const auto e = p.compare(scene);
      EXPECT_LT(e.of_double.wrench, bounds::generic<double>()) << c.file;
      EXPECT_LT(e.of_float.wrench, bounds::generic<float>()) << c.file;
    }
  }
}

// A centre of mass D out along the joint axis (far_com.hpp): the effort does not
// depend on D; a parallel-axis round trip of the inertia turned the across-axis
// components of omega and alpha into an error growing like D^2 (3e-13 at 10 m,
// 1.5e-10 at 1e3 m, 3e-5 at 1e5 m); now every D gives the closed form to rounding.
TEST(StabilityCore, ACentreOfMassFarAlongTheJointAxisCostsTheEffortNoDigits) {
  const jle_test::FarComState state;
  const double exact = static_cast<double>(jle_test::farComEffort(state));
  for (double D : {1.0, 1e1, 1e2, 1e3, 1e4, 1e5}) {
    const jle::Model<double> model = jle::modelFromUrdfString(jle_test::farComUrdf(D));
    jle::Data<double> data(model);
    const Eigen::Vector2d q(state.q[0], state.q[1]), qd(state.qd[0], state.qd[1]),
        qdd(state.qdd[0], state.qdd[1]);
    jle::rnea(model, data, Eigen::VectorXd(q), Eigen::VectorXd(qd), Eigen::VectorXd(qdd),
              Eigen::Vector3d(0, 0, -9.81));
    const int s = model.nsegments() - 1;  // link2
    EXPECT_LT(std::abs(data.effort[s] - exact) / std::abs(exact), 1e-13) << "D = " << D << " m";
  }
}

template <typename S>
void expectSameLoads(const jle::Data<S>& a, const jle::Data<S>& b, const std::vector<int>& joints) {
  for (int i : joints) {
    EXPECT_EQ(a.force[i], b.force[i]) << "joint segment " << i;
    EXPECT_EQ(a.moment[i], b.moment[i]) << "joint segment " << i;
  }
}

TEST(StabilityCore, AWorldOffsetDoesNotEnterTheLoads) {
  // The backward pass works in segment frames with moments about the joint: the base's
  // world position never enters it, nor does it enter wrenches given in the world frame
  // (rotated, not moved). So the loads at 1e5 m from the origin are the loads at the
  // origin, to the last bit, in double and in float (the paper's formulation taken
  // literally loses 8 digits of the moments there: docs/studies/stability.md).
  RandomModelSpec spec;
  spec.joints = 8;
  spec.seed = 2000;
  const jle::Model<double> model = jle::modelFromUrdfString(jle_test::randomUrdf(spec));
  const jle::Model<float> model_f = model.cast<float>();
  jle_test::Random rng(3);
  Scene scene;
  scene.state = jle_test::randomState(model, rng, 1.0, 5.0);
  scene.base.R_world_base =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 2).normalized()).toRotationMatrix();
  for (int frame : {static_cast<int>(model.frames.size()) - 1, 4}) {
    jle_test::AppliedWrench w;
    w.frame = frame;
    w.force = Eigen::Vector3d(12.0, -7.0, 15.0);
    w.moment = Eigen::Vector3d(-2.0, 3.0, 1.5);
    w.expressed_in = jle::WrenchFrame::kWorld;
    scene.wrenches.push_back(w);
  }
  jle::Data<double> at_origin(model), far(model);
  jle::Data<float> at_origin_f(model_f), far_f(model_f);
  jle_test::computeLoads(model, at_origin, scene);
  jle_test::computeLoads(model_f, at_origin_f, scene);
  scene.base.p_world_base = Eigen::Vector3d(6e4, -8e4, 0.0);  // 1e5 m away
  jle_test::computeLoads(model, far, scene);
  jle_test::computeLoads(model_f, far_f, scene);
  ASSERT_GT((far.p_world[model.nsegments() - 1] - at_origin.p_world[model.nsegments() - 1]).norm(),
            9e4);  // the offset did reach the kinematics
  expectSameLoads(at_origin, far, model.moving_segments);
  expectSameLoads(at_origin_f, far_f, model.moving_segments);
  // And the loads there are within the generic bounds of the long double reference.
  jle_test::Precisions<long double> p(model);
  expectGeneric(p.compare(scene));
}

// ---------------------------------------------------------------------------------------
// Filters

using jle::DifferentiatorBank;
using jle::DifferentiatorConfig;
using jle::DifferentiatorType;

DifferentiatorConfig finiteDifference(int order) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kFiniteDifference;
  c.order = order;
  return c;
}

DifferentiatorConfig kalman(jle::KalmanModel model) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kKalman;
  c.kalman_model = model;
  c.process_noise = 1e3;
  return c;
}

// Second derivative at te of the Lagrange basis polynomial k through the points t, in
// long double:
//   L_k'' = 2 sum_{i<j; i,j != k} prod_{m != k,i,j} (te - t_m) / prod_{j != k} (t_k - t_j).
// Each weight is a product of exact differences: a few roundings of long double.
long double lagrangeSecondDerivative(const std::vector<long double>& t, int k, long double te) {
  const int n = static_cast<int>(t.size());
  long double den = 1.0L, num = 0.0L;
  for (int j = 0; j < n; ++j)
    if (j != k) den *= t[k] - t[j];
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (i == k || j == k) continue;
      long double p = 2.0L;
      for (int m = 0; m < n; ++m)
        if (m != k && m != i && m != j) p *= te - t[m];
      num += p;
    }
  return num / den;
}

TEST(StabilityFilters, AShortIntervalCostsNoMoreThanTheInputsRounding) {
  // One interval of d among 1 ms ones (two nearly simultaneous samples). The exact
  // finite-difference weights (Lagrange, above) grow like 1 / d and amplify the
  // samples' rounding: that much error, eps sum |c_k x_k|, is inherent. The bank must
  // stay within kWeightsRatio = 5 of it (measured <= 1.1); the normal equations it used
  // before reached 1.3e6 for the 3-point difference at d = 1e-10 s.
  for (int order : {2, 3})
    for (double d : {1e-6, 1e-10}) {
      SCOPED_TRACE("order " + std::to_string(order) + ", interval " + std::to_string(d));
      DifferentiatorBank bank(finiteDifference(order), 1);
      std::vector<double> times, values;
      double worst = 0.0, t = 2.0;
      for (int k = 0; k < 100; ++k) {
        const double tau = t - 2.0;
        const double x = 0.3 + 0.5 * tau + 0.7 * tau * tau;
        times.push_back(t);
        values.push_back(x);
        if (bank.update(t, &x)) {
          const int w = order + 1;
          std::vector<long double> tw(times.end() - w, times.end());
          long double exact = 0.0L, scale = 0.0L;
          for (int i = 0; i < w; ++i) {
            const long double c = lagrangeSecondDerivative(tw, i, tw.back());
            exact += c * values[values.size() - w + i];
            scale += std::abs(c * values[values.size() - w + i]);
          }
          const double inherent =
              std::numeric_limits<double>::epsilon() * static_cast<double>(scale);
          worst = std::max(worst, std::abs(bank.accel(0) - static_cast<double>(exact)) / inherent);
        }
        t += k % 10 == 5 ? d : 1e-3;
      }
      EXPECT_LT(worst, bounds::kWeightsRatio);
    }
}

// Runs a bank over sin(2 pi tau) sampled at tau_k = k h, with stamps T0 + tau_k.
struct Outputs {
  std::vector<double> value, rate, accel;
};
Outputs runSine(const DifferentiatorConfig& c, double T0, double h, int samples) {
  DifferentiatorBank bank(c, 1);
  Outputs out;
  for (int k = 0; k < samples; ++k) {
    const double x = std::sin(2.0 * M_PI * k * h);
    if (!bank.update(T0 + k * h, &x)) continue;
    out.value.push_back(bank.value(0));
    out.rate.push_back(bank.rate(0));
    out.accel.push_back(bank.accel(0));
  }
  return out;
}

std::vector<DifferentiatorConfig> everyFilter() {
  DifferentiatorConfig sg;
  sg.type = DifferentiatorType::kSavitzkyGolay;
  sg.window = 9;
  sg.order = 2;
  sg.delay = 4;
  return {finiteDifference(2), sg, kalman(jle::KalmanModel::kConstantAcceleration),
          kalman(jle::KalmanModel::kConstantJerk)};
}

TEST(StabilityFilters, ExactStampsGiveTheSameEstimatesAtTheUnixEpoch) {
  // Stamps 1.8e9 + k 2^-10 s are exact doubles: the fit's centred times and the Kalman
  // filter's dt are then exact differences, and the estimates at the epoch are those
  // at T0 = 0 to the last bit.
  const double h = 1.0 / 1024.0, T0 = 1.8e9 - std::fmod(1.8e9, h);
  for (const DifferentiatorConfig& c : everyFilter()) {
    const Outputs at_zero = runSine(c, 0.0, h, 3000), at_epoch = runSine(c, T0, h, 3000);
    ASSERT_EQ(at_zero.accel.size(), at_epoch.accel.size());
    ASSERT_GT(at_zero.accel.size(), 2900u);
    EXPECT_EQ(at_zero.value, at_epoch.value);
    EXPECT_EQ(at_zero.rate, at_epoch.rate);
    EXPECT_EQ(at_zero.accel, at_epoch.accel);
  }
}

TEST(StabilityFilters, EpochStampsLoseOnlyTheirRounding) {
  // Stamps 1.8e9 + k 1e-3 s round to multiples of q = 2^-22 s (2.4e-7). Each sample is
  // then off in time by at most q / 2, i.e. off in value by at most |x'| q / 2 with
  // |x'| <= 2 pi: the 3-point qdd, whose weights sum to 4 / h^2 in magnitude, moves by
  // at most 4 / h^2 * 2 pi * q / 2 = 3.0 rad/s^2 (first order; measured 1.5). What
  // the filter adds would show above that; callers must pass relative times.
  const double h = 1e-3, q = std::ldexp(1.0, -22);
  const Outputs at_zero = runSine(finiteDifference(2), 0.0, h, 3000);
  const Outputs at_epoch = runSine(finiteDifference(2), 1.8e9, h, 3000);
  ASSERT_EQ(at_zero.accel.size(), at_epoch.accel.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < at_zero.accel.size(); ++k)
    worst = std::max(worst, std::abs(at_epoch.accel[k] - at_zero.accel[k]));
  const double predicted = 4.0 / (h * h) * 2.0 * M_PI * q / 2.0;
  EXPECT_LT(worst, predicted);
  EXPECT_GT(worst, 0.1 * predicted);  // the loss is real: not a vacuous bound
}

TEST(StabilityFilters, LongRunsHoldNoAccumulatedError) {
  // After 3e5 samples, the estimate is that of a bank started 1e5 samples before the
  // end: bit for bit for a window filter, within kLongRunFresh = 1e-11 relative for a
  // Kalman filter (measured <= 1.4e-12 here and after 1e7 samples in the bench). So
  // nothing accumulates in the window, the Kalman state or its covariance, and the run
  // can go on indefinitely. The stamps are exact (2^-10 s) or irregular (+-40%), where
  // the bank's reuse of its weights cannot tell the two banks apart.
  DifferentiatorConfig sg;
  sg.type = DifferentiatorType::kSavitzkyGolay;
  sg.window = 9;
  sg.order = 2;
  for (const DifferentiatorConfig& c :
       {finiteDifference(2), sg, kalman(jle::KalmanModel::kConstantAcceleration),
        kalman(jle::KalmanModel::kConstantJerk)})
    for (bool irregular : {false, true}) {
      SCOPED_TRACE("filter type " + std::to_string(static_cast<int>(c.type)) +
                   (irregular ? ", irregular" : ", regular"));
      const long samples = 300000;
      DifferentiatorBank bank(c, 1), fresh(c, 1);
      jle_test::Random rng(11);
      double worst = 0.0, t = 0.0;
      int compared = 0;
      for (long k = 0; k < samples; ++k) {
        const double x = std::sin(2.0 * M_PI * t);
        const bool ready = bank.update(t, &x);
        const bool fresh_ready = k >= samples - 100000 && fresh.update(t, &x);
        ASSERT_TRUE(std::isfinite(bank.accel(0)));
        if (ready && fresh_ready && k >= samples - 50000) {
          worst = std::max(
              worst, std::abs(bank.accel(0) - fresh.accel(0)) / (1.0 + std::abs(fresh.accel(0))));
          ++compared;
        }
        t = irregular ? t + 1e-3 * rng.uniform(0.6, 1.4) : (k + 1) / 1024.0;
      }
      EXPECT_EQ(compared, 50000);
      if (c.type == DifferentiatorType::kKalman)
        EXPECT_LE(worst, bounds::kLongRunFresh);
      else
        EXPECT_EQ(worst, 0.0);
    }
}

// A UR5 fed a quadratic per joint at 1 kHz; the loads published, by stamp.
struct Published {
  std::vector<jle::SampleStatus> status;   // per sample fed
  std::vector<double> stamp, qdd, effort;  // per sample published
  std::vector<std::size_t> index;          // per sample published: which sample fed it
};

Published feed(const std::vector<double>& times, const DifferentiatorConfig& c,
               bool reset_on_jump = false) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf");
  jle::EstimatorConfig config;
  config.differentiator = c;
  jle::Estimator estimator(model, config);
  Published out;
  double last = -1e300;
  for (std::size_t k = 0; k < times.size(); ++k) {
    const double t = times[k];
    if (reset_on_jump && t < last - 1.0) estimator.reset();  // what the node does
    last = t;
    Eigen::VectorXd q(model.nq);
    const double tau = t - std::floor(t);
    for (int i = 0; i < model.nq; ++i) q[i] = 0.1 * i + 0.5 * tau + 0.7 * std::cos(i) * tau * tau;
    out.status.push_back(estimator.addJointSample(t, q.data()));
    if (out.status.back() != jle::SampleStatus::kPublished) continue;
    out.index.push_back(k);
    out.stamp.push_back(estimator.last().stamp());
    out.qdd.push_back(estimator.last().qdd()[2]);
    out.effort.push_back(estimator.last().data().effort[model.moving_segments[1]]);
  }
  return out;
}

// The outputs of `run` published from its sample `first` on equal those of `reference`
// at the same stamps, bit for bit; returns how many were compared.
int expectSameAfter(const Published& run, const Published& reference, std::size_t first) {
  int compared = 0;
  for (std::size_t i = 0; i < run.stamp.size(); ++i) {
    if (run.index[i] < first) continue;
    bool found = false;
    for (std::size_t j = 0; j < reference.stamp.size() && !found; ++j)
      if (reference.stamp[j] == run.stamp[i]) {
        EXPECT_EQ(run.qdd[i], reference.qdd[j]) << "stamp " << run.stamp[i];
        EXPECT_EQ(run.effort[i], reference.effort[j]) << "stamp " << run.stamp[i];
        found = true;
      }
    EXPECT_TRUE(found) << "stamp " << run.stamp[i] << " not in the reference run";
    ++compared;
  }
  return compared;
}

TEST(StabilityFilters, DuplicateAndBackwardStampsLeaveTheFiltersUntouched) {
  std::vector<double> regular;
  for (int k = 0; k < 150; ++k) regular.push_back(1.0 + 1e-3 * k);
  for (const DifferentiatorConfig& c : everyFilter()) {
    // The bank refuses them (its caller's duty to drop them)...
    DifferentiatorBank bank(c, 1);
    const double x = 0.0;
    bank.update(1.0, &x);
    EXPECT_THROW(bank.update(1.0, &x), std::invalid_argument);
    EXPECT_THROW(bank.update(1.0 - 5e-4, &x), std::invalid_argument);
    // ...and the estimator drops them, as if they had never come.
    const Published reference = feed(regular, c);
    for (double bad : {regular[99], regular[99] - 5e-4}) {
      std::vector<double> times = regular;
      times.insert(times.begin() + 100, bad);
      const Published run = feed(times, c);
      EXPECT_EQ(run.status[100], bad == regular[99] ? jle::SampleStatus::kDuplicate
                                                    : jle::SampleStatus::kOutOfOrder);
      EXPECT_EQ(expectSameAfter(run, reference, 101), 50);
    }
  }
}

TEST(StabilityFilters, AGapRestartsAndAResetEqualsAFreshEstimator) {
  for (const DifferentiatorConfig& c : everyFilter()) {
    for (double jump : {5.0, -10.0}) {  // a gap beyond max_gap; a jump back (a looping bag)
      std::vector<double> times;
      for (int k = 0; k < 150; ++k) times.push_back(1.0 + 1e-3 * k + (k >= 100 ? jump : 0.0));
      const std::vector<double> resumed(times.begin() + 100, times.end());
      const Published run = feed(times, c, true);
      const Published fresh = feed(resumed, c);
      // The resumed stream warms up again, then matches a fresh estimator to the bit.
      EXPECT_EQ(run.status[100], jle::SampleStatus::kWarmingUp);
      ASSERT_GT(fresh.stamp.size(), 40u);
      EXPECT_EQ(expectSameAfter(run, fresh, 100), static_cast<int>(fresh.stamp.size()));
    }
  }
}

}  // namespace
