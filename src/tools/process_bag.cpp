// process_bag: the node's estimate, offline, for every joint state of a bag: the same
// settings file and the same message path (jle::Pipeline, through the node's own message
// conversions), in the bag's time order, with the bag's /tf and /tf_static in a tf2
// buffer for the frames the URDF does not hold (jle::processBag, bag_processing.hpp);
// this tool parses the options and writes the outputs. docs/demo.md.
#include <joint_load_estimator/Contact.h>
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/io/csv.hpp>
#include <joint_load_estimator/io/sto.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>
#include <joint_load_estimator/ros/bag_processing.hpp>
#include <joint_load_estimator/ros/conversions.hpp>
#include <joint_load_estimator/ros/external_outputs.hpp>

#include <rosbag/bag.h>

#include <cassert>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using jle::cli::UsageError;
using jle::cli::optionValues;

const char* const kUsage =
    R"(usage: process_bag --bag IN.bag --urdf ROBOT.urdf [--config CONFIG.yaml]
                   [--output OUT.bag | --csv OUT.csv [--kinematics]] [--sto OUT.sto]
                   [--accept-nonphysical-inertia]
                   [--smoothed-csv OUT.csv]
                   [--topic-prefix /joint_load_estimator]
                   [--zero-phase HZ|auto [--cutoff-rule RULE]]

Runs the joint_load_estimator node's estimate over a bag, offline and as fast as the
machine allows: the joint states, the configured wrench and force plate topics and
/tf, /tf_static are read in the bag's time order and go through the node's own
message path (partial joint states, stamps, time jumps, wrench frames, sensor biases,
a floating base, the filters), so the loads are the ones the node publishes when the
bag is played to it, without the timing of a live system.

  --bag PATH           the input bag
  --urdf PATH          the robot (the node reads it from robot_description)
  --config PATH        the node's parameters as a YAML file (config/default.yaml lists
                       them; robot_description is not used here; bias_file is
                       applied). Topic names that are not absolute are taken in the
                       root namespace. Default: every default, no wrench input.
  --output PATH        write joint_load_estimator/JointLoads messages on
                       PREFIX/joint_loads, bag time = the estimate's stamp, and
                       the smoothed stream's on PREFIX/smoothed/joint_loads (as the
                       node publishes them; docs/how_it_works.md "Two streams")
  --csv PATH           write the loads as CSV instead: t, then for every published
                       joint JOINT.fx, .fy, .fz, .mx, .my, .mz, .effort (the columns of
                       joint_loads; wrenches in the child link frame, moment about the
                       joint origin), %.17g; with uncertainty enabled, then
                       JOINT.effort_stddev for every joint; with --kinematics,
                       then JOINT.q, .qd, .qdd for every joint (what the loads were
                       computed from: the filter's estimate); with friction enabled
                       in the config, then JOINT.motor_effort for every joint;
                       with external_effort enabled, then JOINT.external_effort for
                       every joint, contact (0/1) and external@LINK.fx ... .mz per
                       contact link (the bag gets PREFIX/external_wrench/LINK and
                       PREFIX/contact, as the node publishes them)
  --kinematics         the JOINT.q, .qd, .qdd columns in the CSVs (docs/outputs.md)
  --smoothed-csv PATH  also write the smoothed stream's loads (smoothed/... in the
                       config; on by default: the loads `lag` behind, smoothed) as
                       CSV, the columns of --csv without the external ones
  --sto PATH           also (or only) write them as an OpenSim storage file: the
                       same numbers, tab-separated, under OpenSim's column names
                       (time, JOINT_moment or JOINT_force, and
                       JOINT_on_CHILD_in_CHILD_fx ... _mz in the child link's
                       axes; docs/joint_loads.md)
                       Every output is written beside PATH and renamed onto it on
                       success only. With none, the loads are computed and counted.
  --topic-prefix NS    namespace of the output topic (default /joint_load_estimator)
  --accept-nonphysical-inertia
                       as the setting accept_nonphysical_inertia: true (docs/how_it_works.md
                       "Model"): link inertias no rigid body has (an identified
                       parameter set) are accepted with a warning per link
  --zero-phase HZ|auto smooth offline first (docs/studies/zero_phase.md): the whole bag's
                       joint positions, and with the same filter every wrench and
                       plate message, by a Butterworth low-pass (order 4 per pass)
                       run forward and backward, cutoff HZ or chosen from the
                       positions (auto); then the message path runs on the smoothed
                       messages, its differentiator set to central differences
                       (finite_difference, order 2, delay 1) of the smoothed
                       positions. Every joint state must carry the same joints, in
                       increasing stamps. The cutoff and the rule that chose it
                       are printed, and a warning when the choice is doubtful.
  --cutoff-rule R      with --zero-phase auto: auto (default: the joint states'
                       velocities as evidence when every message has them, else
                       the positions' noise spectrum), spectrum, velocity, gcv or
                       residual (docs/studies/zero_phase.md)
  --help               this text

Frames: a wrench's frame that is not a URDF link rigid to its link, a floating base's
pose (world_frame -> base_frame) and a force plate's pose without position/orientation
in the config are looked up in the bag's /tf and /tf_static, at the message's stamp as
the node does; a bag without /tf cannot resolve them (an error).

Progress goes to standard error about once a second when it is a terminal; a summary
line at the end gives the samples per second of the estimate alone (compute) and of
the whole run (with reading and writing), and every message not used, by reason.

Exit status: 0 success; 1 a data error (unreadable bag or URDF, a bad setting, a
missing topic, a frame the bag cannot resolve, no loads at all: the message names the
culprit); 2 a usage error.
)";

