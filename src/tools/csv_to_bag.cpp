// csv_to_bag: a trial in joint_loads' CSV columns (docs/joint_loads.md) as a bag of
// sensor_msgs/JointState, geometry_msgs/WrenchStamped and /tf, so that it can be played
// to the node or given to process_bag. docs/data_in_out.md.
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/io/csv.hpp>
#include <joint_load_estimator/io/portable_random.hpp>

#include "bag_writing.hpp"

#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace jle::cli;  // command_line.hpp: UsageError, optionValues, the parsers

const char* const kUsage =
    R"(usage: csv_to_bag --input STATES.csv --output OUT.bag
                  [--plate NAME=LINK,X,Y,Z[,YAW_DEG]]... [--world-frame world]
                  [--base-frame base_link] [--time-offset S] [--jitter S [--seed N]]

Writes a trial in joint_loads' input columns (docs/joint_loads.md) as a bag for the
node or process_bag (docs/data_in_out.md):
  JOINT.q [, JOINT.qd]   /joint_states, sensor_msgs/JointState: every JOINT of the
                         file in column order, position (and velocity if every JOINT
                         has a .qd column; JOINT.qdd columns are not carried: a
                         JointState has no acceleration)
  wrench@LINK.fx .. .mz  /wrench/LINK, geometry_msgs/WrenchStamped, frame_id LINK
                         (a wrench applied TO the robot at LINK's origin, LINK's frame:
                         the node's wrenches entry {topic: /wrench/LINK, link: LINK})
  plate@NAME.fx .. .mz   /force_plate/NAME, geometry_msgs/WrenchStamped, frame_id NAME
                         (what the foot applies to the plate); with --plate NAME=...,
                         world -> NAME on /tf_static (latched, the first stamp)
  base.x .. base.qw      /tf, world -> base frame (the floating base's pose); base
                         twist and acceleration columns are not carried (the node
                         estimates them)
One message per row and topic, header.seq counting from 0; bag time = the stamp, the
inputs of a row 1 us before its joint state (a reader in bag order, as the node under
rosbag play or process_bag, has an instant's inputs when its joint state comes), and
every message at its own stamp with --jitter (its reception).

  --input PATH       the CSV (joint_loads' input; t [s] increasing)
  --output PATH      the bag; written beside PATH and renamed onto it on success only
  --plate NAME=LINK,X,Y,Z[,YAW_DEG]
                     repeatable, joint_loads' syntax: the pose of plate NAME in the
                     world (z up; X, Y, Z [m] and YAW_DEG finite); LINK is not used
                     here (the node's force_plates entry names it)
  --world-frame F    default world
  --base-frame F     the tf child of the base pose (default base_link): the URDF's
                     root link
  --time-offset S    [s] stamps are t + S (default 0); every stamp must be > 0 and
                     below 4294967295 s (ROS time); a stamp of 0 would mean "unstamped"
  --jitter J         [s], >= 0 (default 0: stamps are the rows' instants): real-log
                     receive-time stamps: each message is stamped (and written at
                     bag time) t + S + U[0, J) (uniform, seeded, drawn per message),
                     as a driver that stamps at reception; J below the spacing of t
                     keeps every topic in order (a stamp that does not increase is
                     refused, naming the line)
  --seed N           of --jitter, 0 .. 4294967295 (default 1; jle::PortableRandom)
  --help             this text

Exit status: 0 success; 1 a data error (an unreadable CSV or a defect in it, naming
FILE:LINE and the column; an unwritable bag); 2 a usage error.
)";

struct PlatePose {
  std::string name;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  double yaw = 0.0;  // [rad] about the world z axis
};

struct Options {
  std::string input, output, world = "world", base = "base_link";
  std::vector<PlatePose> plates;
  double time_offset = 0.0, jitter = 0.0;
  std::uint32_t seed = 1;
};

// joint_loads' --plate syntax, NAME=LINK,X,Y,Z[,YAW_DEG].
PlatePose parsePlate(const std::string& text) {
  const std::string what = "--plate: '" + text + "' is not NAME=LINK,X,Y,Z[,YAW_DEG]";
  const std::size_t eq = text.find('='), comma = text.find(',', eq == std::string::npos ? 0 : eq);
  if (eq == std::string::npos || eq == 0 || comma == std::string::npos) throw UsageError(what);
  PlatePose p;
  p.name = text.substr(0, eq);
  if (p.name.find_first_of(",. \t@") != std::string::npos) throw UsageError(what);
  const std::string numbers = text.substr(comma + 1);
  double v[4] = {0, 0, 0, 0};
  const int count = static_cast<int>(std::count(numbers.begin(), numbers.end(), ',')) + 1;
  if ((count != 3 && count != 4) || !parseNumberList(numbers, count, v)) throw UsageError(what);
  p.p_world = Eigen::Vector3d(v[0], v[1], v[2]);
  p.yaw = v[3] * M_PI / 180.0;
  return p;
}

Options parseOptions(int argc, char** argv) {
  std::vector<char*> rest;
  std::vector<std::string> plates;
  takeRepeatedOption(argc, argv, "--plate", plates, rest);
  std::map<std::string, std::string> v =
      optionValues(static_cast<int>(rest.size()), rest.data(),
                   {"--input", "--output", "--world-frame", "--base-frame", "--time-offset",
                    "--jitter", "--seed"});
  Options o;
  o.input = requiredValue(v, "--input", "STATES.csv");
  o.output = requiredValue(v, "--output", "OUT.bag");
  if (v.count("--world-frame")) o.world = v["--world-frame"];
  if (v.count("--base-frame")) o.base = v["--base-frame"];
  if (v.count("--time-offset")) o.time_offset = parseNumber("--time-offset", v["--time-offset"]);
  if (v.count("--jitter")) o.jitter = parseNumber("--jitter", v["--jitter"], Sign::kNonNegative);
  if (v.count("--seed")) {
    if (!v.count("--jitter")) throw UsageError("--seed is only used with --jitter");
    o.seed = static_cast<std::uint32_t>(parseInteger("--seed", v["--seed"], 0, 4294967295ULL));
  }
  for (const std::string& text : plates) {
    o.plates.push_back(parsePlate(text));
    for (std::size_t k = 0; k + 1 < o.plates.size(); ++k)
      if (o.plates[k].name == o.plates.back().name)
        throw UsageError("--plate: plate '" + o.plates.back().name + "' is given twice");
  }
  return o;
}

// ----------------------------------------------------------------------- the columns

// Where the file's quantities are: indices into a record.
struct Columns {
  int t = -1;
  std::vector<std::string> joints;
  std::vector<int> q, qd;  // qd empty: no velocities
  struct Wrench {
    std::string name;  // LINK or NAME
    bool plate = false;
    std::array<int, 6> c{};
  };
  std::vector<Wrench> wrenches;
  std::array<int, 7> base{};  // x y z qx qy qz qw; base[0] < 0: none
};

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The six columns PREFIX.fx .. PREFIX.mz of a wrench@ or plate@ column.
Columns::Wrench wrenchColumns(const jle::CsvReader& r, const std::string& prefix, bool plate) {
  Columns::Wrench w;
  w.name = prefix.substr(prefix.find('@') + 1);
  w.plate = plate;
  for (int k = 0; k < 6; ++k) {
    w.c[k] = r.column(prefix + "." + jle::kWrenchComponents[k]);
    if (w.c[k] < 0)
      r.failHeader("column '" + prefix + "." + jle::kWrenchComponents[k] +
                   "' is missing (a wrench has all six columns or none)");
  }
  return w;
}

Columns bindColumns(const jle::CsvReader& r, const Options& o) {
  Columns c;
  c.t = r.column("t");
  if (c.t < 0) r.failHeader("no column 't'");
  std::vector<std::string> wrench_prefixes;
  for (const std::string& name : r.header()) {
    if (endsWith(name, ".q") && name.find('@') == std::string::npos && name.rfind("base.", 0)) {
      c.joints.push_back(name.substr(0, name.size() - 2));
      c.q.push_back(r.column(name));
    }
    const std::size_t dot = name.rfind('.');
    const std::string prefix = name.substr(0, dot);
    if ((!prefix.rfind("wrench@", 0) || !prefix.rfind("plate@", 0)) &&
        std::find(wrench_prefixes.begin(), wrench_prefixes.end(), prefix) == wrench_prefixes.end())
      wrench_prefixes.push_back(prefix);
  }
  if (c.joints.empty()) r.failHeader("no JOINT.q column");
  int velocities = 0;
  for (const std::string& j : c.joints) velocities += r.column(j + ".qd") >= 0;
  if (velocities > 0 && velocities < static_cast<int>(c.joints.size()))
    r.failHeader("some JOINT.qd columns but not one for every JOINT.q (give all or none)");
  for (std::size_t k = 0; velocities && k < c.joints.size(); ++k)
    c.qd.push_back(r.column(c.joints[k] + ".qd"));
  for (const std::string& prefix : wrench_prefixes)
    c.wrenches.push_back(wrenchColumns(r, prefix, prefix.rfind("plate@", 0) == 0));
  const char* base[7] = {"base.x", "base.y", "base.z", "base.qx", "base.qy", "base.qz", "base.qw"};
  int found = 0;
  for (int k = 0; k < 7; ++k) found += (c.base[k] = r.column(base[k])) >= 0;
  if (found != 0 && found != 7) r.failHeader("the base pose needs base.x .. base.qw, all seven");
  if (found == 0) c.base[0] = -1;
  for (const PlatePose& p : o.plates) {
    bool known = false;
    for (const Columns::Wrench& w : c.wrenches) known = known || (w.plate && w.name == p.name);
    if (!known)
      throw UsageError("--plate " + p.name + ": the CSV has no plate@" + p.name + " columns");
  }
  return c;
}

// ------------------------------------------------------------------------- the bag

class BagWriter {
 public:
  BagWriter(const Options& o, const Columns& c)
      : o_(o), c_(c), bag_(o.output), random_(o.seed), last_(c.wrenches.size() + 2, -1) {}

  // One record, the row's time t [s].
  // One record, the row's time t [s]: its wrenches, plates and base pose first, then its
  // joint state, so that a reader in bag order has an instant's inputs before its joint
  // state (without --jitter they are written 1 us before it in bag time).
  void row(const jle::CsvReader& r, const std::vector<double>& x, long n) {
    const double t = x[c_.t];
    if (n == 0) staticPlates(r, t);
    for (std::size_t w = 0; w < c_.wrenches.size(); ++w) {
      const Columns::Wrench& cw = c_.wrenches[w];
      geometry_msgs::WrenchStamped m;
      m.header.seq = static_cast<std::uint32_t>(n);
      m.header.stamp = stamp(r, t, w + 1);
      m.header.frame_id = cw.name;
      const auto at = [&](int k) { return x[cw.c[k]]; };
      jle_tools::setWrench(m, Eigen::Vector3d(at(0), at(1), at(2)),
                           Eigen::Vector3d(at(3), at(4), at(5)));
      bag_.bag().write((cw.plate ? "/force_plate/" : "/wrench/") + cw.name,
                       inputTime(m.header.stamp), m);
    }
    if (c_.base[0] >= 0) basePose(r, x, n, t);
    sensor_msgs::JointState js;
    js.header.seq = static_cast<std::uint32_t>(n);
    js.header.stamp = stamp(r, t, 0);
    js.name = c_.joints;
    for (int k : c_.q) js.position.push_back(x[k]);
    for (int k : c_.qd) js.velocity.push_back(x[k]);
    bag_.bag().write("/joint_states", js.header.stamp, js);
  }

  void commit() { bag_.commit(); }

 private:
  // The stamp of a message of topic `topic` (0: joint states; last: the base pose) for
  // the instant t: t + offset, plus the receive-time jitter; in order per topic.
  ros::Time stamp(const jle::CsvReader& r, double t, std::size_t topic) {
    double s = t + o_.time_offset;
    if (o_.jitter > 0.0) s += random_.uniform(0.0, o_.jitter);
    if (!(s > 0.0 && s < 4294967295.0))
      r.failAt(c_.t, "the stamp t + --time-offset = " + std::to_string(s) +
                         " s is not a ROS time > 0 (give --time-offset)");
    const std::int64_t ns = std::llround(s * 1e9);
    if (ns <= last_[topic])
      r.failAt(c_.t,
               "stamps do not increase" +
                   std::string(o_.jitter > 0.0 ? " (--jitter exceeds the spacing of t)" : ""));
    last_[topic] = ns;
    return jle_tools::stampOf(ns);
  }

  // The bag time of an input message stamped `stamp`: 1 us before it without --jitter
  // (ahead of the joint state of its instant), the stamp (its reception) with it.
  ros::Time inputTime(const ros::Time& stamp) const {
    return o_.jitter > 0.0 ? stamp : stamp - ros::Duration(0, 1000);
  }

  void staticPlates(const jle::CsvReader& r, double t) {
    if (o_.plates.empty()) return;
    tf2_msgs::TFMessage tf;
    const ros::Time first = jle_tools::stampOf(std::llround((t + o_.time_offset) * 1e9));
    if (!(t + o_.time_offset > 0.0))
      r.failAt(c_.t, "the first stamp is not > 0 (give --time-offset)");
    for (const PlatePose& p : o_.plates) {
      geometry_msgs::TransformStamped s;
      s.header.stamp = first;
      s.header.frame_id = o_.world;
      s.child_frame_id = p.name;
      s.transform.translation.x = p.p_world.x();
      s.transform.translation.y = p.p_world.y();
      s.transform.translation.z = p.p_world.z();
      s.transform.rotation.z = std::sin(0.5 * p.yaw);
      s.transform.rotation.w = std::cos(0.5 * p.yaw);
      tf.transforms.push_back(s);
    }
    bag_.bag().write("/tf_static", first - ros::Duration(0, 1000), tf);
  }

  void basePose(const jle::CsvReader& r, const std::vector<double>& x, long n, double t) {
    const auto& b = c_.base;
    Eigen::Quaterniond q(x[b[6]], x[b[3]], x[b[4]], x[b[5]]);
    if (!(std::abs(q.norm() - 1.0) <= 0.01))
      r.failAt(b[6], "the quaternion (base.qx, .qy, .qz, .qw) has norm " +
                         std::to_string(q.norm()) + ", not 1 (within 1 %)");
    q.normalize();
    geometry_msgs::TransformStamped s;
    s.header.seq = static_cast<std::uint32_t>(n);
    s.header.stamp = stamp(r, t, last_.size() - 1);
    s.header.frame_id = o_.world;
    s.child_frame_id = o_.base;
    s.transform.translation.x = x[b[0]];
    s.transform.translation.y = x[b[1]];
    s.transform.translation.z = x[b[2]];
    s.transform.rotation.x = q.x();
    s.transform.rotation.y = q.y();
    s.transform.rotation.z = q.z();
    s.transform.rotation.w = q.w();
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(s);
    bag_.bag().write("/tf", inputTime(s.header.stamp), tf);
  }

  const Options& o_;
  const Columns& c_;
  jle_tools::PartialBag bag_;
  jle::PortableRandom random_;
  std::vector<std::int64_t> last_;  // per topic, the last stamp [ns]
};

void run(const Options& o) {
  jle::CsvReader reader(o.input);
  const Columns columns = bindColumns(reader, o);
  BagWriter writer(o, columns);
  std::vector<double> x(static_cast<std::size_t>(reader.columns()));
  long n = 0;
  for (; reader.next(); ++n) {
    reader.numbers(x.data());
    writer.row(reader, x, n);
  }
  if (n == 0) throw std::runtime_error(o.input + ": no rows");
  writer.commit();
  std::printf("csv_to_bag: %ld rows, %zu joints, %zu wrench topics -> %s\n", n,
              columns.joints.size(), columns.wrenches.size(), o.output.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "csv_to_bag", kUsage, parseOptions, run);
}
