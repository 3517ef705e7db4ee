// Per-timestep cost of the core against Orocos KDL on the same states, same run.
// Each benchmark cycles through the same 256 random states (fixed seed), so both
// libraries see identical inputs. The ratios are printed by bench/speed (run_speed.sh).
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <jle_testing/random_models.hpp>

#include "benchmark_main.hpp"

#include <benchmark/benchmark.h>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include <map>
#include <string>

namespace {

const std::string kData = JLE_BENCH_DATA;
constexpr int kStates = 256;

struct States {
  std::vector<Eigen::VectorXd> q, qd, qdd;
};

States randomStates(int nq) {
  jle::PortableRandom random(42);
  States s;
  for (int k = 0; k < kStates; ++k) {
    Eigen::VectorXd q(nq), qd(nq), qdd(nq);
    for (int i = 0; i < nq; ++i) {
      q[i] = random.uniform(-3.0, 3.0);
      qd[i] = random.uniform(-2.0, 2.0);
      qdd[i] = random.uniform(-5.0, 5.0);
    }
    s.q.push_back(q);
    s.qd.push_back(qd);
    s.qdd.push_back(qdd);
  }
  return s;
}

// What a pass computes: kLocal all 6-D joint wrenches over the segment-frame kinematics
// (what KDL's recursive Newton-Euler computes, plus the 5 components it drops), kWorld
// with every segment's world pose as well (forwardKinematics).
enum class Pass { kLocal, kWorld };

template <typename Scalar>
void coreLoads(benchmark::State& state, const std::string& file, Pass pass = Pass::kLocal) {
  const jle::Model<Scalar> model = jle::modelFromUrdfFile(kData + file).cast<Scalar>();
  jle::Data<Scalar> data(model);
  const States s = randomStates(model.nq);
  std::vector<jle::VectorX<Scalar>> q, qd, qdd;
  for (int k = 0; k < kStates; ++k) {
    q.push_back(s.q[k].cast<Scalar>());
    qd.push_back(s.qd[k].cast<Scalar>());
    qdd.push_back(s.qdd[k].cast<Scalar>());
  }
  const Eigen::Matrix<Scalar, 3, 1> g(0, 0, Scalar(-9.80665));
  int k = 0;
  for (auto _ : state) {
    switch (pass) {
      case Pass::kLocal:
        jle::localKinematics(model, data, q[k], qd[k], qdd[k], g);
        jle::inverseDynamics(model, data);
        break;
      case Pass::kWorld:
        jle::forwardKinematics(model, data, q[k], qd[k], qdd[k], g);
        jle::inverseDynamics(model, data);
        break;
    }
    benchmark::DoNotOptimize(data.moment.data());
    benchmark::ClobberMemory();
    k = (k + 1) % kStates;
  }
  state.counters["segments"] = model.nsegments();
}

void coreDoubleWorld(benchmark::State& state, const std::string& file) {
  coreLoads<double>(state, file, Pass::kWorld);
}

void coreDouble(benchmark::State& state, const std::string& file) {
  coreLoads<double>(state, file);
}
void coreFloat(benchmark::State& state, const std::string& file) { coreLoads<float>(state, file); }
void coreLongDouble(benchmark::State& state, const std::string& file) {
  coreLoads<long double>(state, file);
}

void coreKinematicsOnly(benchmark::State& state, const std::string& file) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + file);
  jle::Data<double> data(model);
  const States s = randomStates(model.nq);
  const Eigen::Vector3d g(0, 0, -9.80665);
  int k = 0;
  for (auto _ : state) {
    jle::localKinematics(model, data, s.q[k], s.qd[k], s.qdd[k], g);
    benchmark::DoNotOptimize(data.acc.data());
    k = (k + 1) % kStates;
  }
}

void coreDynamicsOnly(benchmark::State& state, const std::string& file) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + file);
  jle::Data<double> data(model);
  const States s = randomStates(model.nq);
  jle::forwardKinematics(model, data, s.q[0], s.qd[0], s.qdd[0], Eigen::Vector3d(0, 0, -9.80665));
  for (auto _ : state) {
    jle::inverseDynamics(model, data);
    benchmark::DoNotOptimize(data.moment.data());
  }
}

