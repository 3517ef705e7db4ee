// joint_loads: the joint wrenches and efforts of a URDF robot along a CSV of joint
// states (and applied wrenches), one output row per input row. docs/joint_loads.md.
#include <joint_load_estimator/base_motion.hpp>
#include <joint_load_estimator/command_line.hpp>
#include <joint_load_estimator/csv.hpp>
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/force_plate.hpp>
#include <joint_load_estimator/kinematics.hpp>
#include <joint_load_estimator/sto.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cassert>
#include <memory>

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
    R"(usage: joint_loads --urdf ROBOT.urdf --input STATES.csv [--output LOADS]
                   [--gravity GX,GY,GZ] [--frame child|parent|world]
                   [--floating-base] [--plate NAME=LINK,X,Y,Z[,YAW_DEG]]...
                   [--contact-threshold N] [--per-kg [--body-mass KG]]
                   [--format csv|sto]

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
                                               if present: a mimic follows its leader)
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
  --gravity G      gravity in the world (root link) frame [m/s^2], default 0,0,-9.80665
  --frame F        the frame of the output joint wrenches: child (the joint's child
                   link, default), parent (the joint's URDF parent link) or world
  --floating-base  the URDF's root link floats: its pose is read from base.* columns
  --plate NAME=LINK,X,Y,Z[,YAW_DEG]
                   a force plate (repeatable): its frame (z up, the contact surface
                   through its origin) at X,Y,Z [m] in the world, turned by YAW_DEG
                   about the world z axis; the foot LINK stands on it and receives the
                   reaction at the centre of pressure
  --contact-threshold N
                   plate force [N] below which a foot is not in contact (default 20)
  --per-kg         also JOINT.effort_per_kg = effort / body mass [N m/kg, N/kg]
  --body-mass KG   the body mass for --per-kg (default: the URDF's total mass)
  --format F       csv (default) or sto (OpenSim storage file, docs/joint_loads.md)
  --help           this text

Output: t; with a floating base base.fx,.fy,.fz,.mx,.my,.mz (what the world must
apply to the root link: world frame, moment about the root link origin; zero when
the measured loads explain the motion); for every moving joint in URDF tree order
(depth first from the root, children in document order; mimic joints included)
JOINT.fx,JOINT.fy,JOINT.fz,JOINT.mx,JOINT.my,JOINT.mz,JOINT.effort
[,JOINT.effort_per_kg]; for every plate plate@NAME.contact (1 or 0) and
plate@NAME.cop_x,.cop_y,.cop_z (centre of pressure in the world [m], 0 without
contact). Every number with 17 significant digits (%.17g).

Exit status: 0 success; 1 a data error (a file that cannot be read or written, a
URDF the model refuses, a CSV defect: the message names FILE:LINE and the column);
2 a usage error (an unknown, missing or repeated option, a bad option value, a
--plate on an unknown link).
)";

struct Options {
  std::string urdf, input, output;
  Eigen::Vector3d gravity_world{0.0, 0.0, -9.80665};
  jle::WrenchFrame frame = jle::WrenchFrame::kChild;
  bool floating_base = false;
  std::vector<jle::ForcePlateConfig> plates;
  double contact_threshold = 20.0;
  bool per_kg = false;
  double body_mass = 0.0;  // 0: the model's total mass
  bool sto = false;
};

// Parses "A,B,C..." into `count` finite numbers (blanks around them accepted).
bool parseNumbers(const char* s, int count, double* out) {
  for (int i = 0; i < count; ++i) {
    char* end = nullptr;
    out[i] = std::strtod(s, &end);
    while (end != s && (*end == ' ' || *end == '\t')) ++end;
    const char expected = i + 1 < count ? ',' : '\0';
    if (end == s || *end != expected || !std::isfinite(out[i])) return false;
    s = end + (i + 1 < count ? 1 : 0);
  }
  return true;
}

Eigen::Vector3d parseGravity(const std::string& text) {
  Eigen::Vector3d g;
  if (!parseNumbers(text.c_str(), 3, g.data()))
    throw UsageError("--gravity: '" + text + "' is not GX,GY,GZ (three finite numbers, m/s^2)");
  return g;
}

jle::WrenchFrame parseFrame(const std::string& text) {
  if (text == "child") return jle::WrenchFrame::kChild;
  if (text == "parent") return jle::WrenchFrame::kParent;
  if (text == "world") return jle::WrenchFrame::kWorld;
  throw UsageError("--frame: '" + text + "' is not child, parent or world");
}

double parsePositive(const std::string& key, const std::string& text, bool zero_allowed) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(value) || value < 0.0 ||
      (!zero_allowed && value == 0.0))
    throw UsageError(key + ": '" + text + "' is not a " +
                     (zero_allowed ? "finite number >= 0" : "finite number > 0"));
  return value;
}

