// joint_loads: the joint wrenches and efforts of a URDF robot along a CSV of joint
// states (and applied wrenches), one output row per input row. docs/joint_loads.md.
#include <joint_load_estimator/filters/base_motion.hpp>
#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/io/csv.hpp>
#include <joint_load_estimator/io/sto.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/force_plate.hpp>
#include <joint_load_estimator/model/friction.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/planar.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/plausibility.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace jle::cli;  // command_line.hpp: UsageError, optionValues, the parsers

const char* const kUsage =
    R"(usage: joint_loads --urdf ROBOT.urdf --input STATES.csv [--output LOADS]
                   [--gravity GX,GY,GZ] [--frame child|parent|world]
                   [--floating-base] [--accept-nonphysical-inertia]
                   [--plate NAME=LINK,X,Y,Z[,YAW_DEG]]...
                   [--contact-threshold N] [--per-kg [--body-mass KG]]
                   [--kinematics] [--friction [--velocity-scale V]]
                   [--planar off|auto|on] [--format csv|sto]
                   [--cutoff HZ|auto] [--cutoff-rule residual|gcv]
                   [--filter-order N] [--write-kinematics STATES.csv]

Joint loads by per-segment inverse dynamics: for every sample of STATES.csv, the
wrench that each moving joint's parent exerts on its child (moment about the joint
origin) and the joint effort (axis . moment, or axis . force for a prismatic joint).

  --urdf PATH      the robot; its root is fixed in the world unless --floating-base
                   (or a URDF whose root holds a floating joint)
  --input PATH     the joint states, CSV with a header row:
                     t                         time [s], copied to the output
                     JOINT.q, JOINT.qd, JOINT.qdd
                                               for every revolute, continuous and
                                               prismatic joint [rad or m, /s, /s^2];
                                               mimic joints may be left out (ignored
                                               if present: a mimic follows its leader);
                                               or JOINT.q alone for every joint
                                               (positions only: see --cutoff; a
                                               floating base's pose is then smoothed
                                               and differentiated alike)
                     wrench@LINK.fx,.fy,.fz,.mx,.my,.mz
                                               optional: a wrench applied TO the robot
                                               at the origin of URDF link LINK, in
                                               LINK's frame [N, N m]; all six or none
                     base.x,.y,.z,.qx,.qy,.qz,.qw
                                               floating base: the root link's origin
                                               [m] and orientation (unit quaternion) in
                                               the world; required
                     base.vx,.vy,.vz,.wx,.wy,.wz
                                               optional: velocity of the root link
                                               origin and angular velocity, world frame
                     base.ax,.ay,.az,.alx,.aly,.alz
                                               optional: their derivatives, world frame;
                                               estimated from the neighbouring rows when
                                               absent (docs/joint_loads.md)
                     plate@NAME.fx,.fy,.fz,.mx,.my,.mz
                                               for every --plate: what the foot applies
                                               to the plate, plate frame, moment about
                                               the plate origin [N, N m]
                   columns in any order; blanks around cells, CRLF and blank lines at
                   the end are accepted
  --output PATH    where the loads go (default: standard output); written to a
                   temporary file beside PATH and renamed onto it on success only
  --gravity G      gravity in the world (root link) frame [m/s^2], default 0,0,-9.80665;
                   any three finite numbers (0,0,0: no gravity). With --plate it must
                   point along -z (GX = GY = 0, GZ <= 0): the plates lie in the world's
                   x-y plane with z up; a world with another up axis is refused (turn
                   the data into a z-up world, or use the node, whose plate poses are
                   free)
  --frame F        the frame of the output joint wrenches: child (the joint's child
                   link, default), parent (the joint's URDF parent link) or world
  --floating-base  the URDF's root link floats: its pose is read from base.* columns
  --accept-nonphysical-inertia
                   accept link inertias no rigid body has (an identified parameter
                   set: not positive semi-definite, triangle inequality broken) with a
                   warning per link: the efforts are the identified model's, the
                   joints' full 3-D force and moment are not physical (docs/how_it_works.md
                   "Model"). Default: such a model is refused
  --plate NAME=LINK,X,Y,Z[,YAW_DEG]
                   a force plate (repeatable): its frame (z up, the contact surface
                   through its origin) at X,Y,Z [m] in the world (finite), turned by
                   YAW_DEG (finite, any sign) about the world z axis; the foot LINK
                   stands on it and receives the reaction at the centre of pressure
  --contact-threshold N
                   plate force [N], >= 0 (default 20), below which no centre of
                   pressure is decoded and the plate is not in contact; a pressing
                   reading still acts on the foot as measured. 0: every reading that
                   presses into the plate (plate@NAME.fz < 0) is in contact; one that
                   does not (fz >= 0) is never in contact and does not act at all
  --per-kg         also JOINT.effort_per_kg = effort / body mass [N m/kg, N/kg]
  --body-mass KG   the body mass for --per-kg, > 0 (default: the URDF's total mass)
  --kinematics     also JOINT.q, .qd, .qdd of every joint (what the loads were
                   computed from; a mimic joint's from its leader's)
  --friction       also JOINT.motor_effort = effort + damping qd + friction
                   tanh(qd / V), from each joint's URDF <dynamics damping friction>
                   (docs/outputs.md)
  --velocity-scale V
                   [rad/s or m/s] width of the smooth sign of --friction, > 0
                   (default 0.01)
  --planar M       the planar solver (the 3x3 system per segment of a model moving in a
                   plane, e.g. make_body_urdf --sagittal; the same loads within 1e-12
                   relative): off (default), auto (when the model is detected planar:
                   fixed base, every revolute axis along one normal n, prismatic axes
                   and gravity perpendicular to n, n a principal axis of every
                   inertia; a row whose wrench@ columns leave the plane takes the 6x6
                   path) or on (the user asserts planarity: out-of-plane parts are
                   dropped; refused for a floating base or a model without a
                   revolute joint). The choice and its reason are printed on standard
                   error. Not with --plate, --frame parent|world, --kinematics,
                   --friction (the 6x6 path's outputs)
  --format F       csv (default) or sto (OpenSim storage file, docs/joint_loads.md;
                   world vectors in OpenSim's ground axes, y up: the CSV's (x, y, z)
                   is written (x, z, -y); --gravity must point along -z)
  --cutoff HZ|auto positions only (no JOINT.qdd column; JOINT.qd for every joint or
                   none: measured velocities only guide the cutoff): q, and with the
                   same filter every wrench@ and plate@ column, are smoothed by a
                   Butterworth low-pass run forward and backward (zero phase), and
                   q is differentiated (docs/studies/zero_phase.md); the cutoff [Hz] given
                   (> 0 and below half the sampling rate),
                   or chosen from the q columns by --cutoff-rule (default: auto).
                   The cutoff used is printed on standard error.
  --cutoff-rule R  with --cutoff auto: auto (default: the JOINT.qd columns as
                   evidence when the CSV has them, else the positions' noise
                   spectrum), spectrum, velocity, gcv (generalised
                   cross-validation) or residual (Winter's residual analysis).
                   The rule used is printed, and a warning when the choice is
                   doubtful (on a bound of the search, or rules disagreeing)
  --filter-order N Butterworth order of each pass, 1..8 (default 4)
  --write-kinematics PATH
                   positions only: also write the smoothed inputs as a joint-state
                   CSV (t, JOINT.q, .qd, .qdd, the wrench@ and plate@ columns), %.17g
  --help           this text

Output: t; with a floating base base.fx,.fy,.fz,.mx,.my,.mz (what the world must
apply to the root link: world frame, moment about the root link origin; zero when
the measured loads explain the motion); for every moving joint in URDF tree order
(depth first from the root, children in document order; mimic joints included)
JOINT.fx,JOINT.fy,JOINT.fz,JOINT.mx,JOINT.my,JOINT.mz,JOINT.effort
[,JOINT.effort_per_kg]; with --kinematics JOINT.q,.qd,.qdd for every joint; with
--friction JOINT.motor_effort for every joint; for every plate plate@NAME.contact (1 or 0) and
plate@NAME.cop_x,.cop_y,.cop_z (centre of pressure in the world [m], 0 without
contact). Every number with 17 significant digits (%.17g).

Exit status: 0 success; 1 a data error (a file that cannot be read or written, a
URDF the model refuses, a CSV defect: the message names FILE:LINE and the column);
2 a usage error (an unknown, missing or repeated option, a bad option value, a
--plate on an unknown link).
)";

struct Options {
  std::string urdf, input, output;
  Eigen::Vector3d gravity_world = jle::EstimatorConfig().gravity_world;
  jle::WrenchFrame frame = jle::WrenchFrame::kChild;
  bool floating_base = false;
  bool accept_nonphysical_inertia = jle::ModelOptions().accept_nonphysical_inertia;
  std::vector<jle::ForcePlateConfig> plates;
  double contact_threshold = jle::ForcePlateConfig().contact_threshold;
  bool per_kg = false;
  double body_mass = 0.0;  // 0: the model's total mass
  bool sto = false;
  // Positions-only CSVs: the zero-phase filter; `smoothing_given`: an option of it was
  // given (refused for a CSV with JOINT.qd, JOINT.qdd).
  jle::ZeroPhaseConfig smoothing;
  bool smoothing_given = false;
  std::string write_kinematics;  // --write-kinematics FILE
  bool kinematics = false;
  bool friction = false;
  double velocity_scale = jle::FrictionConfig().velocity_scale;  // [rad/s or m/s]
  jle::PlanarMode planar = jle::PlanarMode::kOff;                // --planar
};

Eigen::Vector3d parseGravity(const std::string& text) {
  Eigen::Vector3d g;
  if (!parseNumberList(text, 3, g.data()))
    throw UsageError("--gravity: '" + text + "' is not GX,GY,GZ (three finite numbers, m/s^2)");
  return g;
}

jle::WrenchFrame parseFrame(const std::string& text) {
  if (text == "child") return jle::WrenchFrame::kChild;
  if (text == "parent") return jle::WrenchFrame::kParent;
  if (text == "world") return jle::WrenchFrame::kWorld;
  throw UsageError("--frame: '" + text + "' is not child, parent or world");
}

// NAME=LINK,x,y,z[,yaw_deg]: a plate frame (z up) at (x, y, z) in the world, turned by
// yaw about the world z axis.
jle::ForcePlateConfig parsePlate(const std::string& text) {
  const std::string what = "--plate: '" + text +
                           "' is not NAME=LINK,X,Y,Z[,YAW_DEG] (NAME and LINK without '=', ',', "
                           "'.' or blanks; finite numbers)";
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw UsageError(what);
  const std::size_t comma = text.find(',', eq + 1);
  if (comma == std::string::npos || comma == eq + 1) throw UsageError(what);
  jle::ForcePlateConfig plate;
  plate.name = text.substr(0, eq);
  plate.link = text.substr(eq + 1, comma - eq - 1);
  if (plate.name.find_first_of("=,. \t@") != std::string::npos ||
      plate.link.find_first_of("=, \t") != std::string::npos)
    throw UsageError(what);
  const std::string numbers = text.substr(comma + 1);
  double v[4] = {0, 0, 0, 0};
  const int count = static_cast<int>(std::count(numbers.begin(), numbers.end(), ',')) + 1;
  if ((count != 3 && count != 4) || !parseNumberList(numbers, count, v)) throw UsageError(what);
  plate.p_world_plate = Eigen::Vector3d(v[0], v[1], v[2]);
  plate.R_world_plate =
      Eigen::AngleAxisd(v[3] * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return plate;
}

// The plates of the --plate values, each with the contact threshold; a name once.
std::vector<jle::ForcePlateConfig> platesOf(const std::vector<std::string>& values,
                                            double contact_threshold) {
  std::vector<jle::ForcePlateConfig> plates;
  for (const std::string& text : values) {
    if (text.empty()) throw UsageError("--plate: empty value");
    jle::ForcePlateConfig plate = parsePlate(text);
    for (const jle::ForcePlateConfig& other : plates)
      if (other.name == plate.name)
        throw UsageError("--plate: plate '" + plate.name + "' is given twice");
    plate.contact_threshold = contact_threshold;
    plates.push_back(plate);
  }
  return plates;
}

// The --plate frames are z up in the world: gravity along +z, or off the z axis, would
// put the plates on a wall or a ceiling without saying so. A .sto turns the world's z-up
// vectors into OpenSim's y-up ground (sto.hpp): the same holds.
void checkWorldUp(const Options& options) {
  const Eigen::Vector3d& g = options.gravity_world;
  const double tolerance = 1e-12 * g.norm();
  if ((options.plates.empty() && !options.sto) ||
      (std::abs(g.x()) <= tolerance && std::abs(g.y()) <= tolerance && g.z() <= 0.0))
    return;
  const std::string gravity = "--gravity " + std::to_string(g.x()) + "," + std::to_string(g.y()) +
                              "," + std::to_string(g.z());
  if (options.plates.empty())
    throw UsageError(gravity +
                     " with --format sto: a .sto gives world vectors in OpenSim's y-up ground, "
                     "turned from a z-up world, so --gravity must point along -z (0,0,-G); "
                     "express the data in a z-up world");
  throw UsageError(gravity + " with --plate " + options.plates.front().name +
                   ": --plate frames are z up in the world, so --gravity must point along -z "
                   "(0,0,-G); express the data in a z-up world");
}

// --cutoff, --cutoff-rule, --filter-order, --write-kinematics.
void parseSmoothing(std::map<std::string, std::string>& v, Options& options) {
  jle::ZeroPhaseConfig& z = options.smoothing;
  const std::string cutoff = v.count("--cutoff") ? v["--cutoff"] : "auto";
  if (cutoff != "auto") {
    z.rule = jle::CutoffRule::kFixed;
    z.cutoff = parseNumber("--cutoff", cutoff, Sign::kPositive);
  }
  if (v.count("--cutoff-rule")) {
    if (cutoff != "auto") throw UsageError("--cutoff-rule is only used with --cutoff auto");
    if (!jle::parseCutoffRule(v["--cutoff-rule"], z.rule))
      throw UsageError("--cutoff-rule: '" + v["--cutoff-rule"] +
                       "' is not auto, spectrum, velocity, gcv or residual");
  }
  if (v.count("--filter-order"))
    z.order = static_cast<int>(parseInteger("--filter-order", v["--filter-order"], 1, 8));
  if (v.count("--write-kinematics")) options.write_kinematics = v["--write-kinematics"];
  for (const char* key : {"--cutoff", "--cutoff-rule", "--filter-order", "--write-kinematics"})
    options.smoothing_given = options.smoothing_given || v.count(key) > 0;
}

// --kinematics, --friction, --velocity-scale.
void parseOutputOptions(std::map<std::string, std::string>& v, Options& options) {
  options.kinematics = v.count("--kinematics") > 0;
  options.friction = v.count("--friction") > 0;
  if (v.count("--velocity-scale")) {
    if (!options.friction) throw UsageError("--velocity-scale is only used with --friction");
    options.velocity_scale =
        parseNumber("--velocity-scale", v["--velocity-scale"], Sign::kPositive);
  }
  if (options.sto && (options.kinematics || options.friction))
    throw UsageError("--kinematics and --friction are columns of the csv format only");
  if (v.count("--planar")) {
    const std::string& m = v["--planar"];
    if (m != "off" && m != "auto" && m != "on")
      throw UsageError("--planar: '" + m + "' is not off, auto or on");
    options.planar = m == "on" ? jle::PlanarMode::kOn
                               : (m == "auto" ? jle::PlanarMode::kAuto : jle::PlanarMode::kOff);
  }
  if (options.planar != jle::PlanarMode::kOff &&
      (options.kinematics || options.friction || !options.plates.empty() ||
       options.frame != jle::WrenchFrame::kChild))
    throw UsageError(
        "--planar " + v["--planar"] +
        " is not for --plate, --frame parent|world, --kinematics or --friction (the 6x6 "
        "path's outputs; give plates as wrench@FOOT columns)");
}

Options parseOptions(int argc, char** argv) {
  std::vector<std::string> plates;
  std::vector<char*> rest;
  takeRepeatedOption(argc, argv, "--plate", plates, rest);
  std::map<std::string, std::string> v =
      optionValues(static_cast<int>(rest.size()), rest.data(),
                   {"--urdf", "--input", "--output", "--gravity", "--frame", "--contact-threshold",
                    "--body-mass", "--format", "--cutoff", "--cutoff-rule", "--filter-order",
                    "--write-kinematics", "--velocity-scale", "--planar"},
                   {"--floating-base", "--per-kg", "--kinematics", "--friction",
                    "--accept-nonphysical-inertia"});
  Options options;
  options.urdf = requiredValue(v, "--urdf", "ROBOT.urdf");
  options.input = requiredValue(v, "--input", "STATES.csv");
  if (v.count("--output")) options.output = v["--output"];
  if (v.count("--gravity")) options.gravity_world = parseGravity(v["--gravity"]);
  if (v.count("--frame")) options.frame = parseFrame(v["--frame"]);
  options.floating_base = v.count("--floating-base") > 0;
  if (v.count("--accept-nonphysical-inertia")) options.accept_nonphysical_inertia = true;
  if (v.count("--contact-threshold"))
    options.contact_threshold =
        parseNumber("--contact-threshold", v["--contact-threshold"], Sign::kNonNegative);
  options.plates = platesOf(plates, options.contact_threshold);
  options.per_kg = v.count("--per-kg") > 0;
  if (v.count("--body-mass")) {
    if (!options.per_kg) throw UsageError("--body-mass is only used with --per-kg");
    options.body_mass = parseNumber("--body-mass", v["--body-mass"], Sign::kPositive);
  }
  if (v.count("--format") && v["--format"] != "csv" && v["--format"] != "sto")
    throw UsageError("--format: '" + v["--format"] + "' is not csv or sto");
  options.sto = v.count("--format") && v["--format"] == "sto";
  checkWorldUp(options);
  parseSmoothing(v, options);
  parseOutputOptions(v, options);
  return options;
}

// The output, CSV or OpenSim storage.
class Output {
 public:
  Output(const Options& options, const jle::Model<double>& model,
         const std::vector<std::string>& names) {
    if (options.sto) {
      sto_ = std::make_unique<jle::StoWriter>(options.output);
      sto_->writeHeader(jle::stoLayout(model, names, options.frame));
    } else {
      csv_ = std::make_unique<jle::CsvWriter>(options.output);
      csv_->writeHeader(names);
    }
  }
  void row(const std::vector<double>& values) {
    if (sto_)
      sto_->writeRow(values.data(), values.size());
    else
      csv_->writeRow(values.data(), values.size());
  }
  void commit() {
    if (sto_)
      sto_->commit();
    else
      csv_->commit();
  }

 private:
  std::unique_ptr<jle::CsvWriter> csv_;
  std::unique_ptr<jle::StoWriter> sto_;
};

// One input row, as read.
struct Row {
  std::vector<double> cells;
  long line = 0;
  jle::BasePoseSample pose;
};

// Three cells of a row: columns c[first], c[first + 1], c[first + 2].
Eigen::Vector3d triple(const std::vector<double>& cells, const std::array<int, 6>& c, int first) {
  return Eigen::Vector3d(cells[c[first]], cells[c[first + 1]], cells[c[first + 2]]);
}

std::string shortest(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

// The base pose's quaternion in the current record's `cells`: of norm 1 within 1 %.
void checkBaseQuaternion(const jle::CsvReader& reader, const jle::StateColumns& columns,
                         const std::vector<double>& x) {
  const auto& c = columns.base_pose;
  const double norm = Eigen::Quaterniond(x[c[6]], x[c[3]], x[c[4]], x[c[5]]).norm();
  if (!(std::abs(norm - 1.0) <= 0.01))
    reader.failAt(c[6], "the quaternion (base.qx, .qy, .qz, .qw) has norm " + std::to_string(norm) +
                            ", not 1 (within 1 %)");
}

// Plausibility at the door, the rules of jle::Pipeline (plausibility.hpp, its defaults):
// a position beyond its joint's URDF limits by more than the margin (1e300, 100 rad), a
// step from the previous row faster than the joint moves (a one-row glitch), a measured
// velocity beyond what the joint does. A row of the file: refused as a defect of the CSV
// (exit status 1, the line and column named), never smoothed into its neighbours. The
// step is checked where rows are differentiated (`previous`: positions only); rows with
// JOINT.qd, JOINT.qdd are states of their own.
void checkPlausible(const jle::CsvReader& reader, const jle::Model<double>& model,
                    const jle::StateColumns& columns, const std::vector<double>& cells,
                    const std::vector<double>* previous) {
  static const jle::PlausibilityConfig p;
  static const std::string kWhy =
      ": refused (no such joint moves so; docs/node.md \"Never silently wrong\")";
  const std::vector<int> segment = jle::coordinateSegments(model);
  const double dt = previous ? cells[columns.t] - (*previous)[columns.t] : 0.0;
  for (std::size_t k = 0; k < columns.q.size(); ++k) {
    const std::size_t s = static_cast<std::size_t>(segment[k]);
    const double q = cells[columns.q[k]];
    const jle::PlausibleRange range = jle::plausibleRange(model, p, s);
    if (!jle::plausiblePosition(range, q))
      reader.failAt(columns.q[k], jle::positionProblem(model, p, s, q) + kWhy);
    const double step = dt > 0.0 ? q - (*previous)[columns.q[k]] : 0.0;
    if (dt > 0.0 && !jle::plausibleStep(range, p, step, dt))
      reader.failAt(columns.q[k], jle::stepProblem(model, p, s, step, dt) + kWhy);
    if (columns.qd[k] < 0 || !jle::implausibleVelocity(range, cells[columns.qd[k]])) continue;
    reader.failAt(columns.qd[k], "velocity of joint '" + model.joint_name[s] + "' is " +
                                     shortest(cells[columns.qd[k]]) +
                                     ", beyond plausibility/"
                                     "velocity_factor times its velocity limit " +
                                     shortest(jle::velocityLimit(model, p, s)) + kWhy);
  }
}

// The base pose of a row's cells, its quaternion normalised.
void setBasePose(const jle::StateColumns& columns, Row& row) {
  const auto& c = columns.base_pose;
  const std::vector<double>& x = row.cells;
  row.pose.t = x[columns.t];
  row.pose.p_world_base = Eigen::Vector3d(x[c[0]], x[c[1]], x[c[2]]);
  row.pose.R_world_base =
      Eigen::Quaterniond(x[c[6]], x[c[3]], x[c[4]], x[c[5]]).normalized().toRotationMatrix();
}

// The base pose of the current record, checked.
void readBasePose(const jle::CsvReader& reader, const jle::StateColumns& columns, Row& row) {
  checkBaseQuaternion(reader, columns, row.cells);
  setBasePose(columns, row);
}

// The loads of each input row. A floating base whose twist or acceleration the CSV does
// not hold has them estimated from a window of three rows: a row is emitted once the
// next one is read (the first two with the third, the last at the end).
class Processor {
 public:
  Processor(const Options& options, const jle::Model<double>& model,
            const jle::StateColumns& columns, std::size_t cells)
      : options_(options),
        model_(model),
        columns_(columns),
        data_(model),
        q_(model.nq),
        qd_(model.nq),
        qdd_(model.nq),
        mass_(options.body_mass > 0.0 ? options.body_mass : model.totalMass()),
        estimate_(model.floating_base &&
                  !(columns.hasBaseTwist() && columns.hasBaseAcceleration())),
        cop_(4 * options.plates.size(), 0.0) {
    for (Row& r : window_) r.cells.resize(cells);
    jle::LoadColumnLayout layout;
    layout.base = model.floating_base;
    layout.per_kg = options.per_kg;
    layout.kinematics = options.kinematics;
    layout.motor_effort = options.friction;
    for (const jle::ForcePlateConfig& plate : options.plates) {
      plate_frames_.push_back(model.frameIndex(plate.link));
      layout.plates.push_back(plate.name);
    }
    names_ = jle::jointLoadColumns(model, layout);
    loads_.resize(names_.size());
    setUpPlanar();
  }

  const std::vector<std::string>& names() const { return names_; }

  // Reads the current record of `reader` as row n.
  void read(const jle::CsvReader& reader, long n) {
    Row& row = slot(n);
    reader.numbers(row.cells.data());
    row.line = reader.line();
    checkPlausible(reader, model_, columns_, row.cells, nullptr);
    if (model_.floating_base) readBasePose(reader, columns_, row);
    if (estimate_ && n > 0 && !(row.cells[columns_.t] > slot(n - 1).cells[columns_.t]))
      reader.failAt(columns_.t, "time does not increase (the previous row's is " +
                                    shortest(slot(n - 1).cells[columns_.t]) +
                                    "): the base motion is estimated from the times");
  }

  // Takes `cells` (the record of `line`, as smoothPositions completed it) as row n.
  void take(const std::vector<double>& cells, long line, long n) {
    Row& row = slot(n);
    std::copy(cells.begin(), cells.end(), row.cells.begin());
    row.line = line;
    if (model_.floating_base) setBasePose(columns_, row);
  }

  // Emits what row n, just read, completes.
  void emitReady(long n, Output& out) {
    if (!estimate_) {
      emit(n, -1, out);
    } else if (n == 2) {
      emit(0, 0, out);
      emit(1, 1, out);
    } else if (n > 2) {
      emit(n - 1, 1, out);
    }
  }

  // Emits the last row, after `n` rows in all.
  void finish(long n, Output& out) {
    finishRows(n, out);
    if (implausible_ > 0)
      std::fprintf(stderr,
                   "joint_loads: warning: %ld rows with an effort beyond plausibility/"
                   "effort_factor %.3g times its joint's URDF effort limit (implausible loads; "
                   "the first: %s)\n",
                   implausible_, jle::PlausibilityConfig().effort_factor,
                   first_implausible_.c_str());
  }

 private:
  void finishRows(long n, Output& out) {
    if (!estimate_) return;
    if (n > 0 && n < 3)
      throw std::runtime_error(options_.input + ": " + std::to_string(n) +
                               " rows; estimating the base twist and acceleration from the "
                               "pose needs at least 3 (or give base.vx ... base.alz)");
    if (n >= 3) emit(n - 1, 2, out);
  }

  Row& slot(long index) { return window_[static_cast<std::size_t>(index % 3)]; }

  // Row `index` (its window: the rows index - m ... index - m + 2; m < 0: none) to the
  // output.
  void emit(long index, int m, Output& out) {
    const std::vector<double>& cells = slot(index).cells;
    for (int k = 0; k < model_.nq; ++k) {
      q_[k] = cells[columns_.q[k]];
      qd_[k] = cells[columns_.qd[k]];
      qdd_[k] = cells[columns_.qdd[k]];
    }
    if (!(planar_ && planarLoads(cells))) {
      const jle::BaseState<double> base =
          model_.floating_base ? baseState(index, m) : jle::BaseState<double>();
      jle::forwardKinematics(model_, data_, q_, qd_, qdd_, options_.gravity_world, base);
      for (const jle::StateColumns::WrenchColumns& w : columns_.wrenches)
        jle::addExternalWrench(model_, data_, w.frame, triple(cells, w.column, 0),
                               triple(cells, w.column, 3), jle::WrenchFrame::kLocal);
      applyPlates(cells);
      jle::inverseDynamics(model_, data_);
    }
    writeLoads(slot(index), out);
  }

  // --planar: the planar solver is set up if the model is planar (auto) or asserted (on),
  // as the estimator does for savings/planar.
  void setUpPlanar() {
    if (options_.planar == jle::PlanarMode::kOff) return;
    const jle::PlanarCheck<double> check = jle::detectPlanar(model_, options_.gravity_world);
    planar_ = check.planar;
    if (!planar_ && options_.planar == jle::PlanarMode::kOn) {
      if (model_.floating_base || check.normal.isZero())
        throw std::runtime_error("--planar on: " + check.reason);
      planar_ = true;  // the user's assertion: out-of-plane parts are dropped
    }
    if (planar_) {
      planar_model_ = jle::planarModel(model_, check.normal);
      planar_data_ = jle::PlanarData<double>(model_.nsegments());
      for (int i = 0; i < model_.nsegments(); ++i) segments_.push_back(i);
    }
    const Eigen::Vector3d& n = check.normal;
    std::fprintf(stderr, "joint_loads: planar %s: %s (normal %.17g %.17g %.17g)%s%s\n",
                 options_.planar == jle::PlanarMode::kOn ? "on" : "auto",
                 planar_ ? "the 3x3 solver" : "the 6x6 solver", n.x(), n.y(), n.z(),
                 check.reason.empty() ? "" : ": ", check.reason.c_str());
  }

  // The loads of a row by the planar solver; false (nothing done) when --planar auto
  // meets a wrench out of the plane.
  bool planarLoads(const std::vector<double>& cells) {
    if (options_.planar == jle::PlanarMode::kAuto)
      for (const jle::StateColumns::WrenchColumns& w : columns_.wrenches)
        if (!jle::planarWrenchInPlane(planar_model_, w.frame, triple(cells, w.column, 0),
                                      triple(cells, w.column, 3)))
          return false;
    jle::planarKinematics(model_, planar_model_, planar_data_, q_, qd_, qdd_,
                          options_.gravity_world, segments_);
    for (const jle::StateColumns::WrenchColumns& w : columns_.wrenches)
      jle::planarAddExternalWrench(model_, planar_model_, planar_data_, w.frame,
                                   triple(cells, w.column, 0), triple(cells, w.column, 3));
    jle::planarInverseDynamics(model_, planar_model_, planar_data_, data_, segments_);
    return true;
  }

  // The root's motion at row `index`: its pose, and its twist and acceleration from the
  // row or estimated from the window (m >= 0).
  jle::BaseState<double> baseState(long index, int m) {
    const Row& row = slot(index);
    jle::BaseState<double> base;
    base.R_world_base = row.pose.R_world_base;
    base.p_world_base = row.pose.p_world_base;
    if (columns_.hasBaseTwist()) {
      base.v_world = triple(row.cells, columns_.base_twist, 0);
      base.omega_world = triple(row.cells, columns_.base_twist, 3);
    }
    if (columns_.hasBaseAcceleration()) {
      base.a_world = triple(row.cells, columns_.base_acceleration, 0);
      base.alpha_world = triple(row.cells, columns_.base_acceleration, 3);
    }
    if (m >= 0) estimateBaseMotion(index - m, m, base);
    return base;
  }

  // What the row does not hold of the root's motion, from the rows first .. first + 2
  // (the row itself is first + m).
  void estimateBaseMotion(long first, int m, jle::BaseState<double>& base) {
    if (!columns_.hasBaseTwist()) {
      const jle::BasePoseSample s[3] = {slot(first).pose, slot(first + 1).pose,
                                        slot(first + 2).pose};
      jle::BaseState<double> estimate;
      jle::baseMotionFromPoses(s, m, estimate, !columns_.hasBaseAcceleration());
      base.v_world = estimate.v_world;
      base.omega_world = estimate.omega_world;
      if (!columns_.hasBaseAcceleration()) {
        base.a_world = estimate.a_world;
        base.alpha_world = estimate.alpha_world;
      }
    } else if (!columns_.hasBaseAcceleration()) {
      double t[3];
      Eigen::Vector3d v[3], w[3];
      for (int j = 0; j < 3; ++j) {
        const std::vector<double>& c = slot(first + j).cells;
        t[j] = c[columns_.t];
        v[j] = triple(c, columns_.base_twist, 0);
        w[j] = triple(c, columns_.base_twist, 3);
      }
      jle::baseAccelerationFromTwists(t, m, v, w, base);
    }
  }

  // Each plate's reaction on its foot (force_plate.hpp, as the estimator applies it), and
  // its contact and centre of pressure in the world for the output.
  void applyPlates(const std::vector<double>& cells) {
    double* cop = cop_.data();
    for (std::size_t p = 0; p < options_.plates.size(); ++p) {
      const jle::ForcePlateConfig& plate = options_.plates[p];
      const std::array<int, 6>& c = columns_.plates[p];
      const jle::PlateReading reading =
          jle::readForcePlate(plate, triple(cells, c, 0), triple(cells, c, 3));
      jle::applyPlateReaction(model_, data_, plate_frames_[p], plate, reading);
      const Eigen::Vector3d cop_world =
          reading.contact ? jle::copInWorld(plate, reading) : Eigen::Vector3d::Zero();
      *cop++ = reading.contact ? 1.0 : 0.0;
      for (int i = 0; i < 3; ++i) *cop++ = cop_world[i];
    }
  }

  // The --kinematics and --friction columns of the row, from `o` on.
  double* putOutputs(double* o) const {
    if (options_.kinematics)
      for (int s : model_.moving_segments) {
        *o++ = data_.q[s];
        *o++ = data_.qd[s];
        *o++ = data_.qdd[s];
      }
    if (options_.friction)
      for (int s : model_.moving_segments)
        *o++ = data_.effort[s] + jle::frictionEffort(model_.damping[s], model_.friction[s],
                                                     data_.qd[s], options_.velocity_scale);
    return o;
  }

  // One output row, in the order of names().
  void writeLoads(const Row& row, Output& out) {
    const std::vector<double>& cells = row.cells;
    const auto put = [](const jle::Wrench<double>& w, double* o) {
      for (int i = 0; i < 3; ++i) *o++ = w.force[i];
      for (int i = 0; i < 3; ++i) *o++ = w.moment[i];
      return o;
    };
    double* o = loads_.data();
    *o++ = cells[columns_.t];
    if (model_.floating_base)
      o = put(jle::jointWrench(model_, data_, 0, jle::WrenchFrame::kWorld), o);
    for (int s : model_.moving_segments) {
      o = put(jle::jointWrench(model_, data_, s, options_.frame), o);
      *o++ = data_.effort[s];
      if (options_.per_kg) *o++ = data_.effort[s] / mass_;
    }
    o = putOutputs(o);
    for (double x : cop_) *o++ = x;
    assert(static_cast<std::size_t>(o - loads_.data()) == loads_.size());
    checkLoads(row);
    out.row(loads_);
  }

  // Loads that are not finite are never written (a data error naming the row); efforts
  // beyond plausibility/effort_factor times the URDF effort limit are counted, said at
  // the end (finish()).
  void checkLoads(const Row& row) {
    for (double x : loads_)
      if (!std::isfinite(x))
        throw std::runtime_error(options_.input + ":" + std::to_string(row.line) +
                                 ": the loads are not finite (an absurd acceleration or "
                                 "wrench?): not written");
    static const jle::PlausibilityConfig p;
    for (int s : model_.moving_segments)
      if (jle::implausibleEffort(model_, p, static_cast<std::size_t>(s), data_.effort[s])) {
        if (implausible_++ == 0)
          first_implausible_ =
              "line " + std::to_string(row.line) + ", joint '" + model_.joint_name[s] + "'";
        break;
      }
  }

  const Options& options_;
  const jle::Model<double>& model_;
  const jle::StateColumns& columns_;
  jle::Data<double> data_;
  jle::VectorX<double> q_, qd_, qdd_;
  double mass_;
  bool estimate_;  // the base twist or acceleration estimated from the neighbouring rows
  Row window_[3];
  std::vector<int> plate_frames_;
  bool planar_ = false;  // --planar: the 3x3 solver is used
  jle::PlanarModel<double> planar_model_;
  jle::PlanarData<double> planar_data_;
  std::vector<int> segments_;  // every segment, for the planar passes
  std::vector<std::string> names_;
  std::vector<double> loads_, cop_;
  long implausible_ = 0;  // rows with an implausible effort
  std::string first_implausible_;
};

// The robot, with every --plate's link checked.
jle::Model<double> loadModel(const Options& options) {
  jle::ModelOptions model_options;
  model_options.floating_base = options.floating_base;
  model_options.accept_nonphysical_inertia = options.accept_nonphysical_inertia;
  jle::Model<double> model = jle::modelFromUrdfFile(options.urdf, model_options);
  for (const std::string& w : model.warnings)
    std::fprintf(stderr, "joint_loads: warning: robot model: %s\n", w.c_str());
  for (const jle::ForcePlateConfig& plate : options.plates) {
    bool known = false;
    for (const jle::Frame<double>& f : model.frames) known = known || f.name == plate.link;
    if (!known)
      throw UsageError("--plate " + plate.name + ": unknown link '" + plate.link + "' (not in " +
                       options.urdf + ")");
  }
  return model;
}

// A whole positions-only record, every row's cells; smoothPositions appends JOINT.qd and
// JOINT.qdd of every coordinate to them.
struct Record {
  std::vector<std::vector<double>> cells;
  std::vector<long> lines;
  std::vector<double> t;  // [s]
};

Record readRecord(jle::CsvReader& reader, const jle::Model<double>& model,
                  const jle::StateColumns& columns, const std::string& input) {
  Record r;
  while (reader.next()) {
    std::vector<double> cells(static_cast<std::size_t>(reader.columns()));
    reader.numbers(cells.data());
    checkPlausible(reader, model, columns, cells, r.cells.empty() ? nullptr : &r.cells.back());
    if (columns.base_pose[0] >= 0) checkBaseQuaternion(reader, columns, cells);
    const double t = cells[columns.t];
    if (!r.t.empty() && !(t > r.t.back()))
      reader.failAt(columns.t, "time does not increase (the previous row's is " +
                                   shortest(r.t.back()) +
                                   "): positions only are smoothed over the times");
    r.t.push_back(t);
    r.cells.push_back(std::move(cells));
    r.lines.push_back(reader.line());
  }
  if (r.t.size() < 3)
    throw std::runtime_error(input + ": " + std::to_string(r.t.size()) +
                             " rows; smoothing and differentiating positions needs at least 3");
  return r;
}

// The columns of the record (indices into the cells) as samples x channels, and back.
Eigen::MatrixXd gather(const Record& r, const std::vector<int>& columns) {
  Eigen::MatrixXd x(r.cells.size(), columns.size());
  for (std::size_t i = 0; i < r.cells.size(); ++i)
    for (std::size_t c = 0; c < columns.size(); ++c) x(i, c) = r.cells[i][columns[c]];
  return x;
}

void scatter(const Eigen::MatrixXd& x, const std::vector<int>& columns, Record& r) {
  for (std::size_t i = 0; i < r.cells.size(); ++i)
    for (std::size_t c = 0; c < columns.size(); ++c) r.cells[i][columns[c]] = x(i, c);
}

// Every wrench@ and plate@ column: the forces, filtered like the kinematics.
std::vector<int> forceColumns(const jle::StateColumns& columns) {
  std::vector<int> forces;
  for (const jle::StateColumns::WrenchColumns& w : columns.wrenches)
    forces.insert(forces.end(), w.column.begin(), w.column.end());
  for (const std::array<int, 6>& plate : columns.plates)
    forces.insert(forces.end(), plate.begin(), plate.end());
  return forces;
}

// A floating base's pose smoothed with the joints' cutoff (the quaternion's sign made
// continuous first: q and -q are one turn), its twist and acceleration (world frame)
// from the smoothed pose's rates, appended to every row and `columns` pointed at them.
// With u = q / |q|: omega = 2 vec(q' q*) / |q|^2, alpha = 2 (vec(q'' q*) - (q . q')
// omega) / |q|^2 (the filter leaves |q| a little off 1).
void smoothBase(const Options& options, jle::StateColumns& columns, Record& r, double cutoff) {
  const auto& c = columns.base_pose;
  for (std::size_t i = 1; i < r.cells.size(); ++i) {
    double dot = 0.0;
    for (int k = 3; k < 7; ++k) dot += r.cells[i][c[k]] * r.cells[i - 1][c[k]];
    if (dot < 0.0)
      for (int k = 3; k < 7; ++k) r.cells[i][c[k]] = -r.cells[i][c[k]];
  }
  jle::ZeroPhaseConfig z = options.smoothing;
  z.rule = jle::CutoffRule::kFixed;
  z.cutoff = cutoff;
  const std::vector<int> pose(c.begin(), c.end());
  const jle::ZeroPhaseResult k = jle::smoothZeroPhase(r.t, gather(r, pose), z);
  const std::size_t width = r.cells.front().size();
  for (std::size_t j = 0; j < 6; ++j) {
    columns.base_twist[j] = static_cast<int>(width + j);
    columns.base_acceleration[j] = static_cast<int>(width + 6 + j);
  }
  const auto quaternion = [](const Eigen::MatrixXd& m, Eigen::Index i) {
    return Eigen::Quaterniond(m(i, 6), m(i, 3), m(i, 4), m(i, 5));
  };
  for (std::size_t i = 0; i < r.cells.size(); ++i) {
    const Eigen::Index row = static_cast<Eigen::Index>(i);
    const Eigen::Quaterniond q = quaternion(k.value, row), qd = quaternion(k.rate, row),
                             qdd = quaternion(k.accel, row);
    const double n2 = q.squaredNorm();
    const Eigen::Vector3d w = 2.0 * (qd * q.conjugate()).vec() / n2;
    const Eigen::Vector3d alpha =
        2.0 * ((qdd * q.conjugate()).vec() - q.coeffs().dot(qd.coeffs()) * w) / n2;
    std::vector<double>& cells = r.cells[i];
    cells.resize(width + 12);
    for (int j = 0; j < 3; ++j) {
      cells[c[j]] = k.value(row, j);
      cells[width + j] = k.rate(row, j);
      cells[width + 3 + j] = w[j];
      cells[width + 6 + j] = k.accel(row, j);
      cells[width + 9 + j] = alpha[j];
    }
    const Eigen::Quaterniond unit = q.normalized();
    for (int j = 0; j < 4; ++j) cells[c[3 + j]] = unit.coeffs()[j];  // x, y, z, w
  }
}

// q and the forces smoothed alike (the JOINT.qd columns, if any, as the cutoff rule's
// evidence; the force columns as channels filtered alike, which may raise it), q's rate
// and acceleration appended to every row and `columns` pointed at them. Returns how the
// cutoff was chosen.
jle::CutoffChoice smoothPositions(const Options& options, jle::StateColumns& columns, Record& r) {
  const jle::ZeroPhaseConfig& z = options.smoothing;
  const std::size_t width = r.cells.front().size(), nq = columns.q.size();
  const bool measured =
      std::all_of(columns.qd.begin(), columns.qd.end(), [](int c) { return c >= 0; });
  try {
    const std::vector<int> forces = forceColumns(columns);
    std::vector<jle::FilteredAlike> alike;
    if (!forces.empty()) alike.push_back({r.t, gather(r, forces), "the wrench and plate columns"});
    const jle::ZeroPhaseResult k = jle::smoothZeroPhase(
        r.t, gather(r, columns.q), z, measured ? gather(r, columns.qd) : Eigen::MatrixXd(), alike);
    for (std::size_t j = 0; j < nq; ++j) {
      columns.qd[j] = static_cast<int>(width + j);
      columns.qdd[j] = static_cast<int>(width + nq + j);
    }
    for (std::vector<double>& cells : r.cells) cells.resize(width + 2 * nq);
    scatter(k.value, columns.q, r);
    scatter(k.rate, columns.qd, r);
    scatter(k.accel, columns.qdd, r);
    if (!forces.empty())
      scatter(jle::lowPassZeroPhase(r.t, alike.front().x, k.cutoff, z.order, z.padding), forces, r);
    if (columns.base_pose[0] >= 0) smoothBase(options, columns, r, k.cutoff);
    return k.choice;
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(options.input + ": smoothing the positions (--cutoff): " + e.what());
  }
}

// --write-kinematics: the smoothed record as a joint-state CSV (stateColumnNames' order).
void writeKinematics(const Options& options, const jle::Model<double>& model,
                     const jle::StateColumns& columns, const Record& r) {
  std::vector<std::string> links;
  std::vector<int> order{columns.t};
  for (int k = 0; k < model.nq; ++k)
    order.insert(order.end(), {columns.q[k], columns.qd[k], columns.qdd[k]});
  for (const jle::StateColumns::WrenchColumns& w : columns.wrenches) {
    links.push_back(w.link);
    order.insert(order.end(), w.column.begin(), w.column.end());
  }
  if (model.floating_base) {  // the smoothed pose, its twist and acceleration
    order.insert(order.end(), columns.base_pose.begin(), columns.base_pose.end());
    order.insert(order.end(), columns.base_twist.begin(), columns.base_twist.end());
    order.insert(order.end(), columns.base_acceleration.begin(), columns.base_acceleration.end());
  }
  for (const std::array<int, 6>& plate : columns.plates)
    order.insert(order.end(), plate.begin(), plate.end());
  jle::ExtraStateInputs extra;
  extra.floating_base = model.floating_base;
  for (const jle::ForcePlateConfig& plate : options.plates) extra.plates.push_back(plate.name);
  jle::CsvWriter out(options.write_kinematics);
  out.writeHeader(jle::stateColumnNames(model, links, extra));
  std::vector<double> row(order.size());
  for (const std::vector<double>& cells : r.cells) {
    for (std::size_t i = 0; i < order.size(); ++i) row[i] = cells[order[i]];
    out.writeRow(row.data(), row.size());
  }
  out.commit();
}

// A CSV of positions only: the whole record read, smoothed and differentiated, then the
// loads of every row as for a CSV with JOINT.qd, JOINT.qdd.
void runPositionsOnly(const Options& options, const jle::Model<double>& model,
                      jle::CsvReader& reader, jle::StateColumns columns) {
  if (columns.hasBaseTwist() || columns.hasBaseAcceleration())
    throw std::runtime_error(options.input +
                             ": positions only (no JOINT.qd, JOINT.qdd): the floating base's "
                             "twist and acceleration are computed from its smoothed pose like "
                             "the joints' rates; leave out base.vx ... base.alz, or give "
                             "JOINT.qd and JOINT.qdd of every joint");
  Record record = readRecord(reader, model, columns, options.input);
  const jle::CutoffChoice choice = smoothPositions(options, columns, record);
  std::fprintf(stderr,
               "joint_loads: positions only: zero-phase Butterworth, order %d per pass, "
               "cutoff %.17g Hz (%s)\n",
               options.smoothing.order, choice.cutoff, jle::toString(choice.rule));
  for (const std::string& warning : choice.warnings)
    std::fprintf(stderr, "joint_loads: warning: %s\n", warning.c_str());
  if (!options.write_kinematics.empty()) writeKinematics(options, model, columns, record);
  Processor processor(options, model, columns, record.cells.front().size());
  Output out(options, model, processor.names());
  long n = 0;
  for (; n < static_cast<long>(record.cells.size()); ++n) {
    processor.take(record.cells[n], record.lines[n], n);
    processor.emitReady(n, out);
  }
  processor.finish(n, out);
  out.commit();
}

void run(const Options& options) {
  const jle::Model<double> model = loadModel(options);
  jle::CsvReader reader(options.input);
  jle::ExtraStateInputs extra;
  extra.floating_base = model.floating_base;
  // Positions only: JOINT.q alone (a floating base's pose smoothed and differentiated
  // with the joints).
  extra.positions_only = true;
  for (const jle::ForcePlateConfig& plate : options.plates) extra.plates.push_back(plate.name);
  const jle::StateColumns columns = jle::bindStateColumns(model, reader, extra);
  if (columns.positions_only) return runPositionsOnly(options, model, reader, columns);
  if (options.smoothing_given)
    throw std::runtime_error(options.input +
                             ": --cutoff, --cutoff-rule, --filter-order and --write-kinematics "
                             "are for a CSV of positions only (this one has JOINT.qd, JOINT.qdd)");

  // Everything the loop touches is allocated here, once.
  Processor processor(options, model, columns, static_cast<std::size_t>(reader.columns()));
  Output out(options, model, processor.names());
  long n = 0;
  for (; reader.next(); ++n) {
    processor.read(reader, n);
    processor.emitReady(n, out);
  }
  processor.finish(n, out);
  out.commit();
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "joint_loads", kUsage, parseOptions, run);
}
