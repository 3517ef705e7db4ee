// accuracy: error against run time and delay of the online estimator (jle::Estimator,
// the code the node runs), over its differentiators, precisions and savings, on
// scenes whose exact joint loads are known (ground_truth.hpp). Writes one CSV row per
// configuration and joint plus an overall row per configuration; bench/plot_accuracy.py
// turns it into docs/accuracy.md and the figures. tools/accuracy.sh runs both.
#include <joint_load_estimator/estimator.hpp>
#include <joint_load_estimator/ground_truth.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

const char* const kUsage =
    R"(usage: accuracy --csv OUT.csv [--quick] [--repeat N] [--data DIR]

Runs every scene's sensor readings through jle::Estimator for each configuration and
compares the loads with the exact ones at the estimate's stamp (a sample stamp).

  --csv PATH    where the results go (CSV, one row per configuration x joint, plus
                a row per configuration with joint = ALL)
  --quick       a tiny input (0.3 s per scene, a few configurations): checks that the
                study still runs, in a second
  --repeat N    timed runs per configuration of the main scene (the fastest counts;
                default 3; other scenes 1)
  --data DIR    the test data directory (default: the package's test/data)

Exit status: 0 success; 1 a failed self-check (exact inputs not reproduced to 1e-9
relative in double precision) or an error; 2 a usage error.
)";

constexpr double kTwoPi = 6.283185307179586;
// The static thresholds' setting: a joint slower than 0.02 rad/s and accelerating less
// than 0.5 rad/s^2 (all joints at once) is taken as still.
constexpr double kStaticVelocity = 0.02;     // [rad/s]
constexpr double kStaticAcceleration = 0.5;  // [rad/s^2]

// ---------------------------------------------------------------------------------
// Configurations.

struct Differentiator {
  std::string label;   // e.g. "SG w9 o2 centred"
  std::string family;  // fd, sg, kalman_ca, kalman_cj
  jle::DifferentiatorConfig config;
};

std::vector<Differentiator> differentiators(bool quick) {
  std::vector<Differentiator> out;
  auto add = [&](const std::string& label, const std::string& family,
                 const jle::DifferentiatorConfig& c) { out.push_back({label, family, c}); };
  for (int delay : {0, 1}) {
    jle::DifferentiatorConfig c;
    c.type = jle::DifferentiatorType::kFiniteDifference;
    c.order = 2;
    c.delay = delay;
    add(std::string("FD3 ") + (delay ? "centred" : "causal"), "fd", c);
  }
  const std::vector<int> windows = quick ? std::vector<int>{9} : std::vector<int>{5, 9, 15, 25};
  const std::vector<int> orders = quick ? std::vector<int>{2} : std::vector<int>{2, 3, 4};
  for (int w : windows)
    for (int o : orders)
      for (bool centred : {false, true}) {
        jle::DifferentiatorConfig c;
        c.type = jle::DifferentiatorType::kSavitzkyGolay;
        c.window = w;
        c.order = o;
        c.delay = centred ? (w - 1) / 2 : 0;
        add("SG w" + std::to_string(w) + " o" + std::to_string(o) + (centred ? " centred" : " causal"),
            "sg", c);
      }
  // Process-noise densities: white jerk [rad^2/s^5] (CA) or snap [rad^2/s^7] (CJ). With
  // the encoder's ~1.5e-5 rad the CA settings put the filter's bandwidth (q/r^2)^(1/6)
  // near 40, 90, 190 and 410 rad/s; the CJ ones ((q/r^2)^(1/8)) near 50, 95, 165, 295.
  const std::vector<double> ca = quick ? std::vector<double>{1e2} : std::vector<double>{1e0, 1e2, 1e4, 1e6};
  const std::vector<double> cj = quick ? std::vector<double>{1e6} : std::vector<double>{1e4, 1e6, 1e8, 1e10};
  for (double q : ca) {
    jle::DifferentiatorConfig c;
    c.type = jle::DifferentiatorType::kKalman;
    c.kalman_model = jle::KalmanModel::kConstantAcceleration;
    c.process_noise = q;
    char label[64];
    std::snprintf(label, sizeof label, "KF-CA q=%.0e", q);
    add(label, "kalman_ca", c);
  }
  for (double q : cj) {
    jle::DifferentiatorConfig c;
    c.type = jle::DifferentiatorType::kKalman;
    c.kalman_model = jle::KalmanModel::kConstantJerk;
    c.process_noise = q;
    char label[64];
    std::snprintf(label, sizeof label, "KF-CJ q=%.0e", q);
    add(label, "kalman_cj", c);
  }
  return out;
}

