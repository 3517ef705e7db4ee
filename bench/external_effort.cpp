// External efforts and contact wrenches against KDL's ChainExternalWrenchEstimator
// (Debian's liborocos-kdl-dev), on the same chain and the same states.
//
//   bench_external_effort [Google Benchmark flags]   time per sample
//   (docs/studies/external_effort.md) bench_external_effort --table [--quick]          the error
//   table against a known contact bench_external_effort --friction                 unmodelled
//   friction (issue 40's scene)
//
// Speed: per sample on the Panda chain (7 joints, a wrench at panda_hand_tcp): our
// update (forward pass, M by the composite-rigid-body pass, C^T qd and g through the
// subtree momenta, observer, residual, one damped least-squares solve), the joint-space
// terms alone, KDL's estimator, and the loads alone (jle::rnea) as the peers.
//
// Table: a known wrench at the tool from 1 s to 2 s on a moving Panda (jle_testing::
// ContactScene), 1 kHz joint states through the Pipeline (the node's default filter) for
// the residual and the observer; KDL's estimator is fed the same filtered q, qd and the
// same measured efforts at the same stamps. RMS of the force and moment error over the
// contact after 0.3 s of settling, per scenario: exact, encoder noise, effort noise,
// jittered stamps; at two poses inside the Panda's joint limits and at a near-singular one
// beyond them, each row with the range of the tool Jacobian's condition number over the
// window (sigma_max / sigma_min of its 6 x 7 [m/s; rad/s] rows, as the solve uses it).
#include <joint_load_estimator/estimation/external_effort.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/joint_space.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <jle_testing/contact_scene.hpp>
#include <jle_testing/panda_contacts.hpp>

#include "benchmark_main.hpp"

#include <benchmark/benchmark.h>
#include <kdl/chain.hpp>
#include <kdl/chainexternalwrenchestimator.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

const Eigen::Vector3d kGravity(0.0, 0.0, -9.80665);
const char* kTool = "panda_hand_tcp";
constexpr double kCutoff = 10.0;  // [Hz] observer cut-off, ours and KDL's gain 2 pi f

std::string chainPath() { return std::string(JLE_BENCH_DATA) + "/urdf/chains/panda_chain.urdf"; }

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

KDL::Chain kdlChain() {
  KDL::Tree tree;
  KDL::Chain chain;
  if (!kdl_parser::treeFromString(readFile(chainPath()), tree) ||
      !tree.getChain("panda_link0", kTool, chain))
    throw std::runtime_error("KDL cannot read " + chainPath());
  return chain;
}

void toKdl(const double* v, int n, KDL::JntArray& a) {
  for (int i = 0; i < n; ++i) a(static_cast<unsigned>(i)) = v[i];
}

jle::ExternalEffortConfig externalConfig(jle::ExternalMethod method) {
  jle::ExternalEffortConfig c;
  c.enabled = true;
  c.method = method;
  c.observer_cutoff = kCutoff;
  jle::ContactLinkConfig contact;
  contact.link = kTool;
  c.contacts.push_back(contact);
  return c;
}

// A few hundred states of the scene, with their measured and model efforts.
struct States {
  jle::Model<double> model = jle::modelFromUrdfFile(chainPath());
  std::vector<int> published = jle::publishedSegments(model, {});
  std::vector<jle::VectorX<double>> q, qd, qdd;
  std::vector<std::vector<double>> measured, model_effort;
  States() {
    jle_testing::ContactScene scene;
    scene.link = kTool;
    scene.t_on = 0.0;
    jle::Data<double> data(model);
    for (int k = 0; k < 256; ++k) {
      const double t = k * 1e-3;
      jle::VectorX<double> a, b, c;
      scene.state(model, t, a, b, c);
      q.push_back(a);
      qd.push_back(b);
      qdd.push_back(c);
      std::vector<double> e;
      scene.efforts(model, data, t, published, kGravity, e);
      measured.push_back(e);
      jle::rnea(model, data, a, b, c, kGravity);
      e.clear();
      for (int s : published) e.push_back(data.effort[s]);
      model_effort.push_back(e);
    }
  }
};

const States& states() {
  static const States s;
  return s;
}

