// Numerical stability of the core and of the filters: sweeps that push one parameter
// to its extreme and measure the error against a quad-precision reference on the same
// inputs. Writes docs/studies/stability.md (one table per sweep) and exits non-zero if a
// measurement exceeds the bound that test/algorithms/test_stability.cpp asserts.
//
//   stability [--output PATH] [--quick]
//
// --quick: fewer samples and 1e5 instead of 1e7 filter steps (for CI; the tables are
// the same shape).
#include "stability_literal.hpp"
#include "stability_quad.hpp"

#include <jle_testing/far_com.hpp>
#include <jle_testing/stability_bounds.hpp>

#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/random_models.hpp>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace {

using jle_bench::Quad;
using jle_test::Error;
using jle_test::Precisions;
using jle_test::RandomModelSpec;
using jle_test::Scene;
namespace bounds = jle_test::bounds;
using bounds::generic;

const std::string kData = JLE_BENCH_DATA;
bool quick = false;
int violations = 0;

std::string sci(double x) {
  if (x == 0.0) return "0";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1e", x);
  return buf;
}

std::string fixed(double x, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, x);
  return buf;
}

/// A measured value, marked (and counted as a violation) when over its bound.
std::string checked(double measured, double bound) {
  std::string s = sci(measured);
  if (measured > bound) {
    ++violations;
    s += " **OVER " + sci(bound) + "**";
  }
  return s;
}

struct Table {
  std::string title, text;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::string markdown() const {
    std::ostringstream os;
    os << "## " << title << "\n\n" << text << "\n\n|";
    for (const std::string& h : header) os << " " << h << " |";
    os << "\n|";
    for (std::size_t k = 0; k < header.size(); ++k) os << "---|";
    os << "\n";
    for (const auto& r : rows) {
      os << "|";
      for (const std::string& c : r) os << " " << c << " |";
      os << "\n";
    }
    return os.str();
  }
};

std::vector<Table> tables;

// The figures the findings quote, as the sweeps measured them (double, worst relative
// error of the joint wrenches, or of the effort for the far centre of mass).
struct Findings {
  double chain_100 = 0.0, chain_1000 = 0.0, tree_100 = 0.0, tree_1000 = 0.0;
  double tiny_inertia = 0.0;
  int tiny_kept_links = 0, tiny_links = 0;
  double far_com = 0.0, far_com_max_distance = 0.0;
};
Findings findings;

void print(const Table& t) {
  std::cout << t.markdown() << std::endl;
  tables.push_back(t);
}

// ---------------------------------------------------------------------------------------
// Core sweeps

/// Worst errors over `models` random models (from spec, seeds 1000, 1001, ...) and
/// `states` random states of each.
jle_test::PrecisionComparison<Quad> sweepPoint(RandomModelSpec spec, int models, int states,
                                               double qd_scale, double qdd_scale) {
  jle_test::PrecisionComparison<Quad> worst;
  for (int k = 0; k < models; ++k) {
    spec.seed = static_cast<std::uint32_t>(1000 + k);
    const jle::Model<double> model = jle::modelFromUrdfString(jle_test::randomUrdf(spec));
    Precisions<Quad> p(model);
    jle_test::Random rng(spec.seed);
    for (int s = 0; s < states; ++s) {
      Scene scene;
      scene.state = jle_test::randomState(model, rng, qd_scale, qdd_scale, spec.length);
      worst.merge(p.compare(scene));
    }
  }
  return worst;
}

/// The row's cells; the wrench is checked against the bounds, the moment too with
/// check_moment.
std::vector<std::string> errorCells(const jle_test::PrecisionComparison<Quad>& c,
                                    double bound_double, double bound_float, bool check_moment) {
  auto moment = [&](double m, double b) { return check_moment ? checked(m, b) : sci(m); };
  return {checked(c.of_double.wrench, bound_double),
          sci(c.of_double.force),
          moment(c.of_double.moment, bound_double),
          checked(c.of_float.wrench, bound_float),
          sci(c.of_float.force),
          moment(c.of_float.moment, bound_float),
          sci(c.of_long_double.wrench),
          sci(bound_double),
          sci(bound_float)};
}

const std::vector<std::string> kErrorHeader = {
    "double: wrench",      "force",        "moment",     "float: wrench", "force", "moment",
    "long double: wrench", "bound double", "bound float"};

std::vector<std::string> header(const std::string& first) {
  std::vector<std::string> h{first};
  h.insert(h.end(), kErrorHeader.begin(), kErrorHeader.end());
  return h;
}

std::vector<std::string> row(const std::string& first, std::vector<std::string> cells) {
  cells.insert(cells.begin(), first);
  return cells;
}

const char* kMetric =
    "Relative error of the joint wrenches against quad precision (`__float128`) on the same "
    "inputs (the model and state rounded to double, then converted): |(dF, dM)| / |(F, M)| "
    "per joint in its child frame (N and N m in one 6-vector), and the force and moment "
    "separately; worst over every joint, model and state of the row.";

void chainLengthSweep(bool tree) {
  Table t;
  t.title = tree ? "Tree size: random trees of 1 to 1000 joints"
                 : "Chain length: serial chains of 1 to 1000 joints";
  t.text = std::string(kMetric) +
           " Random links 0.15-0.3 m, masses 1 kg, revolute joints with random axes and "
           "placements (every 4th prismatic), q uniform in [-pi, pi], qd in [-1, 1] rad/s, "
           "qdd in [-5, 5] rad/s^2; 40 models x 10 states per row up to 100 joints, 10 x 5 "
           "beyond. " +
           (tree ? "Each link hangs from a uniformly random earlier link (depth ~ e ln n)." : "");
  t.header = header("joints");
  for (int n : {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000}) {
    const int models = quick ? 2 : (n <= 100 ? 40 : 10);
    const int states = quick ? 2 : (n <= 100 ? 10 : 5);
    RandomModelSpec spec;
    spec.joints = n;
    spec.tree = tree;
    spec.prismatic_every = 4;
    const auto c = sweepPoint(spec, models, states, 1.0, 5.0);
    if (n == 100) (tree ? findings.tree_100 : findings.chain_100) = c.of_double.wrench;
    if (n == 1000) (tree ? findings.tree_1000 : findings.chain_1000) = c.of_double.wrench;
    t.rows.push_back(row(std::to_string(n),
                         errorCells(c, bounds::chain<double>(n), bounds::chain<float>(n), false)));
    std::cerr << t.title << ": " << n << " done" << std::endl;
  }
  print(t);
}