struct SavingsVariant {
  std::string label;
  jle::Savings savings;
  bool wrist_only = false;  // publish only the last three coordinates' joints
};

// Each switch off on its own, all of them off, the static thresholds at a setting, and
// pruning measured where it can act (a subset of the joints published).
std::vector<SavingsVariant> savingsVariants() {
  std::vector<SavingsVariant> out;
  out.push_back({"default", jle::Savings{}, false});
  jle::Savings s;
  s.prune = false;
  out.push_back({"prune off", s, false});
  s = jle::Savings{};
  s.massless_chains = false;
  out.push_back({"massless_chains off", s, false});
  s = jle::Savings{};
  s.gyroscopic = false;
  out.push_back({"gyroscopic off", s, false});
  s = jle::Savings{};
  s.reuse_unchanged = false;
  out.push_back({"reuse_unchanged off", s, false});
  s = jle::Savings{};
  s.prune = s.massless_chains = s.gyroscopic = s.reuse_unchanged = false;
  out.push_back({"all off", s, false});
  s = jle::Savings{};
  s.static_velocity = kStaticVelocity;
  s.static_acceleration = kStaticAcceleration;
  out.push_back({"static on", s, false});
  out.push_back({"wrist joints", jle::Savings{}, true});
  s = jle::Savings{};
  s.prune = false;
  out.push_back({"wrist joints, prune off", s, true});
  return out;
}

// ---------------------------------------------------------------------------------
// Scenes.

struct SceneSpec {
  std::string name;
  std::string description;
  std::string urdf;  // XML text
  jle::MotionKind motion = jle::MotionKind::kStopAndGo;
  double duration = 10.0;
  jle::SensorModel sensor;
  std::vector<std::string> wrench_links;
  bool planar_wrench = false;    // forces in x-z, moment about y only
  bool constant_wrench = false;  // no sinusoidal part
  std::uint64_t seed = 1;
  bool both_precisions = false;
  bool savings_sweep = false;
  bool timed_repeats = false;  // the fastest of --repeat runs counts
  bool exact = false;          // exact inputs: checked to 1e-9 relative
};

// Precomputed per scene: readings, and the truth at each reading's stamp.
struct Scene {
  SceneSpec spec;
  std::unique_ptr<jle::GroundTruth> truth;
  jle::SensorReadings readings;
  std::vector<double> stamps;      // readings.joints[k].stamp
  Eigen::MatrixXd true_effort;     // nmoving x N
  Eigen::MatrixXd true_force;      // 3 nmoving x N
  Eigen::MatrixXd true_moment;     // 3 nmoving x N
  double grid_step = 2.5e-4;       // [s] grid of the true qdd for the lag search
  Eigen::MatrixXd true_qdd_grid;   // nq x G, at (g - grid_offset) * grid_step
  int grid_offset = 0;             // grid samples before t = 0
  double measurement_noise = 1e-6;  // for the Kalman filters [rad]
  double settle = 0.5;              // [s] stamps before this are not scored
};

std::string readFile(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error("cannot read " + path);
  std::string text;
  char buffer[65536];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
  std::fclose(f);
  return text;
}

jle::SensorModel realisticSensor() {
  jle::SensorModel s;
  s.rate = 1000.0;
  s.counts_per_revolution = 131072.0;  // 2^17: 4.79e-5 rad per count
  s.position_noise = 5e-6;             // [rad], about 0.1 count
  s.velocity_noise = 1e-3;
  s.sample_jitter = 1e-5;              // hardware-timed, stamped exactly
  s.drop_probability = 1e-3;
  s.wrench_rate = 1000.0;
  s.wrench_offset = 2.5e-4;            // F/T clock out of phase with the joints
  s.force_noise = 0.1;                 // [N]
  s.moment_noise = 5e-3;               // [N m]
  return s;
}