// NAME=LINK,x,y,z[,yaw_deg]: a plate frame (z up) at (x, y, z) in the world, turned by
// yaw about the world z axis.
jle::ForcePlateConfig parsePlate(const std::string& text) {
  const std::string what =
      "--plate: '" + text + "' is not NAME=LINK,X,Y,Z[,YAW_DEG] (NAME and LINK without '=', ',', '.' or blanks; finite numbers)";
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
  if ((count != 3 && count != 4) || !parseNumbers(numbers.c_str(), count, v))
    throw UsageError(what);
  plate.p_world_plate = Eigen::Vector3d(v[0], v[1], v[2]);
  plate.R_world_plate =
      Eigen::AngleAxisd(v[3] * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return plate;
}

Options parseOptions(int argc, char** argv) {
  // --plate may be repeated: collect its values before the shared parser (each other
  // option once).
  std::vector<std::string> plates;
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--plate") {
      if (i + 1 >= argc) throw UsageError("--plate needs a value");
      plates.push_back(argv[++i]);
    } else if (arg.compare(0, 8, "--plate=") == 0) {
      plates.push_back(arg.substr(8));
    } else {
      rest.push_back(argv[i]);
    }
  }
  std::map<std::string, std::string> v = optionValues(
      static_cast<int>(rest.size()), rest.data(),
      {"--urdf", "--input", "--output", "--gravity", "--frame", "--contact-threshold",
       "--body-mass", "--format"},
      {"--floating-base", "--per-kg"});
  Options options;
  if (!v.count("--urdf")) throw UsageError("--urdf ROBOT.urdf is required");
  if (!v.count("--input")) throw UsageError("--input STATES.csv is required");
  options.urdf = v["--urdf"];
  options.input = v["--input"];
  if (v.count("--output")) options.output = v["--output"];
  if (v.count("--gravity")) options.gravity_world = parseGravity(v["--gravity"]);
  if (v.count("--frame")) options.frame = parseFrame(v["--frame"]);
  options.floating_base = v.count("--floating-base") > 0;
  if (v.count("--contact-threshold"))
    options.contact_threshold =
        parsePositive("--contact-threshold", v["--contact-threshold"], true);
  for (const std::string& text : plates) {
    if (text.empty()) throw UsageError("--plate: empty value");
    jle::ForcePlateConfig plate = parsePlate(text);
    for (const jle::ForcePlateConfig& other : options.plates)
      if (other.name == plate.name) throw UsageError("--plate: plate '" + plate.name + "' is given twice");
    plate.contact_threshold = options.contact_threshold;
    options.plates.push_back(plate);
  }
  options.per_kg = v.count("--per-kg") > 0;
  if (v.count("--body-mass")) {
    if (!options.per_kg) throw UsageError("--body-mass is only used with --per-kg");
    options.body_mass = parsePositive("--body-mass", v["--body-mass"], false);
  }
  if (v.count("--format")) {
    if (v["--format"] == "sto")
      options.sto = true;
    else if (v["--format"] != "csv")
      throw UsageError("--format: '" + v["--format"] + "' is not csv or sto");
  }
  return options;
}