void ratioSweep(bool inertia) {
  Table t;
  t.title = inertia ? "Inertia ratio across the tree" : "Mass ratio across the tree";
  t.text =
      std::string(kMetric) +
      (inertia ? " Each link's inertia scaled by a factor log-uniform in [1, ratio] (masses 1 kg)."
               : " Link masses log-uniform in [1, ratio] kg (inertias scale with them).") +
      " 10-joint chains and 20-joint trees, 40 models of each, 10 states each.";
  t.header = header("ratio");
  for (double ratio : {1.0, 1e3, 1e6, 1e9}) {
    jle_test::PrecisionComparison<Quad> c;
    for (bool tree : {false, true}) {
      RandomModelSpec spec;
      spec.joints = tree ? 20 : 10;
      spec.tree = tree;
      (inertia ? spec.inertia_ratio : spec.mass_ratio) = ratio;
      c.merge(sweepPoint(spec, quick ? 3 : 40, quick ? 2 : 10, 1.0, 5.0));
    }
    t.rows.push_back(row(sci(ratio), errorCells(c, generic<double>(), generic<float>(), true)));
  }
  print(t);
}

void rodSweep() {
  Table t;
  t.title = "Nearly singular inertias: rods";
  t.text = std::string(kMetric) +
           " Every link a rod of thickness/length d: its moment about its own axis is "
           "2 d^2 of the others (0: an ideal rod, that moment exactly zero). 10-joint chains "
           "and 20-joint trees, 40 models of each, 10 states each.";
  t.header = header("d (moment ratio 2 d^2)");
  for (double d : {1.0, 1e-2, 1e-4, 1e-6, 1e-8, -1.0}) {
    jle_test::PrecisionComparison<Quad> c;
    for (bool tree : {false, true}) {
      RandomModelSpec spec;
      spec.joints = tree ? 20 : 10;
      spec.tree = tree;
      spec.rod = d;
      c.merge(sweepPoint(spec, quick ? 3 : 40, quick ? 2 : 10, 1.0, 5.0));
    }
    t.rows.push_back(row(d < 0 ? "0 (ideal rod)" : sci(d),
                         errorCells(c, generic<double>(), generic<float>(), true)));
  }
  print(t);
}

void velocitySweep() {
  Table t;
  t.title = "Angular velocity";
  t.text = std::string(kMetric) +
           " Joint velocities uniform in [-w, w] (the links' angular velocities reach a few "
           "w), qdd in [-5, 5] rad/s^2: above w ~ 10 rad/s the centripetal and gyroscopic "
           "terms dominate gravity. 6-joint chains and 12-joint trees, 40 models of each, 10 "
           "states each.";
  t.header = header("w [rad/s]");
  for (double w : {0.0, 1.0, 10.0, 100.0, 1e3}) {
    jle_test::PrecisionComparison<Quad> c;
    for (bool tree : {false, true}) {
      RandomModelSpec spec;
      spec.joints = tree ? 12 : 6;
      spec.tree = tree;
      c.merge(sweepPoint(spec, quick ? 3 : 40, quick ? 2 : 10, w, 5.0));
    }
    t.rows.push_back(row(sci(w), errorCells(c, generic<double>(), generic<float>(), true)));
  }
  print(t);
}

// Adds world-frame wrenches at the tip and at a middle link, of the size of the weights.
void addWorldWrenches(const jle::Model<double>& model, jle_test::Random& rng, Scene& scene) {
  for (int frame :
       {static_cast<int>(model.frames.size()) - 1, static_cast<int>(model.frames.size()) / 2}) {
    jle_test::AppliedWrench w;
    w.frame = frame;
    w.force = 20.0 * rng.unitVector();
    w.moment = 5.0 * rng.unitVector();
    w.expressed_in = jle::WrenchFrame::kWorld;
    scene.wrenches.push_back(w);
  }
}

// Errors of the literal world-frame formulation, in S, against the core in Quad.
template <typename S>
Error literalError(const jle::Model<double>& model, const Scene& scene, Precisions<Quad>& p) {
  const jle::Model<S> ms = model.cast<S>();
  jle::Data<S> ds(ms);
  const jle_bench::LiteralLoads<S> l = jle_bench::literalWorldFrameLoads(ms, ds, scene);
  jle_test::computeLoads(p.r, p.data_r, scene);
  return jle_test::relativeError<Quad>(model.moving_segments, l.force, l.moment, p.data_r.force,
                                       p.data_r.moment);
}

struct FormulationComparison {
  jle_test::PrecisionComparison<Quad> core;
  Error literal_double, literal_float;
};

using SceneHook = std::function<void(const jle::Model<double>&, jle_test::Random&, Scene&)>;

/// Both formulations over `models` random models (seeds 2000, 2001, ...) and `states`
/// random states of each, the scene changed by `hook`.
FormulationComparison compareFormulations(RandomModelSpec spec, int models, int states,
                                          const SceneHook& hook) {
  FormulationComparison out;
  for (int k = 0; k < models; ++k) {
    spec.seed = static_cast<std::uint32_t>(2000 + k);
    const jle::Model<double> model = jle::modelFromUrdfString(jle_test::randomUrdf(spec));
    Precisions<Quad> p(model);
    jle_test::Random rng(spec.seed);
    for (int s = 0; s < states; ++s) {
      Scene scene;
      scene.state = jle_test::randomState(model, rng, 1.0, 5.0, spec.length);
      hook(model, rng, scene);
      out.core.merge(p.compare(scene));
      out.literal_double.merge(literalError<double>(model, scene, p));
      out.literal_float.merge(literalError<float>(model, scene, p));
    }
  }
  return out;
}

const std::vector<std::string> kFormulationHeader = {
    "core double: wrench",    "moment",
    "literal double: wrench", "moment",
    "core float: wrench",     "moment",
    "literal float: wrench",  "moment",
    "bound double (core)",    "bound float (core)"};

std::vector<std::string> formulationCells(const FormulationComparison& c, double bd, double bf) {
  return {checked(c.core.of_double.wrench, bd),
          checked(c.core.of_double.moment, bd),
          sci(c.literal_double.wrench),
          sci(c.literal_double.moment),
          checked(c.core.of_float.wrench, bf),
          checked(c.core.of_float.moment, bf),
          sci(c.literal_float.wrench),
          sci(c.literal_float.moment),
          sci(bd),
          sci(bf)};
}