std::vector<SceneSpec> sceneSpecs(const std::string& data, bool quick) {
  std::vector<SceneSpec> specs;
  const std::string panda = readFile(data + "/urdf/chains/panda_chain.urdf");
  SceneSpec main;
  main.name = "panda";
  main.description =
      "Panda chain, stop-and-go, 1 kHz, 2^17-count encoders + 5e-6 rad noise, 10 us sample "
      "jitter, 0.1% drops, wrist F/T at 1 kHz (0.1 N, 5 mN m noise)";
  main.urdf = panda;
  main.sensor = realisticSensor();
  main.wrench_links = {"panda_hand"};
  main.seed = 1;
  main.both_precisions = main.savings_sweep = main.timed_repeats = true;
  specs.push_back(main);

  SceneSpec exact = main;
  exact.name = "exact";
  exact.description =
      "exact inputs: Panda chain, quadratic q, 1 kHz, no noise, quantisation, jitter or "
      "drops; constant wrench sampled at the joint stamps";
  exact.motion = jle::MotionKind::kQuadratic;
  exact.duration = 2.0;
  exact.sensor = jle::SensorModel{};
  exact.sensor.rate = 1000.0;
  exact.constant_wrench = true;
  exact.seed = 2;
  exact.savings_sweep = exact.timed_repeats = false;
  exact.exact = true;
  specs.push_back(exact);

  if (!quick) {
    SceneSpec s = main;
    s.both_precisions = s.savings_sweep = s.timed_repeats = false;
    s.name = "panda_sines";
    s.description = "as panda, sums of sines";
    s.motion = jle::MotionKind::kSines;
    specs.push_back(s);
    s.name = "panda_ramps";
    s.description = "as panda, smooth ramps back to back";
    s.motion = jle::MotionKind::kRamps;
    specs.push_back(s);
    s = specs[2];
    s.motion = jle::MotionKind::kStopAndGo;
    s.name = "panda_100hz";
    s.description = "as panda, joints at 100 Hz";
    s.sensor.rate = 100.0;
    specs.push_back(s);
    s.name = "panda_4khz";
    s.description = "as panda, joints at 4 kHz, 5 s";
    s.sensor.rate = 4000.0;
    s.duration = 5.0;
    specs.push_back(s);
    s = specs[2];
    s.motion = jle::MotionKind::kStopAndGo;
    s.name = "panda_stamp_jitter";
    s.description = "as panda, stamps taken on receipt (50 us jitter) and 2% drops";
    s.sensor.stamp_jitter = 5e-5;
    s.sensor.drop_probability = 0.02;
    specs.push_back(s);
    s = specs[2];
    s.motion = jle::MotionKind::kStopAndGo;
    s.name = "panda_ft_bias";
    s.description = "as panda, F/T bias (1, -0.5, 0.8) N, (0.05, -0.03, 0.02) N m";
    s.sensor.force_bias = Eigen::Vector3d(1.0, -0.5, 0.8);
    s.sensor.moment_bias = Eigen::Vector3d(0.05, -0.03, 0.02);
    specs.push_back(s);
    s = specs[2];
    s.motion = jle::MotionKind::kStopAndGo;
    s.name = "ur5";
    s.description = "UR5 chain, stop-and-go, sensors as panda, F/T at tool0";
    s.urdf = readFile(data + "/urdf/chains/ur5_chain.urdf");
    s.wrench_links = {"tool0"};
    s.seed = 3;
    specs.push_back(s);
    s.name = "kinova";
    s.description = "Kinova Jaco 2 chain, stop-and-go, sensors as panda, F/T at the end effector";
    s.urdf = readFile(data + "/urdf/chains/kinova_chain.urdf");
    s.wrench_links = {"j2s6s200_end_effector"};
    s.seed = 4;
    specs.push_back(s);
    s.name = "talos";
    s.description = "TALOS reduced, pelvis fixed, 32 joints, sums of sines, 5 s, wrenches at "
                    "both soles and the left wrist F/T";
    s.urdf = readFile(data + "/urdf/talos_reduced.urdf");
    s.motion = jle::MotionKind::kSines;
    s.duration = 5.0;
    s.wrench_links = {"left_sole_link", "right_sole_link", "wrist_left_ft_link"};
    s.seed = 5;
    specs.push_back(s);
    s.name = "random_tree";
    s.description = "random tree of 12 links (seed 6), smooth ramps, sensors as panda";
    s.urdf = jle::randomTreeUrdf(6, 12);
    s.motion = jle::MotionKind::kRamps;
    s.duration = 10.0;
    s.wrench_links = {"link12"};
    s.seed = 6;
    specs.push_back(s);
    s.name = "planar";
    s.description = "planar 3-link arm, stop-and-go, in-plane tip load, sensors as panda";
    s.urdf = jle::planarArmUrdf();
    s.motion = jle::MotionKind::kStopAndGo;
    s.wrench_links = {"tip"};
    s.planar_wrench = true;
    s.seed = 7;
    specs.push_back(s);
  } else {
    SceneSpec s = main;
    s.both_precisions = s.savings_sweep = s.timed_repeats = false;
    s.name = "planar";
    s.description = "planar 3-link arm (quick)";
    s.urdf = jle::planarArmUrdf();
    s.wrench_links = {"tip"};
    s.planar_wrench = true;
    specs.push_back(s);
    s.name = "random_tree";
    s.description = "random tree (quick)";
    s.urdf = jle::randomTreeUrdf(6, 12);
    s.wrench_links = {"link12"};
    specs.push_back(s);
  }
  if (quick)
    for (SceneSpec& s : specs) s.duration = 0.3;
  return specs;
}

