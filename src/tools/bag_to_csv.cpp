// bag_to_csv: the package's output messages (joint_load_estimator/JointLoads, recorded
// from the node with rosbag record, or written by process_bag --output) as a CSV in the
// columns of process_bag --csv and joint_loads. docs/data_in_out.md.
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/io/csv.hpp>

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "bag_errors.hpp"

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace jle::cli;  // command_line.hpp: UsageError, optionValues, the parsers

const char* const kUsage =
    R"(usage: bag_to_csv --bag IN.bag --output LOADS.csv
                  [--topic /joint_load_estimator/joint_loads] [--kinematics] [--per-kg]

Writes the joint_load_estimator/JointLoads messages of a bag topic as a CSV, one row
per message in bag order, with the columns of process_bag --csv (docs/joint_loads.md):
t (header.stamp [s]), then for every joint JOINT.fx, .fy, .fz, .mx, .my, .mz (child
link frame, moment about the joint origin), .effort [, .effort_per_kg with --per-kg];
JOINT.effort_stddev for every joint when the messages carry it; with --kinematics
JOINT.q, .qd, .qdd for every joint (what the loads were computed from); and
JOINT.motor_effort for every joint when the messages carry it. Every number %.17g.

  --bag PATH      the bag
  --output PATH   the CSV (default: standard output); written beside PATH and renamed
                  onto it on success only
  --topic T       default /joint_load_estimator/joint_loads
  --kinematics    the JOINT.q, .qd, .qdd columns
  --per-kg        the JOINT.effort_per_kg columns (the node's body_mass must be set)
  --help          this text

Exit status: 0 success; 1 a data error (an unreadable bag, no message on the topic, a
message whose joints or arrays differ from the first one's: the message is named by
its index and stamp; an unwritable output); 2 a usage error.
)";

struct Options {
  std::string bag, output, topic = "/joint_load_estimator/joint_loads";
  bool kinematics = false, per_kg = false;
};

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v =
      optionValues(argc, argv, {"--bag", "--output", "--topic"}, {"--kinematics", "--per-kg"});
  Options o;
  o.bag = requiredValue(v, "--bag", "IN.bag");
  if (v.count("--output")) o.output = v["--output"];
  if (v.count("--topic")) o.topic = v["--topic"];
  o.kinematics = v.count("--kinematics") > 0;
  o.per_kg = v.count("--per-kg") > 0;
  return o;
}

class Writer {
 public:
  explicit Writer(const Options& o) : o_(o) {}

  void write(const joint_load_estimator::JointLoads& m, long index) {
    if (!out_) start(m, index);
    check(m, index);
    double* r = row_.data();
    *r++ = m.header.stamp.toSec();
    for (std::size_t i = 0; i < n_; ++i) {
      const geometry_msgs::Wrench& w = m.wrench[i];
      for (double x : {w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z})
        *r++ = x;
      *r++ = m.effort[i];
      if (o_.per_kg) *r++ = m.effort_per_kg[i];
    }
    for (double s : m.effort_stddev) *r++ = s;
    if (o_.kinematics)
      for (std::size_t i = 0; i < n_; ++i) {
        *r++ = m.position[i];
        *r++ = m.velocity[i];
        *r++ = m.acceleration[i];
      }
    for (double e : m.motor_effort) *r++ = e;
    *r++ = m.status;
    out_->writeRow(row_.data(), row_.size());
  }

  void commit(long messages) {
    if (!out_) throw std::runtime_error(o_.bag + ": no message on " + o_.topic);
    out_->commit();
    std::fprintf(stderr, "bag_to_csv: %ld messages of %s -> %s\n", messages, o_.topic.c_str(),
                 o_.output.empty() ? "standard output" : o_.output.c_str());
  }

 private:
  [[noreturn]] void fail(const joint_load_estimator::JointLoads& m, long index,
                         const std::string& what) const {
    throw std::runtime_error(o_.bag + ": " + o_.topic + " message " + std::to_string(index) +
                             " (stamp " + std::to_string(m.header.stamp.toSec()) + "): " + what);
  }

  void start(const joint_load_estimator::JointLoads& m, long index) {
    names_ = m.name;
    n_ = names_.size();
    stddev_ = m.effort_stddev.size();
    motor_ = m.motor_effort.size();
    if (o_.per_kg && m.effort_per_kg.size() != n_)
      fail(m, index, "no effort_per_kg (--per-kg needs the node's body_mass)");
    jle::LoadColumnLayout layout;
    layout.per_kg = o_.per_kg;
    layout.effort_stddev = stddev_ > 0;
    layout.kinematics = o_.kinematics;
    layout.motor_effort = motor_ > 0;
    layout.status = true;  // JointLoads.status, as process_bag --csv writes it
    const std::vector<std::string> header = jle::jointLoadColumns(names_, layout);
    row_.resize(header.size());
    out_ = std::make_unique<jle::CsvWriter>(o_.output);
    out_->writeHeader(header);
  }

  void check(const joint_load_estimator::JointLoads& m, long index) const {
    if (m.name != names_) fail(m, index, "its joints differ from the first message's");
    if (m.wrench.size() != n_ || m.effort.size() != n_)
      fail(m, index, "wrench[] or effort[] is not one per joint");
    if (m.effort_stddev.size() != stddev_ || m.motor_effort.size() != motor_)
      fail(m, index, "effort_stddev[] or motor_effort[] differ in size from the first message's");
    if (o_.per_kg && m.effort_per_kg.size() != n_) fail(m, index, "effort_per_kg[] missing");
    if (o_.kinematics &&
        (m.position.size() != n_ || m.velocity.size() != n_ || m.acceleration.size() != n_))
      fail(m, index, "position[], velocity[] or acceleration[] is not one per joint");
  }

  const Options& o_;
  std::unique_ptr<jle::CsvWriter> out_;
  std::vector<std::string> names_;
  std::size_t n_ = 0, stddev_ = 0, motor_ = 0;
  std::vector<double> row_;
};

void run(const Options& o) {
  rosbag::Bag bag;
  Writer writer(o);
  long index = 0;
  try {
    bag.open(o.bag, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& mi : rosbag::View(bag, rosbag::TopicQuery(o.topic))) {
      const joint_load_estimator::JointLoads::ConstPtr m =
          mi.instantiate<joint_load_estimator::JointLoads>();
      if (!m)
        throw std::runtime_error(o.bag + ": " + o.topic + " holds " + mi.getDataType() +
                                 ", not joint_load_estimator/JointLoads");
      writer.write(*m, index++);
    }
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(jle::bagReadError(o.bag, e));
  }
  writer.commit(index);
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "bag_to_csv", kUsage, parseOptions, run);
}