struct Options {
  std::string bag, urdf, config, output, csv, sto, smoothed_csv;
  std::string prefix = "/joint_load_estimator";
  bool smooth = false;  // --zero-phase
  jle::ZeroPhaseConfig smoothing;
  bool kinematics = false;                  // JOINT.q, .qd, .qdd in the CSV
  bool accept_nonphysical_inertia = false;  // the flag: the setting set to true
};

// --zero-phase, --cutoff-rule.
void parseSmoothing(std::map<std::string, std::string>& v, Options& o) {
  o.smooth = v.count("--zero-phase") > 0;
  const std::string cutoff = o.smooth ? v["--zero-phase"] : "";
  if (o.smooth && cutoff != "auto") {
    o.smoothing.rule = jle::CutoffRule::kFixed;
    o.smoothing.cutoff = jle::cli::parseNumber("--zero-phase", cutoff, jle::cli::Sign::kPositive);
  }
  if (!v.count("--cutoff-rule")) return;
  if (cutoff != "auto") throw UsageError("--cutoff-rule is only used with --zero-phase auto");
  if (!jle::parseCutoffRule(v["--cutoff-rule"], o.smoothing.rule))
    throw UsageError("--cutoff-rule: '" + v["--cutoff-rule"] +
                     "' is not auto, spectrum, velocity, gcv or residual");
}

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v =
      optionValues(argc, argv,
                   {"--bag", "--urdf", "--config", "--output", "--csv", "--sto", "--topic-prefix",
                    "--zero-phase", "--cutoff-rule", "--smoothed-csv"},
                   {"--kinematics", "--accept-nonphysical-inertia"});
  Options o;
  if (!v.count("--bag")) throw UsageError("--bag IN.bag is required");
  if (!v.count("--urdf")) throw UsageError("--urdf ROBOT.urdf is required");
  if (v.count("--output") && v.count("--csv"))
    throw UsageError("--output and --csv exclude each other");
  o.bag = v["--bag"];
  o.urdf = v["--urdf"];
  if (v.count("--config")) o.config = v["--config"];
  if (v.count("--output")) o.output = v["--output"];
  if (v.count("--csv")) o.csv = v["--csv"];
  if (v.count("--sto")) o.sto = v["--sto"];
  if (v.count("--smoothed-csv")) o.smoothed_csv = v["--smoothed-csv"];
  o.kinematics = v.count("--kinematics") > 0;
  o.accept_nonphysical_inertia = v.count("--accept-nonphysical-inertia") > 0;
  if (o.kinematics && o.csv.empty() && o.smoothed_csv.empty())
    throw UsageError("--kinematics is only used with --csv or --smoothed-csv");
  if (v.count("--topic-prefix")) o.prefix = v["--topic-prefix"];
  if (o.prefix[0] != '/') o.prefix = "/" + o.prefix;
  while (o.prefix.size() > 1 && o.prefix.back() == '/') o.prefix.pop_back();
  if (o.prefix == "/") o.prefix.clear();
  parseSmoothing(v, o);
  return o;
}