void tinyInertiaTable() {
  Table t;
  t.title = "Tiny inertias on a planar chain (Model::analyze's gyroscopic skip)";
  t.text = std::string(kMetric) +
           " A planar 3-joint chain (every axis along z, fixed base), each link of mass "
           "10 s kg and inertia s [[2, 0, 0.4], [0, 2, 0], [0.4, 0, 3]] kg m^2 (z is not a "
           "principal axis, so omega x J omega is not zero), qd = 10 rad/s. The reference "
           "computes every term; double and float use the model as the reader builds it, "
           "whose analyze() skips the gyroscopic term of a link only when "
           "|J d x d| <= 64 eps |J d| (relative: any scale), so every row must keep it for "
           "all three links and stay within the generic bounds.";
  t.header = header("s");
  t.header.push_back("gyroscopic term kept");
  for (double scale : {1.0, 1e-6, 1e-12, 1e-13, 1e-14, 1e-15}) {
    std::string xml =
        "<robot name=\"planar\"><link name=\"link0\"><inertial><mass value=\"1\"/>"
        "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>"
        "</inertial></link>";
    for (int k = 1; k <= 3; ++k) {
      char link[600];
      std::snprintf(
          link, sizeof link,
          "<link name=\"link%d\"><inertial><origin xyz=\"0.1 0 0\"/><mass value=\"%.17g\"/>"
          "<inertia ixx=\"%.17g\" ixy=\"0\" ixz=\"%.17g\" iyy=\"%.17g\" iyz=\"0\" izz=\"%.17g\"/>"
          "</inertial></link><joint name=\"j%d\" type=\"continuous\"><parent link=\"link%d\"/>"
          "<child link=\"link%d\"/><origin xyz=\"%s 0 0\"/><axis xyz=\"0 0 1\"/></joint>",
          k, 10.0 * scale, 2.0 * scale, 0.4 * scale, 2.0 * scale, 3.0 * scale, k, k - 1, k,
          k == 1 ? "0" : "0.2");
      xml += link;
    }
    xml += "</robot>";
    const jle::Model<double> model = jle::modelFromUrdfString(xml);
    Precisions<Quad> p(model);
    jle_test::PrecisionComparison<Quad> c;
    jle_test::Random rng(5);
    for (int s = 0; s < 10; ++s) {
      Scene scene;
      scene.state = jle_test::randomState(model, rng, 10.0, 5.0);
      scene.state.qd.setConstant(10.0);
      c.merge(p.compare(scene));
    }
    int kept = 0;
    for (int i = 1; i < model.nsegments(); ++i) kept += model.gyroscopic[i];
    findings.tiny_inertia = std::max(findings.tiny_inertia, c.of_double.wrench);
    findings.tiny_kept_links += kept;
    findings.tiny_links += model.nsegments() - 1;
    if (kept != model.nsegments() - 1) ++violations;
    std::vector<std::string> cells =
        errorCells(c, bounds::generic<double>(), bounds::generic<float>(), true);
    cells.push_back(std::to_string(kept) + " of 3 links");
    t.rows.push_back(row(sci(scale), cells));
  }
  print(t);
}

// The effort of a link whose centre of mass lies D out along its own joint axis
// (test/support/jle_testing/far_com.hpp) against its closed form, which does not depend on D.
void farComSweep() {
  Table t;
  t.title = "Centre of mass far along the joint axis";
  t.text =
      "Relative error of the effort of joint j2 of test/support/jle_testing/far_com.hpp (link2's "
      "centre of "
      "mass D along j2's axis; j1 across it gives omega and alpha components off the axis) "
      "against its closed form in long double from the URDF's numbers, "
      "Izz alpha_z + (Iyy - Ixx) omega_x omega_y, which does not depend on D. The reader "
      "combines a segment's inertials about their common centre of mass: a round trip "
      "through the segment origin (m D^2 added to Ixx and taken away) cost 1.5e-10 at "
      "1e3 m and 3e-5 at 1e5 m. Bound: 1e-13 (test_stability).";
  t.header = {"D [m]", "double: effort", "bound"};
  const jle_test::FarComState state;
  const double exact = static_cast<double>(jle_test::farComEffort(state));
  for (double D : {1.0, 1e1, 1e2, 1e3, 1e4, 1e5}) {
    const jle::Model<double> model = jle::modelFromUrdfString(jle_test::farComUrdf(D));
    jle::Data<double> data(model);
    Eigen::VectorXd q(2), qd(2), qdd(2);
    q << state.q[0], state.q[1];
    qd << state.qd[0], state.qd[1];
    qdd << state.qdd[0], state.qdd[1];
    jle::rnea(model, data, q, qd, qdd, Eigen::Vector3d(0, 0, -9.81));
    const double err =
        std::abs(data.effort[static_cast<std::size_t>(model.nsegments() - 1)] - exact) /
        std::abs(exact);
    findings.far_com = std::max(findings.far_com, err);
    findings.far_com_max_distance = D;
    t.rows.push_back({sci(D), checked(err, 1e-13), sci(1e-13)});
  }
  print(t);
}

void worldOffsetSweep() {
  Table t;
  t.title = "World offset: base far from the world origin, world-frame external wrenches";
  t.text =
      "The base placed at distance D from the world origin (BaseState::p_world_base, along a "
      "random direction, with a random orientation) and two wrenches given in the world "
      "frame (addExternalWrench kWorld, 20 N and 5 N m, at the tip and a middle link). "
      "Relative error of the joint wrenches (6-vector) and of the moments alone, worst "
      "joint, against the core in quad precision. *core*: this package (segment frames, moments "
      "about the joint: no "
      "world position enters the backward pass). *literal*: the paper's formulation "
      "verbatim (bench/stability_literal.hpp: world coordinates, moments about x_G, lever "
      "arms xi = x - x_G from world positions), the same kinematics. 8-joint chains and "
      "16-joint trees, 20 models of each, 10 states each.";
  t.header = {"D [m]"};
  t.header.insert(t.header.end(), kFormulationHeader.begin(), kFormulationHeader.end());
  for (double D : {0.0, 1.0, 1e2, 1e3, 1e4, 1e5, 1e6}) {
    FormulationComparison c;
    for (bool tree : {false, true}) {
      RandomModelSpec spec;
      spec.joints = tree ? 16 : 8;
      spec.tree = tree;
      const FormulationComparison ci = compareFormulations(
          spec, quick ? 2 : 20, quick ? 2 : 10,
          [D](const jle::Model<double>& model, jle_test::Random& rng, Scene& scene) {
            scene.base.p_world_base = D * rng.unitVector();
            scene.base.R_world_base =
                Eigen::AngleAxisd(rng.uniform(-M_PI, M_PI), rng.unitVector()).toRotationMatrix();
            addWorldWrenches(model, rng, scene);
          });
      c.core.merge(ci.core);
      c.literal_double.merge(ci.literal_double);
      c.literal_float.merge(ci.literal_float);
    }
    t.rows.push_back({sci(D)});
    const auto cells = formulationCells(c, generic<double>(), generic<float>());
    t.rows.back().insert(t.rows.back().end(), cells.begin(), cells.end());
  }
  print(t);
}