// KDL's q index of each of our coordinates, by joint name.
std::vector<unsigned> kdlIndex(const jle::Model<double>& model, const KDL::Tree& tree) {
  std::map<std::string, unsigned> by_name;
  for (const auto& kv : tree.getSegments()) {
    const KDL::Segment& seg = kv.second.segment;
    if (seg.getJoint().getType() != KDL::Joint::None)
      by_name[seg.getJoint().getName()] = kv.second.q_nr;
  }
  std::vector<unsigned> out;
  for (int s : model.moving_segments) out.push_back(by_name.at(model.joint_name[s]));
  return out;
}

void kdlTree(benchmark::State& state, const std::string& file) {
  KDL::Tree tree;
  if (!kdl_parser::treeFromFile(kData + file, tree)) {
    state.SkipWithError("kdl_parser failed");
    return;
  }
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + file);
  const std::vector<unsigned> index = kdlIndex(model, tree);
  const States s = randomStates(model.nq);
  const unsigned n = tree.getNrOfJoints();
  std::vector<KDL::JntArray> q(kStates, KDL::JntArray(n)), qd(kStates, KDL::JntArray(n)),
      qdd(kStates, KDL::JntArray(n));
  for (int k = 0; k < kStates; ++k)
    for (std::size_t j = 0; j < model.moving_segments.size(); ++j) {
      const int seg = model.moving_segments[j];
      const int c = model.coordinate[seg];
      q[k](index[j]) = model.multiplier[seg] * s.q[k][c] + model.offset[seg];
      qd[k](index[j]) = model.multiplier[seg] * s.qd[k][c];
      qdd[k](index[j]) = model.multiplier[seg] * s.qdd[k][c];
    }
  KDL::TreeIdSolver_RNE solver(tree, KDL::Vector(0, 0, -9.80665));
  KDL::WrenchMap f_ext;
  for (const auto& kv : tree.getSegments()) f_ext[kv.first] = KDL::Wrench::Zero();
  KDL::JntArray tau(n);
  int k = 0;
  for (auto _ : state) {
    solver.CartToJnt(q[k], qd[k], qdd[k], f_ext, tau);
    benchmark::DoNotOptimize(tau.data.data());
    k = (k + 1) % kStates;
  }
}

void kdlChain(benchmark::State& state, const std::string& file, const std::string& root,
              const std::string& tip) {
  KDL::Tree tree;
  KDL::Chain chain;
  if (!kdl_parser::treeFromFile(kData + file, tree) || !tree.getChain(root, tip, chain)) {
    state.SkipWithError("kdl chain failed");
    return;
  }
  const unsigned n = chain.getNrOfJoints();
  const States s = randomStates(static_cast<int>(n));
  std::vector<KDL::JntArray> q(kStates, KDL::JntArray(n)), qd(kStates, KDL::JntArray(n)),
      qdd(kStates, KDL::JntArray(n));
  // Chain order is the tree order here (a serial chain): same states as the core.
  for (int k = 0; k < kStates; ++k) {
    q[k].data = s.q[k];
    qd[k].data = s.qd[k];
    qdd[k].data = s.qdd[k];
  }
  KDL::ChainIdSolver_RNE solver(chain, KDL::Vector(0, 0, -9.80665));
  KDL::Wrenches f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero());
  KDL::JntArray tau(n);
  int k = 0;
  for (auto _ : state) {
    solver.CartToJnt(q[k], qd[k], qdd[k], f_ext, tau);
    benchmark::DoNotOptimize(tau.data.data());
    k = (k + 1) % kStates;
  }
}

// The filter bank per sample, per filter type and channel count (state.range(0)): 6, 7
// (the arms' joints), 19 (7 joints and two wrench inputs), 50. Sampled every 1 ms, so
// the gains settle and the steady per-sample cost is what is measured.
void runBank(benchmark::State& state, const jle::DifferentiatorConfig& c) {
  const int channels = static_cast<int>(state.range(0));
  jle::DifferentiatorBank bank(c, channels);
  // The samples made beforehand (4096, cycled on a continuous time axis): the loop
  // times the filter, not the signal's sin.
  const int n = 4096;
  std::vector<double> x(static_cast<std::size_t>(n * channels));
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < channels; ++i) x[k * channels + i] = std::sin(2.0 * M_PI * k / n + i);
  double t = 0.0;
  int k = 0;
  for (auto _ : state) {
    t += 1e-3;
    benchmark::DoNotOptimize(bank.update(t, &x[k * channels]));
    benchmark::DoNotOptimize(bank.value(0));
    k = (k + 1) % n;
  }
}