Scene buildScene(const SceneSpec& spec) {
  Scene scene;
  scene.spec = spec;
  jle::Model<double> model = jle::modelFromUrdfString(spec.urdf);
  std::vector<jle::CoordinateMotion> motion =
      jle::randomMotion(model, spec.motion, spec.duration, jle::deriveSeed(spec.seed, 100));
  std::vector<jle::WrenchMotion> wrenches;
  for (std::size_t i = 0; i < spec.wrench_links.size(); ++i) {
    jle::WrenchMotion w = jle::randomWrench(spec.wrench_links[i], jle::deriveSeed(spec.seed, 300 + i));
    if (spec.constant_wrench) w.amplitude.setZero();
    if (spec.planar_wrench)
      for (int c : {1, 3, 5}) w.mean[c] = w.amplitude[c] = 0.0;  // fy, mx, mz
    wrenches.push_back(w);
  }
  scene.truth = std::make_unique<jle::GroundTruth>(model, motion, wrenches);
  scene.readings = scene.truth->sample(spec.sensor, spec.duration, jle::deriveSeed(spec.seed, 200));
  scene.settle = std::min(0.5, 0.1 * spec.duration);

  const jle::Model<double>& m = scene.truth->model();
  const int nmov = static_cast<int>(m.moving_segments.size());
  const int n = static_cast<int>(scene.readings.joints.size());
  scene.true_effort.resize(nmov, n);
  scene.true_force.resize(3 * nmov, n);
  scene.true_moment.resize(3 * nmov, n);
  jle::Data<double> data(m);
  for (int k = 0; k < n; ++k) {
    const double t = scene.readings.joints[static_cast<std::size_t>(k)].stamp;
    scene.stamps.push_back(t);
    scene.truth->loads(t, data);
    for (int j = 0; j < nmov; ++j) {
      const int s = m.moving_segments[static_cast<std::size_t>(j)];
      scene.true_effort(j, k) = data.effort[static_cast<std::size_t>(s)];
      scene.true_force.block<3, 1>(3 * j, k) = data.force[static_cast<std::size_t>(s)];
      scene.true_moment.block<3, 1>(3 * j, k) = data.moment[static_cast<std::size_t>(s)];
    }
  }
  // The true qdd on a fine grid reaching 0.5 s before the start, for the lag search.
  scene.grid_offset = static_cast<int>(std::ceil(0.5 / scene.grid_step));
  const int g = scene.grid_offset + static_cast<int>(std::ceil(spec.duration / scene.grid_step)) + 2;
  scene.true_qdd_grid.resize(m.nq, g);
  jle::VectorX<double> q, qd, qdd;
  for (int i = 0; i < g; ++i) {
    scene.truth->coordinates((i - scene.grid_offset) * scene.grid_step, q, qd, qdd);
    scene.true_qdd_grid.col(i) = qdd;
  }
  const double resolution =
      spec.sensor.counts_per_revolution > 0.0 ? kTwoPi / spec.sensor.counts_per_revolution : 0.0;
  // What a user would configure: the encoder's rounding (uniform, std res/sqrt(12)) and
  // its noise; a floor for exact inputs, where the filter still needs a positive value.
  scene.measurement_noise = std::max(
      1e-6, std::sqrt(spec.sensor.position_noise * spec.sensor.position_noise +
                      resolution * resolution / 12.0));
  return scene;
}

