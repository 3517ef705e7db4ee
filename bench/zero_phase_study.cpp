// The offline zero-phase smoother's automatic cutoffs against the ground truth
// (docs/studies/zero_phase.md): Panda chain scenes at 100 Hz, 200 Hz and 1 kHz with encoder noise
// 1e-4 .. 1e-3 rad and a noisy wrist wrench; for Winter's residual analysis, GCV and the
// best fixed cutoff of a scan (an oracle that knows the truth), the RMS error of the
// efforts and of qdd. Prints a Markdown table.
//   zero_phase_study [--quick]
#include <jle_testing/ground_truth.hpp>
#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

struct Scene {
  const char* motion_name;
  jle::MotionKind motion;
  double rate, noise, jitter;  // [Hz], [rad], sample jitter [periods]
  std::uint64_t seed;
};

// A scene's readings and its truth at the reading instants.
struct Trial {
  std::vector<double> t;
  Eigen::MatrixXd q, wrench;              // samples x nq, samples x 6
  Eigen::MatrixXd true_effort, true_qdd;  // samples x moving joints, samples x nq
};

Trial makeTrial(const jle::GroundTruth& truth, const Scene& scene, double duration) {
  jle::SensorModel sensor;
  sensor.rate = scene.rate;
  sensor.position_noise = scene.noise;
  sensor.sample_jitter = scene.jitter / scene.rate;
  sensor.force_noise = 0.5;
  sensor.moment_noise = 0.02;
  const jle::SensorReadings r = truth.sample(sensor, duration, scene.seed);
  const jle::Model<double>& model = truth.model();
  const std::size_t n = r.joints.size();
  Trial trial;
  trial.q.resize(n, model.nq);
  trial.wrench.resize(n, 6);
  trial.true_effort.resize(n, model.moving_segments.size());
  trial.true_qdd.resize(n, model.nq);
  jle::Data<double> data(model);
  jle::VectorX<double> q, qd, qdd;
  for (std::size_t i = 0; i < n; ++i) {
    const double time = r.joints[i].time;
    trial.t.push_back(time);
    trial.q.row(i) = r.joints[i].q.transpose();
    // The wrench read at the joint's sample (same clock, same rate).
    const jle::WrenchReading& w = r.wrenches[std::min(i, r.wrenches.size() - 1)];
    trial.wrench.row(i) << w.force.transpose(), w.moment.transpose();
    truth.coordinates(time, q, qd, qdd);
    trial.true_qdd.row(i) = qdd.transpose();
    truth.loads(time, data);
    for (std::size_t j = 0; j < model.moving_segments.size(); ++j)
      trial.true_effort(i, j) = data.effort[model.moving_segments[j]];
  }
  return trial;
}

struct Errors {
  double cutoff = 0, effort = 0, qdd = 0, effort_inner = 0;
};

// The efforts of the smoothed trial at cutoff `cutoff` (rule kFixed) or by `rule`.
Errors evaluate(const jle::GroundTruth& truth, const Trial& trial, jle::CutoffRule rule,
                double cutoff) {
  jle::ZeroPhaseConfig config;
  config.rule = rule;
  config.cutoff = cutoff;
  const jle::ZeroPhaseResult k = jle::smoothZeroPhase(trial.t, trial.q, config);
  const Eigen::MatrixXd w = jle::lowPassZeroPhase(trial.t, trial.wrench, k.cutoff, config.order);
  const jle::Model<double>& model = truth.model();
  const int frame = model.frameIndex(truth.wrenches()[0].link);
  jle::Data<double> data(model);
  Errors e;
  e.cutoff = k.cutoff;
  double inner = 0.0;
  long inner_count = 0;
  const std::size_t n = trial.t.size();
  for (std::size_t i = 0; i < n; ++i) {
    jle::forwardKinematics(model, data, jle::VectorX<double>(k.value.row(i).transpose()),
                           jle::VectorX<double>(k.rate.row(i).transpose()),
                           jle::VectorX<double>(k.accel.row(i).transpose()), truth.gravity());
    jle::addExternalWrench(model, data, frame, Eigen::Vector3d(w.row(i).head<3>().transpose()),
                           Eigen::Vector3d(w.row(i).tail<3>().transpose()),
                           jle::WrenchFrame::kLocal);
    jle::inverseDynamics(model, data);
    double sq = 0.0;
    for (std::size_t j = 0; j < model.moving_segments.size(); ++j)
      sq += std::pow(data.effort[model.moving_segments[j]] - trial.true_effort(i, j), 2);
    e.effort += sq;
    // 0.5 s from each end: the record ends' own error (odd reflection) left out.
    if (trial.t[i] - trial.t.front() >= 0.5 && trial.t.back() - trial.t[i] >= 0.5)
      inner += sq, ++inner_count;
  }
  const double joints = static_cast<double>(model.moving_segments.size());
  e.effort = std::sqrt(e.effort / (joints * n));
  e.effort_inner = std::sqrt(inner / (joints * inner_count));
  e.qdd = std::sqrt((k.accel - trial.true_qdd).squaredNorm() / trial.true_qdd.size());
  return e;
}