void linkLengthSweep() {
  Table t;
  t.title = "Link length: tiny and huge links";
  t.text = std::string(kMetric) +
           " Distances between joints uniform in [0.5, 1] L; link sizes, centres of mass "
           "and inertias scale with L. The base is 1 m from the world origin (a robot on a "
           "table), which only the literal formulation feels. 8-joint chains and 16-joint "
           "trees, 20 models of each, 10 states each.";
  t.header = header("L [m]");
  t.header.insert(t.header.end(),
                  {"literal double: wrench", "moment", "literal float: wrench", "moment"});
  for (double L : {1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0}) {
    FormulationComparison c;
    for (bool tree : {false, true}) {
      RandomModelSpec spec;
      spec.joints = tree ? 16 : 8;
      spec.tree = tree;
      spec.length = L;
      const FormulationComparison ci =
          compareFormulations(spec, quick ? 2 : 20, quick ? 2 : 10,
                              [](const jle::Model<double>&, jle_test::Random&, Scene& scene) {
                                scene.base.p_world_base = Eigen::Vector3d(0.6, -0.8, 0.0);
                              });
      c.core.merge(ci.core);
      c.literal_double.merge(ci.literal_double);
      c.literal_float.merge(ci.literal_float);
    }
    std::vector<std::string> cells = errorCells(c.core, generic<double>(), generic<float>(), true);
    cells.push_back(sci(c.literal_double.wrench));
    cells.push_back(sci(c.literal_double.moment));
    cells.push_back(sci(c.literal_float.wrench));
    cells.push_back(sci(c.literal_float.moment));
    t.rows.push_back(row(sci(L), cells));
  }
  print(t);
}

void singularSweep() {
  Table t;
  t.title = "Singular configurations";
  t.text = std::string(kMetric) +
           " Public arms at and near their kinematic singularities (inverse dynamics has no "
           "singularity: nothing is inverted; these rows check that nothing cancels). "
           "*static*: qd = qdd = 0 (gravity only); *moving*: 20 random qd in [-1, 1] rad/s, "
           "qdd in [-5, 5] rad/s^2 at the same q.";
  t.header = header("configuration");
  struct Config {
    std::string name, file;
    std::vector<double> q;
  };
  const double h = M_PI / 2;
  std::vector<Config> configs = {
      {"UR5 stretched horizontally (q = 0)", "ur5_chain.urdf", {0, 0, 0, 0, 0, 0}},
      {"UR5 stretched upwards", "ur5_chain.urdf", {0, -h, 0, -h, 0, 0}},
      {"UR5 wrist singularity (q5 = 0)", "ur5_chain.urdf", {0.3, -1.1, 1.4, -0.7, 0.0, 0.9}},
      {"UR5 wrist singularity + 1e-8", "ur5_chain.urdf", {0.3, -1.1, 1.4, -0.7, 1e-8, 0.9}},
      {"UR5 wrist singularity + 1e-4", "ur5_chain.urdf", {0.3, -1.1, 1.4, -0.7, 1e-4, 0.9}},
      {"Panda stretched upwards (q = 0)", "panda_chain.urdf", {0, 0, 0, 0, 0, 0, 0}},
      {"Panda elbow stretched (q4 = 0)", "panda_chain.urdf", {0.2, 0.5, -0.3, 0, 0.4, 1.2, 0.1}},
      {"Kinova stretched (q = 0)", "kinova_chain.urdf", {}},
  };
  for (const Config& cfg : configs) {
    const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/chains/" + cfg.file);
    Precisions<Quad> p(model);
    for (bool moving : {false, true}) {
      jle_test::PrecisionComparison<Quad> c;
      jle_test::Random rng(7);
      for (int s = 0; s < (moving ? 20 : 1); ++s) {
        Scene scene;
        scene.state.q = Eigen::VectorXd::Zero(model.nq);
        if (!cfg.q.empty()) scene.state.q = Eigen::VectorXd::Map(cfg.q.data(), model.nq);
        scene.state.qd = Eigen::VectorXd::Zero(model.nq);
        scene.state.qdd = Eigen::VectorXd::Zero(model.nq);
        if (moving)
          for (int k = 0; k < model.nq; ++k) {
            scene.state.qd[k] = rng.uniform(-1.0, 1.0);
            scene.state.qdd[k] = rng.uniform(-5.0, 5.0);
          }
        c.merge(p.compare(scene));
      }
      t.rows.push_back(row(cfg.name + (moving ? ", moving" : ", static"),
                           errorCells(c, generic<double>(), generic<float>(), false)));
    }
  }
  print(t);
}

// ---------------------------------------------------------------------------------------
// Filter sweeps

using jle::DifferentiatorBank;
using jle::DifferentiatorConfig;
using jle::DifferentiatorType;
using QuadMatrix = Eigen::Matrix<Quad, Eigen::Dynamic, Eigen::Dynamic>;

struct NamedFilter {
  std::string name;
  DifferentiatorConfig config;
};

DifferentiatorConfig finiteDifference(int order) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kFiniteDifference;
  c.order = order;
  return c;
}

DifferentiatorConfig savitzkyGolay(int window, int order, int delay) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kSavitzkyGolay;
  c.window = window;
  c.order = order;
  c.delay = delay;
  return c;
}

DifferentiatorConfig kalman(jle::KalmanModel model) {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kKalman;
  c.kalman_model = model;
  c.process_noise = 1e3;
  return c;
}

/// Second-derivative weights of the least-squares polynomial of `order` through the
/// window `t` (oldest first) at `stamp`, in quad precision (normal equations: their
/// conditioning, squared, is far inside quad's 34 digits here).
std::vector<Quad> quadWeights(const std::vector<double>& t, int order, double stamp) {
  const int w = static_cast<int>(t.size()), n = order + 1;
  const Quad mid = (Quad(t.front()) + Quad(t.back())) / Quad(2);
  const Quad half = (Quad(t.back()) - Quad(t.front())) / Quad(2);
  QuadMatrix V(w, n);
  for (int k = 0; k < w; ++k) {
    const Quad tau = (Quad(t[k]) - mid) / half;
    Quad p(1);
    for (int j = 0; j < n; ++j, p *= tau) V(k, j) = p;
  }
  const QuadMatrix G = V.transpose() * V;
  const QuadMatrix pinv = G.inverse() * V.transpose();
  const Quad te = (Quad(stamp) - mid) / half;
  std::vector<Quad> c(static_cast<std::size_t>(w), Quad(0));
  for (int j = 2; j < n; ++j) {
    Quad p(j * (j - 1));
    for (int i = 0; i < j - 2; ++i) p *= te;
    for (int k = 0; k < w; ++k) c[k] += p * pinv(j, k) / (half * half);
  }
  return c;
}