// "kalman_cj" is the default (constant-jerk Kalman, config.hpp); "kalman_ca" constant
// acceleration (q = 1e3); "savitzky_golay_9" causal, order 2; "finite_difference" 3 points;
// "adaptive" the bank of Kalman filters with its defaults.
jle::DifferentiatorConfig filterConfig(const std::string& name) {
  jle::DifferentiatorConfig c;
  using Type = jle::DifferentiatorType;
  using Kalman = jle::KalmanModel;
  if (name == "kalman_ca") {
    c.kalman_model = Kalman::kConstantAcceleration;
    c.process_noise = 1e3;
  } else if (name == "savitzky_golay_9") {
    c.type = Type::kSavitzkyGolay;
  } else if (name == "finite_difference") {
    c.type = Type::kFiniteDifference;
  } else if (name == "adaptive") {
    c.type = Type::kAdaptive;
  }
  return c;
}

void filterBank(benchmark::State& state, const std::string& name) {
  runBank(state, filterConfig(name));
}
// The Kalman smoother (differentiator/lag 0.1 s: 100 samples at 1 kHz), the defaults
// otherwise: its cost beside filterBank/kalman_cj's in the same run.
void smootherBank(benchmark::State& state) {
  jle::DifferentiatorConfig c;
  c.lag = 0.1;
  runBank(state, c);
}
// The adaptive smoother (type adaptive, lag 0.1 s), its other keys' defaults.
void adaptiveSmootherBank(benchmark::State& state) {
  jle::DifferentiatorConfig c;
  c.type = jle::DifferentiatorType::kAdaptive;
  c.lag = 0.1;
  runBank(state, c);
}

// Scaling: random serial chains and random trees of n moving joints (seeded), all 6-D
// joint wrenches and the kinematics per sample. Google Benchmark fits the times to
// a n and reports the coefficient and the RMS of the fit: a small RMS shows linearity.
void scaling(benchmark::State& state, bool tree) {
  jle_test::RandomModelSpec spec;
  spec.joints = static_cast<int>(state.range(0));
  spec.tree = tree;
  spec.seed = 11;
  const jle::Model<double> model = jle::modelFromUrdfString(jle_test::randomUrdf(spec));
  jle::Data<double> data(model);
  const States s = randomStates(model.nq);
  const Eigen::Vector3d g(0, 0, -9.80665);
  int k = 0;
  for (auto _ : state) {
    jle::localKinematics(model, data, s.q[k], s.qd[k], s.qdd[k], g);
    jle::inverseDynamics(model, data);
    benchmark::DoNotOptimize(data.moment.data());
    k = (k + 1) % kStates;
  }
  state.SetComplexityN(state.range(0));
}