/// The outputs: a bag of JointLoads, a CSV, an OpenSim storage file, each written
/// beside its path and renamed onto it by commit().
class Outputs : public jle::LoadsSink {
 public:
  explicit Outputs(const Options& options) : options_(options) {}
  ~Outputs() override;  // an output not committed (an error on the way) is removed
  Outputs(const Outputs&) = delete;
  Outputs& operator=(const Outputs&) = delete;

  void open(const jle::Pipeline& pipeline) override;
  void write(const jle::LoadsRecord& record, long seq) override;
  void writeSmoothed(const jle::LoadsRecord& record, long seq) override;
  void commit() override;
  std::string destination() const override;

 private:
  const Options& options_;
  joint_load_estimator::JointLoads loads_;
  std::vector<double> row_;
  std::size_t sto_columns_ = 0;  // the first numbers of row_: the .sto row
  std::unique_ptr<rosbag::Bag> bag_;
  std::string bag_temporary_, topic_, smoothed_topic_;
  std::unique_ptr<jle::CsvWriter> csv_, smoothed_csv_;
  std::vector<double> smoothed_row_;
  std::unique_ptr<jle::StoWriter> sto_;
  std::vector<double> sto_row_;  // the .sto row: t, the joints' loads, status
  // external_effort/enabled: the wrench topics per contact link and the contact events.
  std::vector<std::string> external_topics_;
  std::string contact_topic_;
  geometry_msgs::WrenchStamped wrench_;
  joint_load_estimator::Contact contact_;
  double* writeExternal(const jle::LoadsRecord& record, double* row);
  // t, the 7 numbers per joint, the effort sigmas: the .sto row; `csv`: then the kinematics
  // (--kinematics) and the motor efforts. Returns the end of what it wrote.
  double* writeLoads(const jle::LoadsRecord& record, bool csv, double* row) const;
  void openSmoothed(const jle::Pipeline& pipeline);
  void writeExternalMessages(const jle::LoadsRecord& record);
};