// The output, CSV or OpenSim storage.
class Output {
 public:
  Output(const Options& options, const jle::Model<double>& model,
         const std::vector<std::string>& names) {
    if (options.sto) {
      sto_ = std::make_unique<jle::StoWriter>(options.output);
      sto_->writeHeader(jle::stoColumnNames(model, names, options.frame));
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
    if (sto_) sto_->commit();
    else csv_->commit();
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

class Processor {
 public:
  Processor(const Options& options, const jle::Model<double>& model, const jle::StateColumns& columns,
            std::size_t cells)
      : options_(options),
        model_(model),
        columns_(columns),
        data_(model),
        q_(model.nq),
        qd_(model.nq),
        qdd_(model.nq),
        mass_(options.body_mass > 0.0 ? options.body_mass : model.totalMass()) {
    for (Row& r : window_) r.cells.resize(cells);
    for (const jle::ForcePlateConfig& plate : options.plates) {
      const int frame = model.frameIndex(plate.link);
      plate_frames_.push_back(frame);
    }
    names_ = outputColumns();
    loads_.resize(names_.size());
  }

  const std::vector<std::string>& names() const { return names_; }

  // The next input row's slot (its cells are read into it by the caller).
  Row& slot(long index) { return window_[static_cast<std::size_t>(index % 3)]; }

  // Row `index` (its window: the rows index - m ... index - m + 2) to the output.
  void emit(long index, int m, Output& out) {
    const Row& row = slot(index);
    const std::vector<double>& cells = row.cells;
    for (int k = 0; k < model_.nq; ++k) {
      q_[k] = cells[columns_.q[k]];
      qd_[k] = cells[columns_.qd[k]];
      qdd_[k] = cells[columns_.qdd[k]];
    }
    jle::BaseState<double> base;
    if (model_.floating_base) {
      base.R_world_base = row.pose.R_world_base;
      base.p_world_base = row.pose.p_world_base;
      const auto& tw = columns_.base_twist;
      const auto& ac = columns_.base_acceleration;
      if (columns_.hasBaseTwist()) {
        base.v_world = Eigen::Vector3d(cells[tw[0]], cells[tw[1]], cells[tw[2]]);
        base.omega_world = Eigen::Vector3d(cells[tw[3]], cells[tw[4]], cells[tw[5]]);
      }
      if (columns_.hasBaseAcceleration()) {
        base.a_world = Eigen::Vector3d(cells[ac[0]], cells[ac[1]], cells[ac[2]]);
        base.alpha_world = Eigen::Vector3d(cells[ac[3]], cells[ac[4]], cells[ac[5]]);
      }
      if (m >= 0) {
        const long first = index - m;
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
            v[j] = Eigen::Vector3d(c[tw[0]], c[tw[1]], c[tw[2]]);
            w[j] = Eigen::Vector3d(c[tw[3]], c[tw[4]], c[tw[5]]);
          }
          jle::baseAccelerationFromTwists(t, m, v, w, base);
        }
      }
    }
    jle::forwardKinematics(model_, data_, q_, qd_, qdd_, options_.gravity_world, base);
    for (const jle::StateColumns::WrenchColumns& w : columns_.wrenches) {
      const auto& c = w.column;
      jle::addExternalWrench(
          model_, data_, w.frame, Eigen::Vector3d(cells[c[0]], cells[c[1]], cells[c[2]]),
          Eigen::Vector3d(cells[c[3]], cells[c[4]], cells[c[5]]), jle::WrenchFrame::kLocal);
    }
    double* cop = cop_.data();
    for (std::size_t p = 0; p < options_.plates.size(); ++p) {
      const jle::ForcePlateConfig& plate = options_.plates[p];
      const auto& c = columns_.plates[p];
      const jle::PlateReading reading =
          jle::readForcePlate(plate, Eigen::Vector3d(cells[c[0]], cells[c[1]], cells[c[2]]),
                              Eigen::Vector3d(cells[c[3]], cells[c[4]], cells[c[5]]));
      *cop++ = reading.contact ? 1.0 : 0.0;
      if (!reading.contact) {
        for (int i = 0; i < 3; ++i) *cop++ = 0.0;
        continue;
      }
      const jle::Frame<double>& foot = model_.frames[plate_frames_[p]];
      const Eigen::Vector3d foot_world =
          data_.p_world[foot.segment] + data_.R_world[foot.segment] * foot.p_segment_frame;
      Eigen::Vector3d force_world, moment_world;
      jle::plateReactionInWorld(plate, reading, foot_world, force_world, moment_world);
      jle::addExternalWrench(model_, data_, plate_frames_[p], force_world, moment_world,
                             jle::WrenchFrame::kWorld);
      const Eigen::Vector3d cop_world = plate.p_world_plate + plate.R_world_plate * reading.cop_plate;
      for (int i = 0; i < 3; ++i) *cop++ = cop_world[i];
    }
    jle::inverseDynamics(model_, data_);

    double* o = loads_.data();
    *o++ = cells[columns_.t];
    if (model_.floating_base) {
      const jle::Wrench<double> w = jle::jointWrench(model_, data_, 0, jle::WrenchFrame::kWorld);
      for (int i = 0; i < 3; ++i) *o++ = w.force[i];
      for (int i = 0; i < 3; ++i) *o++ = w.moment[i];
    }
    for (int s : model_.moving_segments) {
      const jle::Wrench<double> w = jle::jointWrench(model_, data_, s, options_.frame);
      for (int i = 0; i < 3; ++i) *o++ = w.force[i];
      for (int i = 0; i < 3; ++i) *o++ = w.moment[i];
      *o++ = data_.effort[s];
      if (options_.per_kg) *o++ = data_.effort[s] / mass_;
    }
    for (double x : cop_) *o++ = x;
    assert(static_cast<std::size_t>(o - loads_.data()) == loads_.size());
    out.row(loads_);
  }

 private:
  std::vector<std::string> outputColumns() {
    std::vector<std::string> names{"t"};
    if (model_.floating_base)
      for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"}) names.push_back(std::string("base.") + c);
    for (int s : model_.moving_segments) {
      for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz", "effort"})
        names.push_back(model_.joint_name[s] + "." + c);
      if (options_.per_kg) names.push_back(model_.joint_name[s] + ".effort_per_kg");
    }
    for (const jle::ForcePlateConfig& plate : options_.plates)
      for (const char* c : {"contact", "cop_x", "cop_y", "cop_z"})
        names.push_back("plate@" + plate.name + "." + c);
    cop_.assign(4 * options_.plates.size(), 0.0);
    return names;
  }

  const Options& options_;
  const jle::Model<double>& model_;
  const jle::StateColumns& columns_;
  jle::Data<double> data_;
  jle::VectorX<double> q_, qd_, qdd_;
  double mass_;
  Row window_[3];
  std::vector<int> plate_frames_;
  std::vector<std::string> names_;
  std::vector<double> loads_, cop_;
};

std::string shortest(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

// The base pose of the current record, checked: a quaternion of norm 1 within 1 %.
void readBasePose(const jle::CsvReader& reader, const jle::StateColumns& columns, Row& row) {
  const auto& c = columns.base_pose;
  const std::vector<double>& x = row.cells;
  row.pose.t = x[columns.t];
  row.pose.p_world_base = Eigen::Vector3d(x[c[0]], x[c[1]], x[c[2]]);
  Eigen::Quaterniond q(x[c[6]], x[c[3]], x[c[4]], x[c[5]]);
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= 0.01))
    reader.failAt(c[6], "the quaternion (base.qx, .qy, .qz, .qw) has norm " +
                            std::to_string(norm) + ", not 1 (within 1 %)");
  q.coeffs() /= norm;
  row.pose.R_world_base = q.toRotationMatrix();
}