// One saving switched relative to the defaults (all exact savings on).
// A "_gy" suffix: gravity along -y (a vertical planar arm turning about z: planar).
jle::EstimatorConfig savingsVariant(std::string variant) {
  jle::EstimatorConfig c;
  c.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;  // 9 samples, causal
  const std::string gy = "_gy";
  if (variant.size() > gy.size() &&
      variant.compare(variant.size() - gy.size(), gy.size(), gy) == 0) {
    c.gravity_world = Eigen::Vector3d(0.0, -9.80665, 0.0);
    variant.resize(variant.size() - gy.size());
  }
  if (variant == "none") {
    c.savings.prune = c.savings.massless_chains = c.savings.gyroscopic = false;
    c.savings.reuse_unchanged = false;
    c.savings.planar = jle::PlanarMode::kOff;
  } else if (variant == "prune_off") {
    c.savings.prune = false;
  } else if (variant == "massless_off") {
    c.savings.massless_chains = false;
  } else if (variant == "gyroscopic_off") {
    c.savings.gyroscopic = false;
  } else if (variant == "reuse_off") {
    c.savings.reuse_unchanged = false;
  } else if (variant == "static_on") {
    c.savings.static_velocity = 1e-3;
    c.savings.static_acceleration = 1e-3;
  } else if (variant == "float") {
    c.precision = jle::Precision::kFloat;
  } else if (variant.rfind("cov_", 0) == 0) {
    // Covariance of the loads (docs/studies/uncertainty.md): cov_full = every source, the state
    // linearised; cov_qdd = its cheap path (q-ddot, wrench and inertial parts only);
    // _diag = only the variances; _pN = uncertainty.period N ms (the step is 1 ms: computed
    // every N-th sample), extrapolated in between (_p1000: the extrapolation alone, nearly).
    c.uncertainty.enabled = true;
    c.uncertainty.position_noise = 1e-4;
    c.uncertainty.mass_fraction = 0.05;
    c.uncertainty.com_offset = 0.005;
    c.uncertainty.inertia_fraction = 0.1;
    c.uncertainty.linearize_state = variant.find("full") != std::string::npos;
    c.uncertainty.diagonal_only = variant.find("diag") != std::string::npos;
    c.uncertainty.period = 0.0;
    const std::size_t p = variant.find("_p");
    if (p != std::string::npos) c.uncertainty.period = 1e-3 * std::stoi(variant.substr(p + 2));
  } else if (variant == "planar_off") {
    c.savings.planar = jle::PlanarMode::kOff;
  }
  return c;
}

// The estimator per joint sample (filter + kinematics + dynamics) as the node runs it,
// over 4096 samples of a smooth trajectory (or of a still robot), cycled.
void runEstimator(benchmark::State& state, const std::string& file,
                  const jle::EstimatorConfig& config, bool still) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + file);
  jle::Estimator estimator(model, config);
  const int n = 4096;
  std::vector<Eigen::VectorXd> q(n, Eigen::VectorXd(model.nq));
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < model.nq; ++i) q[k][i] = still ? 0.1 * i : 0.5 * std::sin(2e-3 * k + i);
  int k = 0;
  double t = 0.0;
  for (auto _ : state) {
    t += 1e-3;
    benchmark::DoNotOptimize(estimator.addJointSample(t, q[k].data()));
    k = (k + 1) % n;
  }
  state.counters["computed_segments"] =
      static_cast<double>(estimator.layout().dynamicsSegments().size());
  state.counters["planar"] = estimator.last().planar();
}

void estimatorStep(benchmark::State& state, const std::string& file, const std::string& joints,
                   bool still, const std::string& variant) {
  jle::EstimatorConfig config = savingsVariant(variant);
  if (!joints.empty()) config.joints = {joints};
  runEstimator(state, file, config, still);
}

// The node's step with every default (EstimatorConfig{}: the constant-jerk Kalman filter,
// the exact savings) on a moving arm: the "full step" tools/speed.sh sets against
// coreDouble, the loads alone, on the same arm.
void fullStep(benchmark::State& state, const std::string& file) {
  runEstimator(state, file, jle::EstimatorConfig(), false);
}

// The same with the Kalman smoother (differentiator/lag 0.1 s, 100 samples at 1 kHz):
// its cost beside the causal filter's (the defaults') in the same run.
void fullStepSmoother(benchmark::State& state, const std::string& file) {
  jle::EstimatorConfig config;
  config.differentiator.lag = 0.1;
  runEstimator(state, file, config, false);
}

// Both streams of the node's defaults (jle::Settings{}: the immediate estimator and the
// smoothed one, smoothedEstimatorConfig) fed the same samples, against fullStep (the
// immediate stream alone): their ratio is the cost of both (issue 37: under 3x).
void fullStepBothStreams(benchmark::State& state, const std::string& file) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + file);
  const jle::Settings settings;
  jle::Estimator immediate(model, settings.estimator);
  jle::Estimator smoothed(model, jle::smoothedEstimatorConfig(settings));
  const int n = 4096;
  std::vector<Eigen::VectorXd> q(n, Eigen::VectorXd(model.nq));
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < model.nq; ++i) q[k][i] = 0.5 * std::sin(2e-3 * k + i);
  int k = 0;
  double t = 0.0;
  for (auto _ : state) {
    t += 1e-3;
    benchmark::DoNotOptimize(immediate.addJointSample(t, q[k].data()));
    benchmark::DoNotOptimize(smoothed.addJointSample(t, q[k].data()));
    k = (k + 1) % n;
  }
}

}  // namespace