/// The weights by the normal equations, for comparison with the bank's QR: normal
/// equations V^T V solved by LDLT.
std::vector<double> normalEquationWeights(const std::vector<double>& t, int order, double stamp) {
  using Matrix = Eigen::MatrixXd;
  const int w = static_cast<int>(t.size()), n = order + 1;
  const double mid = 0.5 * (t.back() + t.front()), half = 0.5 * (t.back() - t.front());
  Matrix V(w, n);
  for (int k = 0; k < w; ++k) {
    const double tau = (t[k] - mid) / half;
    double p = 1.0;
    for (int j = 0; j < n; ++j, p *= tau) V(k, j) = p;
  }
  const Matrix gram = V.transpose() * V;
  const Eigen::LDLT<Matrix> ldlt(gram);
  const Matrix pinv = ldlt.solve(V.transpose());
  const double te = (stamp - mid) / half;
  Eigen::RowVectorXd e = Eigen::RowVectorXd::Zero(n);
  for (int j = 2; j < n; ++j) e[j] = j * (j - 1) * std::pow(te, j - 2);
  const Eigen::RowVectorXd c = e * pinv / (half * half);
  return std::vector<double>(c.data(), c.data() + w);
}

void shortIntervalSweep() {
  Table t;
  t.title = "Irregular sampling: one short interval among 1 ms ones";
  t.text =
      "A quadratic q(t) = 0.3 + 0.5 t + 0.7 t^2 rad sampled every 1 ms, except that every "
      "10th interval lasts d (two nearly simultaneous samples, as a driver that stamps "
      "partial messages can produce). Error of qdd over 400 samples against the same fit "
      "computed in quad precision from the same (double) samples, divided by the error "
      "that rounding the samples alone causes (eps sum |c_k q_k|, c the exact weights): 1 "
      "is as accurate as the inputs allow. *normal equations*: the weights by the normal "
      "equations (LDLT of V^T V), for comparison; *QR*: the bank (Householder QR of "
      "V). *inherent, 3-point*: the error of the 3-point difference that the samples' "
      "rounding causes, in rad/s^2 (a short interval amplifies it whatever the method). "
      "*Kalman*: the worst |qdd - 1.4| [rad/s^2] of the constant-acceleration and "
      "constant-jerk filters after their first 200 samples (the quadratic is in both "
      "models, so there is no bias to hide a loss): a short interval does not disturb them.";
  const std::vector<NamedFilter> filters = {{"3-point", finiteDifference(2)},
                                            {"4-point", finiteDifference(3)},
                                            {"SG 9/2", savitzkyGolay(9, 2, 0)},
                                            {"SG 7/5 centred", savitzkyGolay(7, 5, 3)}};
  t.header = {"d [s]"};
  for (const NamedFilter& f : filters) {
    t.header.push_back(f.name + " normal equations");
    t.header.push_back("QR");
  }
  t.header.push_back("inherent, 3-point [rad/s^2]");
  t.header.push_back("bound after");
  t.header.push_back("Kalman CA");
  t.header.push_back("Kalman CJ");
  for (double d : {1e-3, 1e-4, 1e-6, 1e-8, 1e-10}) {
    std::vector<std::string> r{sci(d)};
    double inherent_fd = 0.0;
    for (const NamedFilter& f : filters) {
      DifferentiatorBank bank(f.config, 1);
      const int w = bank.config().window, order = bank.config().order;
      std::vector<double> times, values;
      double before = 0.0, after = 0.0, t_now = 2.0;
      for (int k = 0; k < 400; ++k) {
        const double tau = t_now - 2.0;
        const double x = 0.3 + 0.5 * tau + 0.7 * tau * tau;
        times.push_back(t_now);
        values.push_back(x);
        if (bank.update(t_now, &x)) {
          const std::vector<double> tw(times.end() - w, times.end());
          const std::vector<double> xw(values.end() - w, values.end());
          const std::vector<Quad> c = quadWeights(tw, order, bank.stamp());
          const std::vector<double> c_old = normalEquationWeights(tw, order, bank.stamp());
          Quad exact(0), scale(0);
          double old = 0.0;
          for (int i = 0; i < w; ++i) {
            exact += c[i] * Quad(xw[i]);
            scale += abs(c[i] * Quad(xw[i]));
            old += c_old[i] * xw[i];
          }
          const double inherent = std::numeric_limits<double>::epsilon() * double(scale);
          before = std::max(before, std::abs(old - double(exact)) / inherent);
          after = std::max(after, std::abs(bank.accel(0) - double(exact)) / inherent);
          if (f.name == "3-point") inherent_fd = std::max(inherent_fd, inherent);
        }
        t_now += k % 10 == 5 ? d : 1e-3;
      }
      r.push_back(sci(before));
      r.push_back(checked(after, bounds::kWeightsRatio));
    }
    r.push_back(sci(inherent_fd));
    r.push_back(sci(bounds::kWeightsRatio));
    for (jle::KalmanModel m :
         {jle::KalmanModel::kConstantAcceleration, jle::KalmanModel::kConstantJerk}) {
      DifferentiatorBank bank(kalman(m), 1);
      double worst = 0.0, t_now = 2.0;
      for (int k = 0; k < 400; ++k) {
        const double tau = t_now - 2.0;
        const double x = 0.3 + 0.5 * tau + 0.7 * tau * tau;
        if (bank.update(t_now, &x) && k >= 200)
          worst = std::max(worst, std::abs(bank.accel(0) - 1.4));
        t_now += k % 10 == 5 ? d : 1e-3;
      }
      r.push_back(sci(worst));
    }
    t.rows.push_back(r);
  }
  print(t);
}

/// sin(2 pi f tau) and its second derivative, evaluated in long double.
struct Sine {
  long double f = 1.0L;
  double value(long double tau) const { return static_cast<double>(sinl(2.0L * M_PIl * f * tau)); }
  double accel(long double tau) const {
    const long double w = 2.0L * M_PIl * f;
    return static_cast<double>(-w * w * sinl(w * tau));
  }
};