// ---------------------------------------------------------------------------------
// Runs and scores.

struct Score {
  std::string joint;
  long samples = 0;
  double rms_effort = 0, max_effort = 0, rms_force = 0, max_force = 0, rms_moment = 0,
         max_moment = 0;
  double rms_true_effort = 0, rms_true_force = 0, rms_true_moment = 0;
};

struct RunResult {
  std::vector<Score> joints;  // evaluated joints, then ALL
  double time_per_sample_us = 0;
  double stamp_lag_ms = 0;  // mean of newest stamp - estimate stamp
  double phase_lag_ms = std::nan("");  // lag maximising the cross-correlation of qdd
  long published = 0;
};

// Lag [s] that maximises sum_k sum_i est(i, k) true_qdd_i(stamp_k - lag) over lag in
// [-0.04, 0.3] s: a coarse search at 2 ms, a fine one at the grid step around the best,
// and a parabola through the three best points.
double phaseLag(const Scene& scene, const std::vector<double>& stamps, const Eigen::MatrixXd& qdd) {
  const int n = static_cast<int>(stamps.size());
  if (n < 10) return std::nan("");
  const double h = scene.grid_step;
  std::vector<int> base(static_cast<std::size_t>(n));
  std::vector<double> frac(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double x = stamps[static_cast<std::size_t>(k)] / h + scene.grid_offset;
    base[static_cast<std::size_t>(k)] = static_cast<int>(std::floor(x));
    frac[static_cast<std::size_t>(k)] = x - std::floor(x);
  }
  const Eigen::MatrixXd& G = scene.true_qdd_grid;
  const int cols = static_cast<int>(G.cols());
  auto correlation = [&](int lag) {  // lag in grid steps
    double sum = 0.0, norm_true = 0.0;
    for (int k = 0; k < n; ++k) {
      const int i0 = base[static_cast<std::size_t>(k)] - lag;
      if (i0 < 0 || i0 + 1 >= cols) continue;
      const double f = frac[static_cast<std::size_t>(k)];
      for (int c = 0; c < G.rows(); ++c) {
        const double t = (1.0 - f) * G(c, i0) + f * G(c, i0 + 1);
        sum += qdd(c, k) * t;
        norm_true += t * t;
      }
    }
    return norm_true > 0.0 ? sum / std::sqrt(norm_true) : 0.0;
  };
  const int lo = static_cast<int>(std::lround(-0.04 / h)), hi = static_cast<int>(std::lround(0.3 / h));
  const int coarse = std::max(1, static_cast<int>(std::lround(0.002 / h)));
  int best = 0;
  double best_value = -std::numeric_limits<double>::infinity();
  for (int lag = lo; lag <= hi; lag += coarse) {
    const double v = correlation(lag);
    if (v > best_value) best_value = v, best = lag;
  }
  const int centre = best;
  for (int lag = centre - coarse; lag <= centre + coarse; ++lag) {
    const double v = correlation(lag);
    if (v > best_value) best_value = v, best = lag;
  }
  const double left = correlation(best - 1), right = correlation(best + 1);
  const double curvature = left - 2.0 * best_value + right;
  const double offset = curvature < 0.0 ? 0.5 * (left - right) / curvature : 0.0;
  return (best + std::max(-0.5, std::min(0.5, offset))) * h;
}