void Outputs::open(const jle::Pipeline& pipeline) {
  const Options& options = options_;
  const jle::LoadsRecord& record = pipeline.record();
  jle::prepare(record, loads_);
  sto_columns_ = 1 + 7 * record.joint.size() + record.effort_stddev.size();
  const std::size_t kinematics = options.kinematics ? 3 * record.joint.size() : 0;
  const std::size_t external =
      record.external_effort.empty() ? 0 : record.joint.size() + 1 + 6 * record.contacts.size();
  row_.resize(sto_columns_ +
              (options.csv.empty() ? 0 : kinematics + record.motor_effort.size() + external + 1));
  if (!options.output.empty()) {
    bag_temporary_ = options.output + ".partial";
    bag_ = std::make_unique<rosbag::Bag>();
    try {
      bag_->open(bag_temporary_, rosbag::bagmode::Write);
      // rosbag writes an uncompressed chunk to the file record by record; an LZ4 chunk
      // is built in memory and written at once: a third faster here, and smaller.
      bag_->setCompression(rosbag::compression::LZ4);
    } catch (const rosbag::BagException& e) {
      throw std::runtime_error(options.output + ": " + e.what());
    }
    topic_ = options.prefix + "/joint_loads";
    smoothed_topic_ = options.prefix + "/smoothed/joint_loads";
    if (!record.external_effort.empty()) {
      for (const jle::ContactEstimate& c : record.contacts)
        external_topics_.push_back(options.prefix + "/external_wrench/" + c.link);
      contact_topic_ = options.prefix + "/contact";
    }
  }
  const std::vector<std::string> names = jle::jointLoadColumns(record.joint);
  if (!options.csv.empty()) {
    jle::LoadColumnLayout layout;
    layout.effort_stddev = !record.effort_stddev.empty();
    layout.kinematics = options.kinematics;
    layout.motor_effort = !record.motor_effort.empty();
    layout.external_effort = !record.external_effort.empty();
    layout.status = true;
    if (layout.external_effort)
      for (const jle::ContactEstimate& c : record.contacts) layout.contacts.push_back(c.link);
    csv_ = std::make_unique<jle::CsvWriter>(options.csv);
    csv_->writeHeader(jle::jointLoadColumns(record.joint, layout));
  }
  if (!options.sto.empty()) {
    std::vector<std::string> sto_names = names;
    sto_names.push_back("status");
    sto_ = std::make_unique<jle::StoWriter>(options.sto);
    sto_->writeHeader(jle::stoLayout(pipeline.model(), sto_names, jle::WrenchFrame::kChild));
    sto_row_.assign(sto_names.size(), 0.0);
  }
  openSmoothed(pipeline);
}

void Outputs::openSmoothed(const jle::Pipeline& pipeline) {
  if (options_.smoothed_csv.empty()) return;
  if (!pipeline.hasSmoothed())
    throw std::runtime_error(
        "--smoothed-csv: the smoothed stream is off (smoothed/enabled: "
        "false in the config, or --zero-phase)");
  const jle::LoadsRecord& record = pipeline.smoothedRecord();
  jle::LoadColumnLayout layout;
  layout.effort_stddev = !record.effort_stddev.empty();
  layout.kinematics = options_.kinematics;
  layout.motor_effort = !record.motor_effort.empty();
  layout.status = true;
  smoothed_csv_ = std::make_unique<jle::CsvWriter>(options_.smoothed_csv);
  smoothed_csv_->writeHeader(jle::jointLoadColumns(record.joint, layout));
  smoothed_row_.resize(1 + 7 * record.joint.size() + record.effort_stddev.size() +
                       (options_.kinematics ? 3 * record.joint.size() : 0) +
                       record.motor_effort.size() + 1);
}

Outputs::~Outputs() {
  if (bag_) bag_->close();
  if (!bag_temporary_.empty()) std::remove(bag_temporary_.c_str());
}

double* Outputs::writeLoads(const jle::LoadsRecord& record, bool csv, double* row) const {
  *row++ = jle::toRosTime(record.stamp).toSec();
  for (std::size_t i = 0; i < record.joint.size(); ++i) {
    for (int c = 0; c < 3; ++c) *row++ = record.force[i][c];
    for (int c = 0; c < 3; ++c) *row++ = record.moment[i][c];
    *row++ = record.effort[i];
  }
  for (double s : record.effort_stddev) *row++ = s;
  if (!csv) return row;
  if (options_.kinematics)
    for (std::size_t i = 0; i < record.joint.size(); ++i) {
      *row++ = record.position[i];
      *row++ = record.velocity[i];
      *row++ = record.acceleration[i];
    }
  for (double e : record.motor_effort) *row++ = e;
  return row;
}

namespace {
double* writeStatus(const jle::LoadsRecord& record, double* row) {
  *row++ = record.status;
  return row;
}
}  // namespace