void epochSweep() {
  Table t;
  t.title = "Absolute time: stamps around the Unix epoch";
  t.text =
      "The same signal (sin 2 pi t, 1 rad, 1 kHz, 10 s) fed with stamps T0 + t: the double "
      "a caller holding absolute seconds passes (rounded to the spacing of doubles at T0, "
      "the 'stamp quantum'). Cells: the largest change of qdd [rad/s^2] against the run at "
      "T0 = 0 (the signal is sampled at the true instants; only the stamps differ). "
      "*exact stamps*: the same with a spacing of 2^-10 s, which doubles at 1.8e9 still "
      "represent exactly: the filters' arithmetic loses nothing at any T0, the loss is the "
      "stamps' rounding before the filter sees them, which no change inside the bank can "
      "undo (subtracting a reference stamp inside the bank is exact at these magnitudes and "
      "keeps the rounded stamps). *node "
      "path*: stamps made relative to the first one in integer nanoseconds before the "
      "conversion to double, as EstimatorNode::relative() does. The filters' own errors at "
      "T0 = 0 (truncation and lag), for scale: ";
  const std::vector<NamedFilter> filters = {
      {"3-point", finiteDifference(2)},
      {"SG 9/2 centred", savitzkyGolay(9, 2, 4)},
      {"Kalman CA", kalman(jle::KalmanModel::kConstantAcceleration)},
      {"Kalman CJ", kalman(jle::KalmanModel::kConstantJerk)}};
  const Sine sine;
  const int samples = 10000;
  // Runs a filter over the samples with the stamps given; returns qdd per sample (NaN
  // while warming up).
  auto run = [&](const DifferentiatorConfig& c, const std::function<double(int)>& stamp,
                 const std::function<long double(int)>& tau) {
    DifferentiatorBank bank(c, 1);
    std::vector<double> out(samples, std::nan(""));
    std::vector<long double> when(samples, 0.0L);
    for (int k = 0; k < samples; ++k) {
      const double x = sine.value(tau(k));
      if (bank.update(stamp(k), &x)) {
        out[k] = bank.accel(0);
        when[k] = tau(k - bank.config().delay);
      }
    }
    return std::make_pair(out, when);
  };
  auto deviation = [&](const std::vector<double>& a, const std::vector<double>& b) {
    double worst = 0.0;
    for (int k = 1000; k < samples; ++k) worst = std::max(worst, std::abs(a[k] - b[k]));
    return worst;
  };
  for (const NamedFilter& f : filters) {
    const auto base = run(
        f.config, [](int k) { return k * 1e-3; }, [](int k) { return k * 1e-3L; });
    double own = 0.0;
    for (int k = 1000; k < samples; ++k)
      own = std::max(own, std::abs(base.first[k] - sine.accel(base.second[k])));
    t.text += f.name + " " + sci(own) + (&f == &filters.back() ? "." : ", ");
  }
  t.header = {"T0 [s]", "stamp quantum [s]"};
  for (const NamedFilter& f : filters) t.header.push_back(f.name);
  t.header.push_back("exact stamps (all)");
  t.header.push_back("node path (all)");
  t.header.push_back("bound, exact stamps");
  for (double T0 : {0.0, 1e3, 1e6, 1.8e9}) {
    std::vector<std::string> r{sci(T0), sci(T0 == 0.0 ? 0.0 : std::nextafter(T0, 1e300) - T0)};
    double exact_dev = 0.0, node_dev = 0.0;
    for (const NamedFilter& f : filters) {
      const auto base = run(
          f.config, [](int k) { return k * 1e-3; }, [](int k) { return k * 1e-3L; });
      const auto shifted = run(
          f.config, [T0](int k) { return T0 + k * 1e-3; }, [](int k) { return k * 1e-3L; });
      r.push_back(sci(deviation(shifted.first, base.first)));
      const double q = 1.0 / 1024.0;
      const auto exact0 = run(
          f.config, [q](int k) { return k * q; },
          [q](int k) { return static_cast<long double>(k * q); });
      const auto exact = run(
          f.config, [T0, q](int k) { return T0 + k * q; },
          [q](int k) { return static_cast<long double>(k * q); });
      exact_dev = std::max(exact_dev, deviation(exact.first, exact0.first));
      // ros::Time arithmetic: whole seconds and nanoseconds, subtracted as integers.
      const auto node = run(
          f.config,
          [](int k) {
            const long long ns = 1000000LL * k;
            return static_cast<double>(ns / 1000000000LL) +
                   static_cast<double>(ns % 1000000000LL) * 1e-9;
          },
          [](int k) { return k * 1e-3L; });
      node_dev = std::max(node_dev, deviation(node.first, base.first));
    }
    r.push_back(checked(exact_dev, bounds::kEpochExactStamps));
    r.push_back(sci(node_dev));
    r.push_back(sci(bounds::kEpochExactStamps));
    t.rows.push_back(r);
  }
  print(t);
}

/// How far the weight reuse of the bank (differentiation.hpp: weights kept while every
/// sample stays within bounds::kWeightsReuseSpacing of where the last fit had it) may
/// move qdd of sin(2 pi t) at 1 ms spacing: each sample may be taken up to that far from
/// where it is, which moves qdd by at most sum |c_k| |x'| kWeightsReuseSpacing; twice
/// that between two banks.
double reuseBound(const DifferentiatorConfig& config) {
  DifferentiatorBank bank(config, 1);
  const int w = bank.config().window, order = bank.config().order;
  std::vector<double> t;
  for (int k = 0; k < w; ++k) t.push_back(1e-3 * k);
  double sum = 0.0;
  for (const Quad& c : quadWeights(t, order, t[w - 1 - bank.config().delay])) sum += double(abs(c));
  return 2.0 * sum * 2.0 * M_PI * bounds::kWeightsReuseSpacing;
}

void longRunSweep() {
  const long samples = quick ? 200000 : 10000000;
  const long window = 100000;
  Table t;
  t.title = "Long runs: " + sci(static_cast<double>(samples)) + " samples";
  t.text = "sin(2 pi t) rad sampled " + sci(static_cast<double>(samples)) + " times (t up to " +
           sci(samples * 1e-3) +
           " s): every 2^-10 s (exact doubles), every 1 ms (t = k 1e-3 rounded to double), or "
           "at intervals of 1 ms +-40% (fixed seed). *early*, *late*: worst |qdd error| "
           "[rad/s^2] against the exact second derivative at the estimate's stamp, over samples "
           "1e4 .. 1.1e5 and over the last 1e5; the signal is periodic, so a filter that does "
           "not drift has the same worst error in both. *late vs fresh bank*: the largest "
           "|qdd - qdd_fresh| / (1 + |qdd_fresh|) over the last 1e5 samples, against a bank "
           "started 2e5 samples before the end (a window filter must agree at once, a Kalman "
           "filter once its start is forgotten, ~20 samples): the long-running state holds no "
           "accumulated error. Its bound is 1e-11 but at a rounded 1 ms spacing, where the "
           "bank reuses what it computed for the last samples while they stay within 0.1 ns of "
           "where they were (a window filter's weights; the Kalman filter's F and Q, while dt "
           "stays within 0.1 ns): two banks that computed them at different times may then "
           "differ by the effect of moving every sample by 0.2 ns (window filters), or of "
           "rescaling time by 2e-10 s / 1 ms, which moves qdd by twice that relatively "
           "(Kalman filters). *finite*: every output was finite.";
  t.header = {"filter",       "sampling",           "early",  "late",
              "late / early", "late vs fresh bank", "finite", "bounds"};
  const std::vector<NamedFilter> filters = {
      {"3-point", finiteDifference(2)},
      {"SG 9/2", savitzkyGolay(9, 2, 0)},
      {"SG 11/3 centred", savitzkyGolay(11, 3, 5)},
      {"Kalman CA", kalman(jle::KalmanModel::kConstantAcceleration)},
      {"Kalman CJ", kalman(jle::KalmanModel::kConstantJerk)}};
  const Sine sine;
  const char* kSampling[] = {"2^-10 s", "1 ms", "1 ms +-40%"};
  for (const NamedFilter& f : filters)
    for (int sampling = 0; sampling < 3; ++sampling) {
      DifferentiatorBank bank(f.config, 1);
      DifferentiatorBank fresh(f.config, 1);
      jle_test::Random rng(11);
      double early = 0.0, late = 0.0, vs_fresh = 0.0;
      bool finite = true;
      long double t_now = 0.0L;
      for (long k = 0; k < samples; ++k) {
        const double stamp = sampling == 0 ? k / 1024.0 : static_cast<double>(t_now);
        const double x = sine.value(stamp);  // the stamp is the truth here: nothing to model
        const bool ready = bank.update(stamp, &x);
        const bool fresh_ready = k >= samples - 2 * window && fresh.update(stamp, &x);
        if (ready) {
          const double e = std::abs(bank.accel(0) - sine.accel(bank.stamp()));
          finite = finite && std::isfinite(bank.value(0)) && std::isfinite(bank.rate(0)) &&
                   std::isfinite(bank.accel(0));
          if (k >= 10000 && k < 10000 + window) early = std::max(early, e);
          if (k >= samples - window) {
            late = std::max(late, e);
            if (fresh_ready)
              vs_fresh = std::max(vs_fresh, std::abs(bank.accel(0) - fresh.accel(0)) /
                                                (1.0 + std::abs(fresh.accel(0))));
          }
        }
        t_now += sampling == 2 ? 1e-3L * rng.uniform(0.6, 1.4) : 1e-3L;
      }
      const double ratio = late / early;
      double fresh_bound = bounds::kLongRunFresh;
      if (sampling == 1)
        fresh_bound = f.config.type == DifferentiatorType::kKalman ? bounds::kalmanReuseBound(1e-3)
                                                                   : reuseBound(f.config);
      if (ratio > bounds::kLongRunDrift || !finite) ++violations;
      t.rows.push_back({f.name, kSampling[sampling], sci(early), sci(late),
                        fixed(ratio, 4) + (ratio > bounds::kLongRunDrift ? " **OVER**" : ""),
                        checked(vs_fresh, fresh_bound), finite ? "yes" : "**NO**",
                        fixed(bounds::kLongRunDrift, 2) + ", " + sci(fresh_bound)});
      std::cerr << "long run " << f.name << " " << kSampling[sampling] << " done" << std::endl;
    }
  print(t);
}