void BM_OursExternalEffort(benchmark::State& st) {
  const States& s = states();
  jle::ExternalEffort ext(s.model, externalConfig(jle::ExternalMethod::kObserver), s.published,
                          kGravity, 0.0, false);
  std::size_t k = 0;
  double t = 0.0;
  for (auto _ : st) {
    ext.update(t, s.q[k], s.qd[k], jle::BaseState<double>(), s.model_effort[k], s.measured[k],
               nullptr);
    benchmark::DoNotOptimize(ext.contacts()[0].force);
    k = (k + 1) % s.q.size();
    t += 1e-3;
  }
}
BENCHMARK(BM_OursExternalEffort);

void BM_OursJointSpaceTerms(benchmark::State& st) {
  const States& s = states();
  jle::Data<double> data(s.model);
  jle::JointSpace js(s.model);
  const jle::VectorX<double> zero = jle::VectorX<double>::Zero(s.model.nq);
  std::size_t k = 0;
  for (auto _ : st) {
    jle::forwardKinematics(s.model, data, s.q[k], s.qd[k], zero, kGravity);
    jle::updateJointSpace(s.model, data, kGravity, js);
    benchmark::DoNotOptimize(js.coriolis_transpose.data());
    k = (k + 1) % s.q.size();
  }
}
BENCHMARK(BM_OursJointSpaceTerms);

void BM_KdlExternalWrenchEstimator(benchmark::State& st) {
  const States& s = states();
  const KDL::Chain chain = kdlChain();
  KDL::ChainExternalWrenchEstimator kdl(chain, KDL::Vector(0, 0, kGravity.z()), 1000.0,
                                        2.0 * M_PI * kCutoff, 0.0);
  const int n = s.model.nq;
  KDL::JntArray q(n), qd(n), tau(n);
  KDL::Wrench w;
  std::size_t k = 0;
  for (auto _ : st) {
    toKdl(s.q[k].data(), n, q);
    toKdl(s.qd[k].data(), n, qd);
    toKdl(s.measured[k].data(), n, tau);
    kdl.JntToExtWrench(q, qd, tau, w);
    benchmark::DoNotOptimize(w);
    k = (k + 1) % s.q.size();
  }
}
BENCHMARK(BM_KdlExternalWrenchEstimator);

void BM_LoadsAlone(benchmark::State& st) {
  const States& s = states();
  jle::Data<double> data(s.model);
  std::size_t k = 0;
  for (auto _ : st) {
    jle::rnea(s.model, data, s.q[k], s.qd[k], s.qdd[k], kGravity);
    benchmark::DoNotOptimize(data.effort.data());
    k = (k + 1) % s.q.size();
  }
}
BENCHMARK(BM_LoadsAlone);

// ---------------------------------------------------------------------------------------
// The error table.

struct Scenario {
  const char* name;
  double position_noise;   // [rad] 1 sigma
  double effort_noise;     // [N m] 1 sigma
  double stamp_jitter;     // [s] stamps late by U(0, jitter) (taken at reception)
  double amplitude = 0.3;  // [rad] of the motion (ContactScene)
};

// The poses the Panda moves about (ContactScene::center; 0.3 rad of motion keeps the
// first two inside every joint limit), and ContactScene's own, near-singular, beyond
// joints 4 and 6's limits.
struct Pose {
  const char* name;
  std::vector<double> q;  // empty: ContactScene's own pose
};
const Pose kPoses[] = {{"ready", {0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785}},
                       {"reach", {0.5, 0.3, -0.4, -1.8, 0.6, 2.2, -0.5}},
                       {"near-singular", {}}};

struct Errors {
  double force2 = 0.0, moment2 = 0.0;
  double cond_min = 1e300, cond_max = 0.0;  // the tool Jacobian's sigma_max / sigma_min
  long n = 0;
  void add(const Eigen::Vector3d& f, const Eigen::Vector3d& m, const jle_testing::ContactScene& s) {
    force2 += (f - s.force_link).squaredNorm();
    moment2 += (m - s.moment_link).squaredNorm();
    ++n;
  }
  double force() const { return n ? std::sqrt(force2 / n) : NAN; }
  double moment() const { return n ? std::sqrt(moment2 / n) : NAN; }
};