// The best fixed cutoff of a scan at ratio 1.1 from 1 Hz to 0.4 of the rate (an oracle).
Errors bestFixed(const jle::GroundTruth& truth, const Trial& trial, double rate) {
  Errors best;
  best.effort = INFINITY;
  for (double fc = 1.0; fc < 0.4 * rate; fc *= 1.1) {
    const Errors e = evaluate(truth, trial, jle::CutoffRule::kFixed, fc);
    if (e.effort < best.effort) best = e;
  }
  return best;
}

void printRow(const Scene& s, const char* rule, const Errors& e) {
  std::printf("| %s | %g | %g | %g | %s | %.3g | %.3g | %.3g | %.3g |\n", s.motion_name, s.rate,
              s.noise, s.jitter, rule, e.cutoff, e.effort, e.effort_inner, e.qdd);
}

}  // namespace

const char* const kUsage =
    "usage: zero_phase_study [--quick]\n"
    "The offline zero-phase smoother's automatic cutoffs (residual analysis, GCV) against the\n"
    "best fixed cutoff on Panda scenes at 100 Hz, 200 Hz and 1 kHz (docs/studies/zero_phase.md):\n"
    "prints a Markdown table. --quick: 2 s scenes instead of 10 s.\n";

int main(int argc, char** argv) {
  if (jle::cli::answerHelpOrVersion(argc, argv, "zero_phase_study", kUsage)) return 0;
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const jle::Model<double> model =
      jle::modelFromUrdfFile(std::string(JLE_BENCH_DATA) + "/urdf/chains/panda_chain.urdf");
  const double duration = quick ? 2.0 : 10.0;
  std::vector<Scene> scenes;
  for (const double rate : {100.0, 200.0, 1000.0})
    for (const double noise : {1e-4, 3e-4, 1e-3})
      for (const int m : {0, 1})
        scenes.push_back({m == 0 ? "stop-and-go" : "sines",
                          m == 0 ? jle::MotionKind::kStopAndGo : jle::MotionKind::kSines, rate,
                          noise, 0.0, static_cast<std::uint64_t>(m + 1)});
  for (const double rate : {200.0, 1000.0})
    scenes.push_back({"stop-and-go", jle::MotionKind::kStopAndGo, rate, 3e-4, 0.15, 1});
  if (quick) scenes.resize(2);
  std::printf(
      "| motion | rate [Hz] | noise [rad] | jitter [periods] | cutoff rule | cutoff [Hz] | "
      "effort RMS [N m] | same, 0.5 s from the ends | qdd RMS [rad/s^2] |\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  for (const Scene& s : scenes) {
    const jle::GroundTruth truth(model, jle::randomMotion(model, s.motion, duration, s.seed),
                                 {jle::randomWrench("panda_hand", s.seed + 10)});
    const Trial trial = makeTrial(truth, s, duration);
    printRow(s, "residual", evaluate(truth, trial, jle::CutoffRule::kResidual, 0.0));
    printRow(s, "GCV", evaluate(truth, trial, jle::CutoffRule::kGcv, 0.0));
    printRow(s, "noise spectrum", evaluate(truth, trial, jle::CutoffRule::kSpectrum, 0.0));
    printRow(s, "best fixed (oracle)", bestFixed(truth, trial, s.rate));
    std::fflush(stdout);
  }
  return 0;
}
