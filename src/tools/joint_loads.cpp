// joint_loads: the joint wrenches and efforts of a URDF robot along a CSV of joint
// states (and applied wrenches), one output row per input row. docs/joint_loads.md.
#include <joint_load_estimator/command_line.hpp>
#include <joint_load_estimator/csv.hpp>
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/kinematics.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using jle::cli::UsageError;
using jle::cli::optionValues;

const char* const kUsage =
    R"(usage: joint_loads --urdf ROBOT.urdf --input STATES.csv [--output LOADS.csv]
                   [--gravity GX,GY,GZ] [--frame child|parent|world]

Joint loads by per-segment inverse dynamics: for every sample of STATES.csv, the
wrench that each moving joint's parent exerts on its child (moment about the joint
origin) and the joint effort (axis . moment, or axis . force for a prismatic joint).

  --urdf PATH      the robot (a fixed base; a floating-base model is refused)
  --input PATH     the joint states, CSV with a header row:
                     t                         time [s], copied to the output
                     JOINT.q, JOINT.qd, JOINT.qdd
                                               for every revolute, continuous and
                                               prismatic joint [rad or m, /s, /s^2];
                                               mimic joints may be left out (ignored
                                               if present: a mimic follows its leader)
                     wrench@LINK.fx,.fy,.fz,.mx,.my,.mz
                                               optional: a wrench applied TO the robot
                                               at the origin of URDF link LINK, in
                                               LINK's frame [N, N m]; all six or none
                   columns in any order; blanks around cells, CRLF and blank lines at
                   the end are accepted
  --output PATH    where the loads go (default: standard output); written to a
                   temporary file beside PATH and renamed onto it on success only
  --gravity G      gravity in the world (root link) frame [m/s^2], default 0,0,-9.80665
  --frame F        the frame of the output wrenches: child (the joint's child link,
                   default), parent (the joint's URDF parent link) or world
  --help           this text

Output: t, then for every moving joint in URDF tree order (depth first from the
root, children in document order; mimic joints included)
JOINT.fx,JOINT.fy,JOINT.fz,JOINT.mx,JOINT.my,JOINT.mz,JOINT.effort, every number
with 17 significant digits (%.17g).

Exit status: 0 success; 1 a data error (a file that cannot be read or written, a
URDF the model refuses, a CSV defect: the message names FILE:LINE and the column);
2 a usage error (an unknown, missing or repeated option, a bad option value).
)";

struct Options {
  std::string urdf, input, output;
  Eigen::Vector3d gravity_world{0.0, 0.0, -9.80665};
  jle::WrenchFrame frame = jle::WrenchFrame::kChild;
};


Eigen::Vector3d parseGravity(const std::string& text) {
  Eigen::Vector3d g;
  const char* s = text.c_str();
  for (int i = 0; i < 3; ++i) {
    char* end = nullptr;
    g[i] = std::strtod(s, &end);
    while (end != s && (*end == ' ' || *end == '\t')) ++end;
    const char expected = i < 2 ? ',' : '\0';
    if (end == s || *end != expected || !std::isfinite(g[i]))
      throw UsageError("--gravity: '" + text + "' is not GX,GY,GZ (three finite numbers, m/s^2)");
    s = end + (i < 2 ? 1 : 0);
  }
  return g;
}

jle::WrenchFrame parseFrame(const std::string& text) {
  if (text == "child") return jle::WrenchFrame::kChild;
  if (text == "parent") return jle::WrenchFrame::kParent;
  if (text == "world") return jle::WrenchFrame::kWorld;
  throw UsageError("--frame: '" + text + "' is not child, parent or world");
}

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v =
      optionValues(argc, argv, {"--urdf", "--input", "--output", "--gravity", "--frame"});
  Options options;
  if (!v.count("--urdf")) throw UsageError("--urdf ROBOT.urdf is required");
  if (!v.count("--input")) throw UsageError("--input STATES.csv is required");
  options.urdf = v["--urdf"];
  options.input = v["--input"];
  if (v.count("--output")) options.output = v["--output"];
  if (v.count("--gravity")) options.gravity_world = parseGravity(v["--gravity"]);
  if (v.count("--frame")) options.frame = parseFrame(v["--frame"]);
  return options;
}

void run(const Options& options) {
  const jle::Model<double> model = jle::modelFromUrdfFile(options.urdf);
  if (model.floating_base)
    throw std::runtime_error(options.urdf +
                             ": the model has a floating base, whose motion joint_loads "
                             "does not read");
  jle::CsvReader reader(options.input);
  const jle::StateColumns columns = jle::bindStateColumns(model, reader);

  // Everything the loop touches is allocated here, once.
  jle::Data<double> data(model);
  jle::VectorX<double> q(model.nq), qd(model.nq), qdd(model.nq);
  std::vector<double> cells(static_cast<std::size_t>(reader.columns()));
  std::vector<double> loads(1 + 7 * model.moving_segments.size());

  jle::CsvWriter writer(options.output);
  writer.writeHeader(jle::jointLoadColumns(model));
  while (reader.next()) {
    reader.numbers(cells.data());
    for (int k = 0; k < model.nq; ++k) {
      q[k] = cells[columns.q[k]];
      qd[k] = cells[columns.qd[k]];
      qdd[k] = cells[columns.qdd[k]];
    }
    jle::forwardKinematics(model, data, q, qd, qdd, options.gravity_world);
    for (const jle::StateColumns::WrenchColumns& w : columns.wrenches) {
      const auto& c = w.column;
      jle::addExternalWrench(
          model, data, w.frame, Eigen::Vector3d(cells[c[0]], cells[c[1]], cells[c[2]]),
          Eigen::Vector3d(cells[c[3]], cells[c[4]], cells[c[5]]), jle::WrenchFrame::kLocal);
    }
    jle::inverseDynamics(model, data);

    double* out = loads.data();
    *out++ = cells[columns.t];
    for (int s : model.moving_segments) {
      const jle::Wrench<double> w = jle::jointWrench(model, data, s, options.frame);
      for (int i = 0; i < 3; ++i) *out++ = w.force[i];
      for (int i = 0; i < 3; ++i) *out++ = w.moment[i];
      *out++ = data.effort[s];
    }
    writer.writeRow(loads.data(), loads.size());
  }
  writer.commit();
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "joint_loads", kUsage, parseOptions, run);
}