RunResult runConfig(const Scene& scene, const jle::EstimatorConfig& config,
                    const std::vector<int>& segments, int repeats, bool want_lag) {
  const jle::Model<double>& model = scene.truth->model();
  const jle::SensorReadings& r = scene.readings;
  const int nseg = static_cast<int>(segments.size());
  const std::size_t n = r.joints.size();
  // Outputs of the published samples: stamp, newest stamp, then per joint effort, force, moment.
  std::vector<double> stamps, newest;
  std::vector<double> loads;
  Eigen::MatrixXd qdd;
  RunResult result;
  double best = std::numeric_limits<double>::infinity();
  for (int rep = 0; rep < repeats; ++rep) {
    jle::Estimator estimator(model, config);
    stamps.clear();
    newest.clear();
    loads.clear();
    stamps.reserve(n);
    newest.reserve(n);
    loads.reserve(n * static_cast<std::size_t>(7 * nseg));
    qdd.resize(model.nq, static_cast<Eigen::Index>(n));
    std::size_t w = 0;
    long published = 0;
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < n; ++k) {
      const jle::JointReading& j = r.joints[k];
      while (w < r.wrenches.size() && r.wrenches[w].stamp <= j.stamp) {
        const jle::WrenchReading& x = r.wrenches[w++];
        estimator.addWrench(x.input, x.stamp, x.force, x.moment);
      }
      if (estimator.addJointSample(j.stamp, j.q.data()) != jle::SampleStatus::kPublished) continue;
      const jle::Data<double>& d = estimator.data();
      stamps.push_back(estimator.stamp());
      newest.push_back(j.stamp);
      for (int s : segments) {
        const std::size_t i = static_cast<std::size_t>(s);
        loads.push_back(d.effort[i]);
        loads.insert(loads.end(), d.force[i].data(), d.force[i].data() + 3);
        loads.insert(loads.end(), d.moment[i].data(), d.moment[i].data() + 3);
      }
      qdd.col(published++) = estimator.qdd();
    }
    const auto stop = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::micro>(stop - start).count() /
                              static_cast<double>(n));
    result.published = published;
  }
  result.time_per_sample_us = best;
  qdd.conservativeResize(Eigen::NoChange, result.published);

  // Score against the truth at each estimate's stamp, which is one of the reading stamps.
  const std::vector<int>& moving = model.moving_segments;
  std::vector<Score> scores(static_cast<std::size_t>(nseg) + 1);
  double lag_sum = 0.0;
  std::vector<double> scored_stamps;
  std::vector<int> scored_columns;
  for (std::size_t p = 0; p < stamps.size(); ++p) {
    lag_sum += newest[p] - stamps[p];
    const auto it = std::lower_bound(scene.stamps.begin(), scene.stamps.end(), stamps[p]);
    if (it == scene.stamps.end() || *it != stamps[p])
      throw std::logic_error("an estimate's stamp is not a sample stamp");
    const long k = it - scene.stamps.begin();
    if (stamps[p] < scene.settle) continue;
    scored_stamps.push_back(stamps[p]);
    scored_columns.push_back(static_cast<int>(p));
    const double* out = &loads[p * static_cast<std::size_t>(7 * nseg)];
    for (int j = 0; j < nseg; ++j, out += 7) {
      const int row = static_cast<int>(std::find(moving.begin(), moving.end(), segments[static_cast<std::size_t>(j)]) - moving.begin());
      const double de = out[0] - scene.true_effort(row, k);
      const double df = (Eigen::Vector3d(out + 1) - scene.true_force.block<3, 1>(3 * row, k)).norm();
      const double dm = (Eigen::Vector3d(out + 4) - scene.true_moment.block<3, 1>(3 * row, k)).norm();
      for (Score* s : {&scores[static_cast<std::size_t>(j)], &scores.back()}) {
        ++s->samples;
        s->rms_effort += de * de;
        s->max_effort = std::max(s->max_effort, std::abs(de));
        s->rms_force += df * df;
        s->max_force = std::max(s->max_force, df);
        s->rms_moment += dm * dm;
        s->max_moment = std::max(s->max_moment, dm);
        s->rms_true_effort += scene.true_effort(row, k) * scene.true_effort(row, k);
        s->rms_true_force += scene.true_force.block<3, 1>(3 * row, k).squaredNorm();
        s->rms_true_moment += scene.true_moment.block<3, 1>(3 * row, k).squaredNorm();
      }
    }
  }
  for (int j = 0; j <= nseg; ++j) {
    Score& s = scores[static_cast<std::size_t>(j)];
    s.joint = j < nseg ? model.joint_name[static_cast<std::size_t>(segments[static_cast<std::size_t>(j)])] : "ALL";
    const double count = std::max<long>(1, s.samples);
    for (double* x : {&s.rms_effort, &s.rms_force, &s.rms_moment, &s.rms_true_effort,
                      &s.rms_true_force, &s.rms_true_moment})
      *x = std::sqrt(*x / count);
  }
  result.joints = scores;
  result.stamp_lag_ms = stamps.empty() ? 0.0 : 1e3 * lag_sum / static_cast<double>(stamps.size());
  if (want_lag) {
    Eigen::MatrixXd scored(model.nq, static_cast<Eigen::Index>(scored_columns.size()));
    for (std::size_t i = 0; i < scored_columns.size(); ++i)
      scored.col(static_cast<Eigen::Index>(i)) = qdd.col(scored_columns[i]);
    // The lag of the estimate behind the truth at its own stamp.
    result.phase_lag_ms = 1e3 * phaseLag(scene, scored_stamps, scored);
  }
  return result;
}