// One run of the scenario through the Pipeline with `method`; KDL fed alongside.
void runScenario(const Scenario& sc, const Pose& pose, jle::ExternalMethod method, double duration,
                 Errors& ours, Errors& kdl_errors) {
  const jle::Model<double> model = jle::modelFromUrdfFile(chainPath());
  jle::Settings settings;
  settings.external_effort = externalConfig(method);
  settings.smoothed.enabled = false;  // the immediate stream's estimate against KDL's
  jle::Pipeline pipeline(model, settings, nullptr);
  const KDL::Chain chain = kdlChain();
  KDL::ChainExternalWrenchEstimator kdl(chain, KDL::Vector(0, 0, kGravity.z()), 1000.0,
                                        2.0 * M_PI * kCutoff, 0.0);
  const int n = model.nq;
  KDL::JntArray kq(n), kqd(n), ktau(n);
  KDL::Wrench kw;
  bool kdl_started = false;
  jle_testing::ContactScene scene;
  scene.link = kTool;
  scene.t_off = std::min(scene.t_off, duration);
  scene.amplitude = sc.amplitude;
  scene.center = Eigen::Map<const Eigen::VectorXd>(pose.q.data(), static_cast<long>(pose.q.size()));
  jle::Data<double> data(model);
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> late(0.0, 1.0);
  std::vector<double> effort, position, none;
  const jle::Stamp t0 = 1000000000000LL;
  for (int k = 0; k < static_cast<int>(duration * 1000.0); ++k) {
    const double t = k * 1e-3;
    jle::VectorX<double> q, qd, qdd;
    scene.state(model, t, q, qd, qdd);
    scene.efforts(model, data, t, pipeline.record().segment, kGravity, effort);
    position.assign(q.data(), q.data() + n);
    for (double& p : position) p += sc.position_noise * gauss(rng);
    for (double& e : effort) e += sc.effort_noise * gauss(rng);
    const double stamp_t = t + sc.stamp_jitter * late(rng);
    const jle::Stamp stamp = t0 + static_cast<jle::Stamp>(std::llround(stamp_t * 1e9));
    if (pipeline.onJointState(stamp, stamp, model.coordinate_names, position, none, effort) !=
        jle::Outcome::kPublished)
      continue;
    const jle::LoadsRecord& r = pipeline.record();
    toKdl(r.position.data(), n, kq);
    toKdl(r.velocity.data(), n, kqd);
    toKdl(r.measured_effort.data(), n, ktau);
    if (!kdl_started) kdl.setInitialMomentum(kq, kqd);
    kdl_started = true;
    kdl.JntToExtWrench(kq, kqd, ktau, kw);
    // The record describes the sample whose (jittered) stamp it carries: its true time is
    // the nearest millisecond at or below.
    const double tr = std::floor(static_cast<double>(r.stamp - t0) * 1e-6 + 1e-6) * 1e-3;
    if (!(tr >= scene.t_on + 0.3 && scene.active(tr))) continue;
    ours.add(r.contacts[0].force, r.contacts[0].moment, scene);
    ours.cond_min = std::min(ours.cond_min, 1.0 / r.contacts[0].conditioning);
    ours.cond_max = std::max(ours.cond_max, 1.0 / r.contacts[0].conditioning);
    kdl_errors.add(Eigen::Vector3d(kw.force.x(), kw.force.y(), kw.force.z()),
                   Eigen::Vector3d(kw.torque.x(), kw.torque.y(), kw.torque.z()), scene);
  }
}