/// A UR5 fed q(t) = a + b t + c t^2 per joint at 1 kHz, with one event at sample 100.
struct EventRun {
  std::vector<jle::SampleStatus> status;   // per fed sample
  std::vector<double> stamp, qdd, effort;  // per published sample, in order
  std::vector<int> index;                  // per published sample: the fed sample's index
};

EventRun runEstimator(const jle::Model<double>& model, const DifferentiatorConfig& c,
                      const std::vector<double>& times, bool reset_at_jump = false) {
  jle::EstimatorConfig config;
  config.differentiator = c;
  jle::Estimator estimator(model, config);
  EventRun out;
  double last = -1e300;
  for (std::size_t k = 0; k < times.size(); ++k) {
    const double t = times[k];
    if (reset_at_jump && t < last - 1.0) estimator.reset();  // the node's time_jump_threshold
    last = t;
    Eigen::VectorXd q(model.nq);
    const double tau = std::fmod(t, 100.0);
    for (int i = 0; i < model.nq; ++i)
      q[i] = 0.1 * i - 0.3 + 0.5 * tau + 0.7 * std::cos(i) * tau * tau;
    const jle::SampleStatus st = estimator.addJointSample(t, q.data());
    out.status.push_back(st);
    if (st == jle::SampleStatus::kPublished) {
      out.index.push_back(static_cast<int>(k));
      out.stamp.push_back(estimator.last().stamp());
      out.qdd.push_back(estimator.last().qdd()[1]);
      out.effort.push_back(estimator.last().data().effort[model.moving_segments[1]]);
    }
  }
  return out;
}

void eventsTable() {
  Table t;
  t.title = "Stamp events: duplicate, backwards, gap, jump back";
  t.text =
      "A UR5 (Estimator, default settings but the filter) fed a quadratic per joint at 1 "
      "kHz, with one event at sample 100. *bank*: what DifferentiatorBank::update does "
      "with the event's stamp; *estimator*: the SampleStatus of the event's sample; "
      "*after*: the largest difference of the published qdd and efforts from those of the "
      "reference run (without the event for a dropped sample; a fresh estimator started "
      "at the resumed stream for a restart), over every sample published after the "
      "event. 0 means identical to the last bit.";
  t.header = {"event",     "filter",          "bank",
              "estimator", "published after", "after: largest change of qdd, of effort"};
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf");
  const std::vector<NamedFilter> filters = {
      {"3-point", finiteDifference(2)},
      {"SG 9/2 centred", savitzkyGolay(9, 2, 4)},
      {"Kalman CA", kalman(jle::KalmanModel::kConstantAcceleration)}};
  std::vector<double> regular;
  for (int k = 0; k < 300; ++k) regular.push_back(1.0 + 1e-3 * k);
  struct Event {
    std::string name;
    std::vector<double> times;      // what is fed
    std::vector<double> reference;  // what the outputs after the event must equal
    bool reset;
  };
  std::vector<Event> events;
  {
    Event e{"duplicate stamp (dt = 0)", regular, regular, false};
    e.times.insert(e.times.begin() + 100, regular[99]);
    events.push_back(e);
  }
  {
    Event e{"backwards stamp (-0.5 ms)", regular, regular, false};
    e.times.insert(e.times.begin() + 100, regular[99] - 5e-4);
    events.push_back(e);
  }
  {
    Event e{"gap of 5 s (max_gap 0.5 s)", regular, {}, false};
    for (std::size_t k = 100; k < e.times.size(); ++k) e.times[k] += 5.0;
    e.reference.assign(e.times.begin() + 100, e.times.end());
    events.push_back(e);
  }
  {
    Event e{"jump back by 10 s, reset()", regular, {}, true};
    for (std::size_t k = 100; k < e.times.size(); ++k) e.times[k] -= 10.0;
    e.reference.assign(e.times.begin() + 100, e.times.end());
    events.push_back(e);
  }
  for (const Event& ev : events)
    for (const NamedFilter& f : filters) {
      std::string bank_result;
      {
        DifferentiatorBank bank(f.config, 1);
        const double x = 0.0;
        try {
          for (int k = 0; k <= 100; ++k) bank.update(ev.times[k], &x);
          bank_result =
              ev.times[100] > ev.times[99] + bank.config().max_gap ? "restarts" : "accepts";
        } catch (const std::invalid_argument&) {
          bank_result = "throws invalid_argument";
        }
      }
      const EventRun run = runEstimator(model, f.config, ev.times, ev.reset);
      const EventRun ref = runEstimator(model, f.config, ev.reference);
      // Compare the outputs published at the same stamps after the event.
      double dq = 0.0, de = 0.0;
      int matched = 0, after = 0;
      for (std::size_t i = 0; i < run.stamp.size(); ++i) {
        if (run.index[i] < 100) continue;
        ++after;
        for (std::size_t j = 0; j < ref.stamp.size(); ++j)
          if (ref.stamp[j] == run.stamp[i]) {
            dq = std::max(dq, std::abs(run.qdd[i] - ref.qdd[j]));
            de = std::max(de, std::abs(run.effort[i] - ref.effort[j]));
            ++matched;
            break;
          }
      }
      if (matched != after) ++violations;
      t.rows.push_back({ev.name, f.name, bank_result, jle::toString(run.status[100]),
                        std::to_string(after) + (matched == after ? "" : " **unmatched**"),
                        sci(dq) + ", " + sci(de)});
      if (dq != 0.0 || de != 0.0) ++violations;
    }
  print(t);
}