double relative(double error, double scale) { return scale > 0.0 ? error / scale : 0.0; }

}  // namespace

int main(int argc, char** argv) {
  std::string csv_path;
  bool quick = false;
  int repeat = 3;
  std::string data = JLE_ACCURACY_DATA;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "--csv") csv_path = value();
      else if (arg == "--quick") quick = true;
      else if (arg == "--repeat") repeat = std::stoi(value());
      else if (arg == "--data") data = value();
      else if (arg == "--help") {
        std::fputs(kUsage, stdout);
        return 0;
      } else throw std::invalid_argument("unknown option " + arg);
    }
    if (csv_path.empty()) throw std::invalid_argument("--csv is required");
    if (repeat < 1) throw std::invalid_argument("--repeat must be at least 1");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "accuracy: %s\n%s", e.what(), kUsage);
    return 2;
  }
  if (quick) repeat = 1;

  try {
    std::FILE* csv = std::fopen(csv_path.c_str(), "w");
    if (!csv) throw std::runtime_error("cannot write " + csv_path);
    std::fprintf(csv,
                 "scene,config,family,window,order,delay_samples,process_noise,precision,"
                 "savings,joint,samples,rms_effort,max_effort,rms_force,max_force,rms_moment,"
                 "max_moment,rel_rms_effort,rel_rms_force,rel_rms_moment,stamp_lag_ms,"
                 "phase_lag_ms,delay_ms,time_per_sample_us,rate_hz,scene_description\n");
    bool exact_ok = true;
    double worst_exact = 0.0;
    const std::vector<Differentiator> diffs = differentiators(quick);
    const std::vector<SavingsVariant> variants = savingsVariants();
    const auto study_start = std::chrono::steady_clock::now();
    for (const SceneSpec& spec : sceneSpecs(data, quick)) {
      const auto scene_start = std::chrono::steady_clock::now();
      const Scene scene = buildScene(spec);
      const jle::Model<double>& model = scene.truth->model();
      std::vector<jle::WrenchInputConfig> inputs;
      for (const std::string& link : spec.wrench_links) {
        jle::WrenchInputConfig in;
        in.name = link;
        in.link = link;
        inputs.push_back(in);
      }
      // The last three coordinates' joints (the wrist of an arm), for the pruning rows.
      std::vector<int> wrist;
      for (int s : model.moving_segments)
        if (model.coordinate[static_cast<std::size_t>(s)] >= model.nq - 3) wrist.push_back(s);
      const std::vector<jle::Precision> precisions =
          spec.both_precisions ? std::vector<jle::Precision>{jle::Precision::kDouble, jle::Precision::kFloat}
                               : std::vector<jle::Precision>{jle::Precision::kDouble};
      const std::vector<SavingsVariant> scene_variants =
          spec.savings_sweep ? variants : std::vector<SavingsVariant>{variants.front()};
      int runs = 0;
      for (const Differentiator& diff : diffs) {
        double phase_lag_ms = std::nan("");
        for (jle::Precision precision : precisions)
          for (const SavingsVariant& variant : scene_variants) {
            jle::EstimatorConfig config;
            config.differentiator = diff.config;
            config.differentiator.measurement_noise = scene.measurement_noise;
            config.precision = precision;
            config.savings = variant.savings;
            config.wrenches = inputs;
            config.gravity_world = scene.truth->gravity();
            std::vector<int> segments = model.moving_segments;
            if (variant.wrist_only) {
              segments = wrist;
              for (int s : wrist) config.joints.push_back(model.joint_name[static_cast<std::size_t>(s)]);
            }
            // The filters run in double whatever the precision and the savings: the lag
            // is measured once per differentiator, on the first (double, default) run.
            const bool want_lag = std::isnan(phase_lag_ms);
            RunResult result = runConfig(scene, config, segments,
                                         spec.timed_repeats && variant.label == "default" ? repeat : 1,
                                         want_lag);
            if (want_lag) phase_lag_ms = result.phase_lag_ms;
            result.phase_lag_ms = phase_lag_ms;
            ++runs;
            const double delay_ms = result.stamp_lag_ms + (std::isnan(phase_lag_ms) ? 0.0 : phase_lag_ms);
            const char* precision_name = precision == jle::Precision::kDouble ? "double" : "float";
            for (const Score& s : result.joints) {
              std::fprintf(csv,
                           "%s,%s,%s,%d,%d,%d,%.3g,%s,%s,%s,%ld,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,"
                           "%.6g,%.6g,%.6g,%.4f,%.4f,%.4f,%.4f,%g,\"%s\"\n",
                           spec.name.c_str(), diff.label.c_str(), diff.family.c_str(),
                           diff.config.type == jle::DifferentiatorType::kFiniteDifference
                               ? diff.config.order + 1
                               : (diff.config.type == jle::DifferentiatorType::kKalman ? 0 : diff.config.window),
                           diff.config.type == jle::DifferentiatorType::kKalman
                               ? (diff.config.kalman_model == jle::KalmanModel::kConstantAcceleration ? 2 : 3)
                               : diff.config.order,
                           diff.config.type == jle::DifferentiatorType::kKalman ? 0 : diff.config.delay,
                           diff.config.type == jle::DifferentiatorType::kKalman ? diff.config.process_noise : 0.0,
                           precision_name, variant.label.c_str(), s.joint.c_str(), s.samples,
                           s.rms_effort, s.max_effort, s.rms_force, s.max_force, s.rms_moment,
                           s.max_moment, relative(s.rms_effort, s.rms_true_effort),
                           relative(s.rms_force, s.rms_true_force),
                           relative(s.rms_moment, s.rms_true_moment), result.stamp_lag_ms,
                           phase_lag_ms, delay_ms, result.time_per_sample_us, spec.sensor.rate,
                           spec.description.c_str());
            }
            const Score& all = result.joints.back();
            if (spec.exact && precision == jle::Precision::kDouble && diff.family != "kalman_ca" &&
                diff.family != "kalman_cj") {
              const double rel = std::max({relative(all.rms_effort, all.rms_true_effort),
                                           relative(all.max_force, all.rms_true_force),
                                           relative(all.max_moment, all.rms_true_moment)});
              worst_exact = std::max(worst_exact, rel);
              if (!(rel < 1e-9) || all.samples == 0) {
                exact_ok = false;
                std::fprintf(stderr, "accuracy: exact inputs not reproduced by %s (%s): %.3g relative\n",
                             diff.label.c_str(), variant.label.c_str(), rel);
              }
            }
          }
      }
      std::fflush(csv);
      std::fprintf(stderr, "accuracy: scene %-18s %4d runs, %6zu samples, %.1f s\n", spec.name.c_str(),
                   runs, scene.readings.joints.size(),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - scene_start).count());
    }
    std::fclose(csv);
    std::fprintf(stderr, "accuracy: exact inputs reproduced to %.3g relative (double); study %.1f s\n",
                 worst_exact,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - study_start).count());
    return exact_ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "accuracy: %s\n", e.what());
    return 1;
  }
}