void run(const Options& options) {
  jle::ModelOptions model_options;
  model_options.floating_base = options.floating_base;
  const jle::Model<double> model = jle::modelFromUrdfFile(options.urdf, model_options);
  for (const jle::ForcePlateConfig& plate : options.plates) {
    bool known = false;
    for (const jle::Frame<double>& f : model.frames) known = known || f.name == plate.link;
    if (!known)
      throw UsageError("--plate " + plate.name + ": unknown link '" + plate.link + "' (not in " +
                       options.urdf + ")");
  }
  jle::CsvReader reader(options.input);
  jle::ExtraStateInputs extra;
  extra.floating_base = model.floating_base;
  for (const jle::ForcePlateConfig& plate : options.plates) extra.plates.push_back(plate.name);
  const jle::StateColumns columns = jle::bindStateColumns(model, reader, extra);
  // The base twist or acceleration estimated from the neighbouring rows.
  const bool estimate =
      model.floating_base && !(columns.hasBaseTwist() && columns.hasBaseAcceleration());

  // Everything the loop touches is allocated here, once.
  Processor processor(options, model, columns, static_cast<std::size_t>(reader.columns()));
  Output out(options, model, processor.names());
  long n = 0;
  while (reader.next()) {
    Row& row = processor.slot(n);
    reader.numbers(row.cells.data());
    row.line = reader.line();
    if (model.floating_base) readBasePose(reader, columns, row);
    if (estimate && n > 0 && !(row.cells[columns.t] > processor.slot(n - 1).cells[columns.t]))
      reader.failAt(columns.t, "time does not increase (the previous row's is " +
                                   shortest(processor.slot(n - 1).cells[columns.t]) +
                                   "): the base motion is estimated from the times");
    if (!estimate) {
      processor.emit(n, -1, out);
    } else if (n == 2) {
      processor.emit(0, 0, out);
      processor.emit(1, 1, out);
    } else if (n > 2) {
      processor.emit(n - 1, 1, out);
    }
    ++n;
  }
  if (estimate) {
    if (n > 0 && n < 3)
      throw std::runtime_error(options.input + ": " + std::to_string(n) +
                               " rows; estimating the base twist and acceleration from the "
                               "pose needs at least 3 (or give base.vx ... base.alz)");
    if (n >= 3) {
      processor.emit(n - 1, 2, out);
    }
  }
  out.commit();
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "joint_loads", kUsage, parseOptions, run);
}