const char* kHeader = R"(# Numerical stability

Generated by `tools/stability.sh` (bench/stability.cpp); do not edit by hand. Each
sweep pushes one parameter to its extreme; the joint loads are computed in float,
double and long double from the same inputs (a model and a state in double, converted)
and compared with the same computation in quad precision (`__float128`, 113-bit
significand). The bounds are those test/support/jle_testing/stability_bounds.hpp states and
test/algorithms/test_stability.cpp asserts on representative points; every measured point
here is checked against them (a cell over its bound is marked **OVER** and the tool
fails).

)";

// The findings, with the figures the sweeps measured.
std::string findingsText() {
  const auto ratio = [](double a, double b) { return b > 0.0 ? fixed(a / b, 1) : "n/a"; };
  const double growth =
      std::max(findings.chain_1000 / findings.chain_100, findings.tree_1000 / findings.tree_100);
  std::ostringstream os;
  os << "## Findings\n\n"
     << "- The core loses nothing to the extremes swept: the relative error of the joint\n"
        "  wrenches stays within a few hundred epsilons in double and in float for chains and\n"
        "  trees of up to 1000 joints, mass and inertia ratios of 1e9, links of 0.1 mm to 100 m,\n"
        "  angular velocities of 1e3 rad/s, ideal rods and singular configurations. It grows\n"
        "  with the number of joints "
     << (growth <= 10.0 ? "no faster than linearly" : "FASTER than linearly")
     << ", not with the ratios: from 100 to 1000 joints the worst double error grew "
     << ratio(findings.chain_1000, findings.chain_100) << " times in chains ("
     << sci(findings.chain_100) << " to " << sci(findings.chain_1000) << ") and "
     << ratio(findings.tree_1000, findings.tree_100) << " times in trees ("
     << sci(findings.tree_100) << " to " << sci(findings.tree_1000)
     << "); the bound (300 + 3 n) eps grows 5.5 times.\n"
     << "- A centre of mass far out along the joint axis costs the effort nothing: up to "
     << sci(findings.far_com_max_distance) << " m the worst relative error is "
     << sci(findings.far_com) << " (the table \"Centre of mass far along the joint axis\").\n"
     << "- Tiny inertias keep their gyroscopic term: the skip is decided relative to the\n"
        "  inertia's scale, "
     << findings.tiny_kept_links << " of " << findings.tiny_links
     << " links kept it down to 1e-15 kg m^2, worst double error " << sci(findings.tiny_inertia)
     << " (the table \"Tiny inertias on a planar chain\").\n";
  return os.str();
}

const char* kStaticFindings =
    R"(- A world offset costs the core nothing, because the backward pass works in segment
  frames with moments about the joint and no world position enters it: at 1e5 m from
  the origin the loads are bit-identical to those at the origin. The paper's formulation
  taken literally (world coordinates, lever arms from world positions) loses about
  log10(D / link size) digits of the moments: 1e-8 relative at 1e5 m in double, nothing
  left in float. The same happens to tiny links on a base 1 m from the world origin.
- The least-squares weights of the Savitzky-Golay and finite-difference filters, if
  computed by the normal equations, which square the conditioning of the Vandermonde
  matrix: with one short interval among 1 ms ones (two nearly simultaneous samples),
  the 3-point difference loses up to 6 digits more than its inputs allow (the table
  below). The bank's come from a Householder QR factorisation and stay within a factor
  1.1 of the inputs' rounding.
- Absolute stamps (Unix time, 1.8e9 s) are rounded to 2.4e-7 s before any filter sees
  them, which at 1 kHz is a timing error of 2.4e-4 of the interval: the 3-point qdd of a
  1 rad, 1 Hz sine moves by 1.5 rad/s^2. Nothing inside the filter can undo a rounding
  of its input; with exactly representable stamps the filters give bit-identical
  estimates at any offset. Callers must pass times relative to a recent origin, as the
  message path does (jle::Pipeline keeps a time origin near the stamps).
- Duplicate and backward stamps are refused without disturbing the filters, a gap
  restarts them, a reset after a jump back gives exactly what a fresh estimator gives.
  After 1e7 samples every filter agrees with one started 2e5 samples earlier: the
  window filters to the bit, the Kalman filters to 1e-12; at a steady rate whose
  stamps differ only by rounding, both reuse what they computed earlier (weights, F and
  Q), and two banks differ by what that tolerance of 0.1 ns allows (4e-10 relative for
  the Kalman filters at 1 ms). Nothing accumulates.
)";

const char* const kUsage =
    "usage: stability [--output PATH] [--quick]\n"
    "Sweeps that push one parameter of the core or the filters to its extreme, each against a\n"
    "quad-precision reference; writes the report (docs/studies/stability.md, or PATH) and exits 1 "
    "if a\n"
    "measurement exceeds test_stability's bound. --quick: fewer samples (for CI).\n";

}  // namespace

int main(int argc, char** argv) {
  if (jle::cli::answerHelpOrVersion(argc, argv, "stability", kUsage)) return 0;
  std::string output;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--quick") {
      quick = true;
    } else if (a == "--output" && k + 1 < argc) {
      output = argv[++k];
    } else {
      std::cerr << kUsage;
      return 2;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  chainLengthSweep(false);
  chainLengthSweep(true);
  ratioSweep(false);
  ratioSweep(true);
  linkLengthSweep();
  velocitySweep();
  rodSweep();
  singularSweep();
  tinyInertiaTable();
  farComSweep();
  worldOffsetSweep();
  shortIntervalSweep();
  epochSweep();
  eventsTable();
  longRunSweep();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cerr << "done in " << seconds << " s, " << violations << " bound(s) exceeded\n";
  if (!output.empty()) {
    std::ofstream out(output);
    out << kHeader << findingsText() << kStaticFindings;
    if (quick) out << "\n**This is a --quick run: fewer samples than the published tables.**\n";
    out << "\n";
    for (const Table& t : tables) out << t.markdown() << "\n";
  }
  return violations == 0 ? 0 : 1;
}