void Outputs::writeSmoothed(const jle::LoadsRecord& record, long seq) {
  if (smoothed_csv_) {
    double* end = writeStatus(record, writeLoads(record, true, smoothed_row_.data()));
    assert(static_cast<std::size_t>(end - smoothed_row_.data()) == smoothed_row_.size());
    (void)end;
    smoothed_csv_->writeRow(smoothed_row_.data(), smoothed_row_.size());
  }
  if (bag_) {
    jle::toMessage(record, loads_);
    loads_.header.seq = static_cast<std::uint32_t>(seq);
    bag_->write(smoothed_topic_, loads_.header.stamp, loads_);
  }
}

void Outputs::write(const jle::LoadsRecord& record, long seq) {
  if (!bag_ && !csv_ && !sto_) return;
  double* row = writeLoads(record, csv_ != nullptr, row_.data());
  if (csv_) row = writeStatus(record, writeExternal(record, row));
  assert(static_cast<std::size_t>(row - row_.data()) == (csv_ ? row_.size() : sto_columns_));
  if (csv_) csv_->writeRow(row_.data(), row_.size());
  if (sto_) {
    std::copy(row_.begin(), row_.begin() + static_cast<long>(sto_row_.size()) - 1,
              sto_row_.begin());
    sto_row_.back() = record.status;
    sto_->writeRow(sto_row_.data(), sto_row_.size());
  }
  if (bag_) {
    jle::toMessage(record, loads_);
    loads_.header.seq = static_cast<std::uint32_t>(seq);
    bag_->write(topic_, loads_.header.stamp, loads_);
    writeExternalMessages(record);
  }
}

double* Outputs::writeExternal(const jle::LoadsRecord& record, double* row) {
  if (record.external_effort.empty()) return row;
  for (double e : record.external_effort) *row++ = e;
  *row++ = record.in_contact ? 1.0 : 0.0;
  for (const jle::ContactEstimate& c : record.contacts) {
    for (int k = 0; k < 3; ++k) *row++ = c.force[k];
    for (int k = 0; k < 3; ++k) *row++ = c.moment[k];
  }
  return row;
}

// As the node publishes them: ~external_wrench/<link> and the ~contact events.
void Outputs::writeExternalMessages(const jle::LoadsRecord& record) {
  for (std::size_t k = 0; k < external_topics_.size(); ++k) {
    jle::toWrenchMessage(record.contacts[k], record.stamp, wrench_);
    bag_->write(external_topics_[k], wrench_.header.stamp, wrench_);
  }
  if (contact_topic_.empty() || !jle::isContactEvent(record)) return;
  jle::toContactMessage(record, contact_);
  bag_->write(contact_topic_, contact_.header.stamp, contact_);
}

void Outputs::commit() {
  if (bag_) {
    bag_->close();
    bag_.reset();
    if (std::rename(bag_temporary_.c_str(), options_.output.c_str()) != 0)
      throw std::runtime_error(options_.output + ": cannot rename " + bag_temporary_ + " onto it");
    bag_temporary_.clear();
  }
  if (csv_) csv_->commit();
  if (sto_) sto_->commit();
  if (smoothed_csv_) smoothed_csv_->commit();
}

std::string Outputs::destination() const {
  return !options_.output.empty() ? " to " + options_.output
         : !options_.csv.empty()  ? " to " + options_.csv
         : !options_.sto.empty()  ? " to " + options_.sto
                                  : " (not written)";
}

void run(const Options& options) {
  jle::BagOptions bag;
  bag.bag = options.bag;
  bag.urdf = options.urdf;
  bag.config = options.config;
  bag.smooth = options.smooth;
  bag.smoothing = options.smoothing;
  bag.accept_nonphysical_inertia = options.accept_nonphysical_inertia;
  Outputs outputs(options);
  jle::processBag(bag, outputs);
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "process_bag", kUsage, parseOptions, run);
}