// Savings: each switched off (or on) against the defaults, where it applies and where
// it does not.
#define JLE_SAVING(name, file, joints, still)                                                     \
  BENCHMARK_CAPTURE(estimatorStep, name##_defaults, file, joints, still, "defaults");             \
  BENCHMARK_CAPTURE(estimatorStep, name##_none, file, joints, still, "none");                     \
  BENCHMARK_CAPTURE(estimatorStep, name##_prune_off, file, joints, still, "prune_off");           \
  BENCHMARK_CAPTURE(estimatorStep, name##_massless_off, file, joints, still, "massless_off");     \
  BENCHMARK_CAPTURE(estimatorStep, name##_gyroscopic_off, file, joints, still, "gyroscopic_off"); \
  BENCHMARK_CAPTURE(estimatorStep, name##_reuse_off, file, joints, still, "reuse_off");           \
  BENCHMARK_CAPTURE(estimatorStep, name##_static_on, file, joints, still, "static_on");           \
  BENCHMARK_CAPTURE(estimatorStep, name##_float, file, joints, still, "float")
BENCHMARK_CAPTURE(scaling, chain, false)
    ->RangeMultiplier(10)
    ->Range(1, 1000)
    ->Arg(300)
    ->Arg(30)
    ->Arg(3)
    ->Complexity(benchmark::oN);
BENCHMARK_CAPTURE(scaling, tree, true)
    ->RangeMultiplier(10)
    ->Range(1, 1000)
    ->Arg(300)
    ->Arg(30)
    ->Arg(3)
    ->Complexity(benchmark::oN);

// The covariance of the loads against the same step without it.
#define JLE_COVARIANCE(name, file)                                                          \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_off, file, "", false, "defaults");            \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full, file, "", false, "cov_full");           \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_diag, file, "", false, "cov_full_diag"); \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_qdd, file, "", false, "cov_qdd");             \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_qdd_diag, file, "", false, "cov_qdd_diag");   \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_p8, file, "", false, "cov_full_p8");     \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_p12, file, "", false, "cov_full_p12");   \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_p16, file, "", false, "cov_full_p16");   \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_p17, file, "", false, "cov_full_p17");   \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_p18, file, "", false, "cov_full_p18");   \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_p20, file, "", false, "cov_full_p20");   \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_p24, file, "", false, "cov_full_p24");   \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_diag_p16, file, "", false,               \
                    "cov_full_diag_p16");                                                   \
  BENCHMARK_CAPTURE(estimatorStep, name##_cov_full_p1000, file, "", false, "cov_full_p1000")
JLE_COVARIANCE(panda, "/urdf/panda.urdf");
JLE_COVARIANCE(talos, "/urdf/talos_reduced.urdf");

JLE_SAVING(talos_all_moving, "/urdf/talos_reduced.urdf", "", false);
JLE_SAVING(talos_one_knee_moving, "/urdf/talos_reduced.urdf", "leg_left_4_joint", false);
JLE_SAVING(talos_all_still, "/urdf/talos_reduced.urdf", "", true);
JLE_SAVING(planar_arm_moving, "/urdf/planar_arm.urdf", "", false);
JLE_SAVING(panda_chain_moving, "/urdf/chains/panda_chain.urdf", "", false);
JLE_SAVING(panda_chain_still, "/urdf/chains/panda_chain.urdf", "", true);
// savings.planar: planar scenes (the planar arm and a 12-link planar chain, gravity in
// their plane) with the 3x3 path (auto detects it) and without; a spatial arm, where
// detection refuses at construction, with auto and off (what detection costs per
// sample: nothing).
BENCHMARK_CAPTURE(estimatorStep, planar_arm_vertical_planar_auto, "/urdf/planar_arm.urdf", "",
                  false, "defaults_gy");
BENCHMARK_CAPTURE(estimatorStep, planar_arm_vertical_planar_off, "/urdf/planar_arm.urdf", "", false,
                  "planar_off_gy");
BENCHMARK_CAPTURE(estimatorStep, planar_chain_vertical_planar_auto, "/urdf/planar_chain.urdf", "",
                  false, "defaults_gy");
BENCHMARK_CAPTURE(estimatorStep, planar_chain_vertical_planar_off, "/urdf/planar_chain.urdf", "",
                  false, "planar_off_gy");
BENCHMARK_CAPTURE(estimatorStep, panda_chain_moving_planar_auto, "/urdf/chains/panda_chain.urdf",
                  "", false, "defaults");
BENCHMARK_CAPTURE(estimatorStep, panda_chain_moving_planar_off, "/urdf/chains/panda_chain.urdf", "",
                  false, "planar_off");

#define JLE_PASSES(name, file)                     \
  BENCHMARK_CAPTURE(coreDouble, name, file);       \
  BENCHMARK_CAPTURE(coreDoubleWorld, name, file);  \
  BENCHMARK_CAPTURE(fullStep, name, file);         \
  BENCHMARK_CAPTURE(fullStepSmoother, name, file); \
  BENCHMARK_CAPTURE(fullStepBothStreams, name, file)
JLE_PASSES(panda_chain, "/urdf/chains/panda_chain.urdf");
BENCHMARK_CAPTURE(kdlChain, panda_chain, "/urdf/chains/panda_chain.urdf", "panda_link0",
                  "panda_hand_tcp");
BENCHMARK_CAPTURE(kdlTree, panda_chain, "/urdf/chains/panda_chain.urdf");
JLE_PASSES(ur5_chain, "/urdf/chains/ur5_chain.urdf");
BENCHMARK_CAPTURE(kdlChain, ur5_chain, "/urdf/chains/ur5_chain.urdf", "base_link", "tool0");
JLE_PASSES(kinova_chain, "/urdf/chains/kinova_chain.urdf");
BENCHMARK_CAPTURE(kdlChain, kinova_chain, "/urdf/chains/kinova_chain.urdf", "base",
                  "j2s6s200_end_effector");
JLE_PASSES(panda, "/urdf/panda.urdf");
BENCHMARK_CAPTURE(kdlTree, panda, "/urdf/panda.urdf");
JLE_PASSES(talos, "/urdf/talos_reduced.urdf");
BENCHMARK_CAPTURE(coreFloat, talos, "/urdf/talos_reduced.urdf");
BENCHMARK_CAPTURE(coreLongDouble, talos, "/urdf/talos_reduced.urdf");
BENCHMARK_CAPTURE(kdlTree, talos, "/urdf/talos_reduced.urdf");
BENCHMARK_CAPTURE(coreKinematicsOnly, talos, "/urdf/talos_reduced.urdf");
BENCHMARK_CAPTURE(coreDynamicsOnly, talos, "/urdf/talos_reduced.urdf");
BENCHMARK_CAPTURE(coreKinematicsOnly, panda_chain, "/urdf/chains/panda_chain.urdf");
BENCHMARK_CAPTURE(coreDynamicsOnly, panda_chain, "/urdf/chains/panda_chain.urdf");
#define JLE_FILTER(name) \
  BENCHMARK_CAPTURE(filterBank, name, #name)->Arg(6)->Arg(7)->Arg(19)->Arg(50)
JLE_FILTER(kalman_cj);
JLE_FILTER(kalman_ca);
JLE_FILTER(savitzky_golay_9);
JLE_FILTER(finite_difference);
JLE_FILTER(adaptive);
BENCHMARK(smootherBank)->Arg(6)->Arg(7)->Arg(19)->Arg(50);
BENCHMARK(adaptiveSmootherBank)->Arg(6)->Arg(7)->Arg(19)->Arg(50);

int main(int argc, char** argv) {
  const char* const usage =
      "usage: bench_speed_core [Google Benchmark options, e.g. --benchmark_filter=REGEX]\n"
      "The core against Orocos KDL on the same 256 random states, same run: the loads, the\n"
      "full estimator step, the filter bank, scaling to 1000 joints (tools/speed.sh runs it;\n"
      "tools/speed_summary.py prints the ratios).\n";
  return jle_bench::benchmarkMain(argc, argv, "bench_speed_core", usage);
}