int table(bool quick) {
  const Scenario scenarios[] = {{"exact", 0.0, 0.0, 0.0},
                                {"encoder noise 1e-4 rad", 1e-4, 0.0, 0.0},
                                {"effort noise 0.1 N m", 0.0, 0.1, 0.0},
                                {"jittered stamps 0.3 ms", 0.0, 0.0, 3e-4},
                                {"exact, slow motion (0.03 rad)", 0.0, 0.0, 0.0, 0.03}};
  const double duration = quick ? 1.5 : 2.2;
  std::printf(
      "| pose | scenario | cond | residual F [N] | residual M [N m] | observer F [N] "
      "| observer M [N m] | KDL F [N] | KDL M [N m] |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const Pose& pose : kPoses)
    for (const Scenario& sc : scenarios) {
      Errors residual, observer, kdl, kdl_again;
      runScenario(sc, pose, jle::ExternalMethod::kResidual, duration, residual, kdl);
      runScenario(sc, pose, jle::ExternalMethod::kObserver, duration, observer, kdl_again);
      std::printf("| %s | %s | %.0f-%.0f | %.3g | %.3g | %.3g | %.3g | %.3g | %.3g |\n", pose.name,
                  sc.name, residual.cond_min, residual.cond_max, residual.force(),
                  residual.moment(), observer.force(), observer.moment(), kdl.force(),
                  kdl.moment());
      if (!(residual.n > 0 && observer.n > 0)) return 1;
    }
  return 0;
}

// ---------------------------------------------------------------------------------------
// Unmodelled friction: issue 40's scene (jle_testing::PandaContacts, KDL's RNE efforts,
// effort noise 0.1 N m, position noise 1e-4 rad, the observer, noise_multiple 6, contacts
// at the fingertip and on link 5) with joint friction added to the measured efforts:
// damping 0.1 N m s/rad and Coulomb 0.5 N m on joints 1-4, 0.05 and 0.2 on joints 5-7,
// tanh(qd / 0.01) (friction.hpp's model).

struct FrictionRow {
  const char* name;
  bool friction;                   // in the measured efforts
  bool modelled;                   // in the model, friction/enabled
  double noise_multiple;           // external_effort/noise_multiple
  std::vector<double> thresholds;  // joint_thresholds of joints 1..7 [N m] (empty: none)
};

struct FrictionFigures {
  double free_rms[7] = {0, 0, 0, 0, 0, 0, 0};  // tau_ext in free motion [N m]
  long free_n = 0, false_samples = 0;
  double delay[3] = {NAN, NAN, NAN};  // [ms] per scene contact
  double force2 = 0.0;                // fingertip force error where reported, 0.1 s into
  long force_n = 0, contact_n = 0;    // its contact on; samples there
};

// The defaults but for the row's detection, friction and the two contacts.
jle::Settings frictionSettings(const FrictionRow& row, const jle::Model<double>& model,
                               const std::vector<int>& published,
                               const jle_testing::PandaContacts& scene) {
  jle::Settings settings;
  settings.smoothed.enabled = false;
  settings.friction.enabled = row.modelled;
  jle::ExternalEffortConfig& x = settings.external_effort;
  x.enabled = true;
  x.noise_multiple = row.noise_multiple;
  for (std::size_t i = 0; i < row.thresholds.size(); ++i)
    x.joint_thresholds.emplace_back(model.joint_name[published[i]], row.thresholds[i]);
  for (int k : {0, 2}) {
    jle::ContactLinkConfig c;
    c.link = scene.contacts[k].link;
    c.point = scene.contacts[k].point;
    c.force_only = true;
    x.contacts.push_back(c);
  }
  return settings;
}

FrictionFigures runFriction(const FrictionRow& row) {
  jle::Model<double> model = jle::modelFromUrdfFile(chainPath());
  const jle_testing::PandaContacts scene(readFile(chainPath()));
  const std::vector<int> published = jle::publishedSegments(model, {});
  std::vector<double> damping(7), coulomb(7);
  for (int i = 0; i < 7; ++i) {
    damping[i] = i < 4 ? 0.1 : 0.05;
    coulomb[i] = i < 4 ? 0.5 : 0.2;
    model.damping[published[i]] = row.modelled ? damping[i] : 0.0;
    model.friction[published[i]] = row.modelled ? coulomb[i] : 0.0;
  }
  jle::Pipeline pipeline(model, frictionSettings(row, model, published, scene), nullptr);
  std::mt19937 rng(40);
  std::normal_distribution<double> gauss(0.0, 1.0);
  FrictionFigures f;
  const jle::Stamp t0 = 1000000000000LL;
  std::vector<double> position(7), none;
  for (int k = 0; k < 5000; ++k) {
    const double t = k * 1e-3;
    Eigen::VectorXd q, qd, qdd;
    scene.state(t, q, qd, qdd);
    std::vector<double> effort = scene.efforts(t);
    for (int i = 0; i < 7; ++i) {
      position[i] = q[i] + 1e-4 * gauss(rng);
      effort[i] += 0.1 * gauss(rng);
      if (row.friction) effort[i] += damping[i] * qd[i] + coulomb[i] * std::tanh(qd[i] / 0.01);
    }
    const jle::Stamp stamp = t0 + static_cast<jle::Stamp>(k) * 1000000;
    if (pipeline.onJointState(stamp, stamp, model.coordinate_names, position, none, effort) !=
        jle::Outcome::kPublished)
      continue;
    const jle::LoadsRecord& r = pipeline.record();
    const double tr = std::round(static_cast<double>(r.stamp - t0) * 1e-6) * 1e-3;
    int near = -1;  // the scene contact whose window (+ 0.15 s release) holds tr
    for (int c = 0; c < 3; ++c)
      if (tr >= scene.contacts[c].t_on && tr < scene.contacts[c].t_off + 0.15) near = c;
    if (near >= 0 && r.contact_started && std::isnan(f.delay[near]))
      f.delay[near] = (tr - scene.contacts[near].t_on) * 1e3;
    if (near < 0 && tr > 1.5) {
      ++f.free_n;
      f.false_samples += r.in_contact;
      for (int i = 0; i < 7; ++i) f.free_rms[i] += r.external_effort[i] * r.external_effort[i];
    }
    if (scene.active(tr) == 0 && tr >= scene.contacts[0].t_on + 0.1) {
      ++f.contact_n;
      if (!r.contacts[0].active) continue;
      f.force2 += (r.contacts[0].force - scene.contacts[0].force).squaredNorm();
      ++f.force_n;
    }
  }
  for (double& v : f.free_rms) v = std::sqrt(v / std::max(1L, f.free_n));
  return f;
}

int frictionTable() {
  // 6 x the friction-free RMS of tau_ext (the first row's calibration), and those raised by
  // the friction's peak (Coulomb + damping at 0.5 rad/s: 0.55 N m on joints 1-4, 0.23 on
  // joints 5-7) plus 0.5 and 0.2 N m.
  const std::vector<double> free = {0.8, 2.4, 1.3, 1.6, 0.15, 0.22, 0.1};
  const std::vector<double> raised = {1.85, 3.45, 2.35, 2.65, 0.58, 0.65, 0.53};
  const FrictionRow rows[] = {
      {"none; noise_multiple 6", false, false, 6.0, {}},
      {"not modelled; noise_multiple 6", true, false, 6.0, {}},
      {"modelled (friction/enabled); noise_multiple 6", true, true, 6.0, {}},
      {"none; joint_thresholds: the friction-free ones", false, false, 0.0, free},
      {"not modelled; joint_thresholds: the friction-free ones", true, false, 0.0, free},
      {"not modelled; joint_thresholds raised over the friction", true, false, 0.0, raised},
      {"none; no detection", false, false, 0.0, {}},
      {"not modelled; no detection", true, false, 0.0, {}}};
  std::printf(
      "| friction; detection | RMS tau_ext free, joints 1..7 [N m] | false-contact samples | "
      "delays fingertip / link 4 / link 5 [ms] | fingertip force error [N] (reported) "
      "|\n|---|---|---|---|---|\n");
  for (const FrictionRow& row : rows) {
    const FrictionFigures f = runFriction(row);
    std::printf("| %s |", row.name);
    for (double v : f.free_rms) std::printf(" %.3g", v);
    std::printf(" | %ld / %ld |", f.false_samples, f.free_n);
    for (double d : f.delay) std::isnan(d) ? std::printf(" missed") : std::printf(" %.0f", d);
    std::printf(" | %.3g (%.0f %%) |\n",
                f.force_n ? std::sqrt(f.force2 / static_cast<double>(f.force_n)) : NAN,
                100.0 * static_cast<double>(f.force_n) / std::max(1L, f.contact_n));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const char* const usage =
      "usage: bench_external_effort [--table [--quick] | --friction | Google Benchmark options]\n"
      "--table: the external wrench's error at poses inside the Panda's limits, ours against\n"
      "KDL's ChainExternalWrenchEstimator (docs/studies/external_effort.md); --friction: "
      "unmodelled\n"
      "friction against detection; otherwise the time per sample against KDL's (benchmark).\n";
  bool want_table = false, quick = false, friction = false;
  for (int i = 1; i < argc; ++i) {
    want_table = want_table || std::strcmp(argv[i], "--table") == 0;
    quick = quick || std::strcmp(argv[i], "--quick") == 0;
    friction = friction || std::strcmp(argv[i], "--friction") == 0;
  }
  if (jle::cli::answerHelpOrVersion(argc, argv, "bench_external_effort", usage)) return 0;
  if (friction) return frictionTable();
  if (want_table) return table(quick);
  return jle_bench::benchmarkMain(argc, argv, "bench_external_effort", usage);
}
