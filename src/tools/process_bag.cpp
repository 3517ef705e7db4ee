// process_bag: the node's estimate, offline, for every joint state of a bag: the same
// settings file and the same message path (jle::Pipeline, through the node's own message
// conversions), in the bag's time order, with the bag's /tf and /tf_static in a tf2
// buffer for the frames the URDF does not hold. docs/demo.md.
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/command_line.hpp>
#include <joint_load_estimator/csv.hpp>
#include <joint_load_estimator/pipeline.hpp>
#include <joint_load_estimator/ros/bias_file.hpp>
#include <joint_load_estimator/ros/conversions.hpp>
#include <joint_load_estimator/ros/settings.hpp>
#include <joint_load_estimator/sto.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <geometry_msgs/WrenchStamped.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>

#include <unistd.h>

#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

namespace {

using jle::cli::UsageError;
using jle::cli::optionValues;

const char* const kUsage =
    R"(usage: process_bag --bag IN.bag --urdf ROBOT.urdf [--config CONFIG.yaml]
                   [--output OUT.bag | --csv OUT.csv [--kinematics]] [--sto OUT.sto]
                   [--topic-prefix /joint_load_estimator]

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
                       PREFIX/joint_loads, bag time = the estimate's stamp
  --csv PATH           write the loads as CSV instead: t, then for every published
                       joint JOINT.fx, .fy, .fz, .mx, .my, .mz, .effort (the columns of
                       joint_loads; wrenches in the child link frame, moment about the
                       joint origin), %.17g; with uncertainty enabled, then
                       JOINT.effort_stddev for every joint; with --kinematics,
                       then JOINT.q, .qd, .qdd for every joint (what the loads were
                       computed from: the filter's estimate); with friction enabled
                       in the config, then JOINT.motor_effort for every joint
  --kinematics         the JOINT.q, .qd, .qdd columns in the CSV (docs/outputs.md)
  --sto PATH           also (or only) write them as an OpenSim storage file: the
                       same numbers, tab-separated, under OpenSim's column names
                       (time, JOINT_moment or JOINT_force, and
                       JOINT_on_CHILD_in_CHILD_fx ... _mz; docs/joint_loads.md)
                       Every output is written beside PATH and renamed onto it on
                       success only. With none, the loads are computed and counted.
  --topic-prefix NS    namespace of the output topic (default /joint_load_estimator)
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
  std::string bag, urdf, config, output, csv, sto;
  std::string prefix = "/joint_load_estimator";
  bool kinematics = false;  // JOINT.q, .qd, .qdd in the CSV
};

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v = optionValues(
      argc, argv, {"--bag", "--urdf", "--config", "--output", "--csv", "--sto", "--topic-prefix"},
      {"--kinematics"});
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
  o.kinematics = v.count("--kinematics") > 0;
  if (o.kinematics && o.csv.empty()) throw UsageError("--kinematics is only used with --csv");
  if (v.count("--topic-prefix")) o.prefix = v["--topic-prefix"];
  if (o.prefix[0] != '/') o.prefix = "/" + o.prefix;
  while (o.prefix.size() > 1 && o.prefix.back() == '/') o.prefix.pop_back();
  if (o.prefix == "/") o.prefix.clear();
  return o;
}

std::string globalName(const std::string& topic) {
  return !topic.empty() && topic[0] == '/' ? topic : "/" + topic;
}

// A destination for MessageInstance::write: one buffer, grown to the largest message
// and then reused, so that reading a message does not allocate.
struct ReuseBuffer {
  std::vector<std::uint8_t> bytes;
  std::uint32_t size = 0;
  std::uint8_t* advance(std::uint32_t n) {
    if (bytes.size() < n) bytes.resize(n);
    size = n;
    return bytes.data();
  }
};

template <typename Message>
void deserialize(const rosbag::MessageInstance& m, ReuseBuffer& buffer, Message& message) {
  m.write(buffer);
  ros::serialization::IStream stream(buffer.bytes.data(), buffer.size);
  ros::serialization::deserialize(stream, message);
}

using Clock = std::chrono::steady_clock;

/// The outputs: a bag of JointLoads, a CSV, an OpenSim storage file, each written
/// beside its path and renamed onto it by commit().
class Outputs {
 public:
  Outputs(const Options& options, const jle::Pipeline& pipeline);
  ~Outputs();  // an output not committed (an error on the way) is removed
  Outputs(const Outputs&) = delete;
  Outputs& operator=(const Outputs&) = delete;

  void write(const jle::LoadsRecord& record, long seq);
  void commit();
  std::string destination() const;

 private:
  const Options& options_;
  joint_load_estimator::JointLoads loads_;
  std::vector<double> row_;
  std::size_t sto_columns_ = 0;  // the first numbers of row_: the .sto row
  std::unique_ptr<rosbag::Bag> bag_;
  std::string bag_temporary_, topic_;
  std::unique_ptr<jle::CsvWriter> csv_;
  std::unique_ptr<jle::StoWriter> sto_;
};

Outputs::Outputs(const Options& options, const jle::Pipeline& pipeline) : options_(options) {
  const jle::LoadsRecord& record = pipeline.record();
  jle::prepare(record, loads_);
  sto_columns_ = 1 + 7 * record.joint.size() + record.effort_stddev.size();
  const std::size_t kinematics = options.kinematics ? 3 * record.joint.size() : 0;
  row_.resize(sto_columns_ + (options.csv.empty() ? 0 : kinematics + record.motor_effort.size()));
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
  }
  const std::vector<std::string> names = jle::jointLoadColumns(record.joint);
  if (!options.csv.empty()) {
    jle::LoadColumnLayout layout;
    layout.effort_stddev = !record.effort_stddev.empty();
    layout.kinematics = options.kinematics;
    layout.motor_effort = !record.motor_effort.empty();
    csv_ = std::make_unique<jle::CsvWriter>(options.csv);
    csv_->writeHeader(jle::jointLoadColumns(record.joint, layout));
  }
  if (!options.sto.empty()) {
    sto_ = std::make_unique<jle::StoWriter>(options.sto);
    sto_->writeHeader(jle::stoColumnNames(pipeline.model(), names, jle::WrenchFrame::kChild));
  }
}

Outputs::~Outputs() {
  if (bag_) bag_->close();
  if (!bag_temporary_.empty()) std::remove(bag_temporary_.c_str());
}

void Outputs::write(const jle::LoadsRecord& record, long seq) {
  if (!bag_ && !csv_ && !sto_) return;
  double* row = row_.data();
  *row++ = jle::toRosTime(record.stamp).toSec();
  for (std::size_t i = 0; i < record.joint.size(); ++i) {
    for (int c = 0; c < 3; ++c) *row++ = record.force[i][c];
    for (int c = 0; c < 3; ++c) *row++ = record.moment[i][c];
    *row++ = record.effort[i];
  }
  for (double s : record.effort_stddev) *row++ = s;
  if (csv_ && options_.kinematics)
    for (std::size_t i = 0; i < record.joint.size(); ++i) {
      *row++ = record.position[i];
      *row++ = record.velocity[i];
      *row++ = record.acceleration[i];
    }
  if (csv_)
    for (double e : record.motor_effort) *row++ = e;
  assert(static_cast<std::size_t>(row - row_.data()) == (csv_ ? row_.size() : sto_columns_));
  if (csv_) csv_->writeRow(row_.data(), row_.size());
  if (sto_) sto_->writeRow(row_.data(), sto_columns_);
  if (bag_) {
    jle::toMessage(record, loads_);
    loads_.header.seq = static_cast<std::uint32_t>(seq);
    bag_->write(topic_, loads_.header.stamp, loads_);
  }
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
}

std::string Outputs::destination() const {
  return !options_.output.empty() ? " to " + options_.output
         : !options_.csv.empty()  ? " to " + options_.csv
         : !options_.sto.empty()  ? " to " + options_.sto
                                  : " (not written)";
}

/// The bag's messages through the pipeline, in the bag's order. Everything the loop
/// touches is allocated in the constructor or by the first messages.
class BagProcessor {
 public:
  BagProcessor(const Options& options, const jle::Settings& settings,
               const jle::Model<double>& model)
      : options_(options),
        tf_(ros::Duration(tf2::BufferCore::DEFAULT_CACHE_TIME)),  // the node's tf2_ros::Buffer
        frames_(tf_),
        pipeline_(model, settings, &frames_) {
    joint_topic_ = globalName(settings.joint_states_topic);
    for (const jle::WrenchTopicSettings& w : settings.wrenches)
      wrench_topics_.push_back(globalName(w.topic));
    for (const jle::PlateTopicSettings& p : settings.force_plates)
      plate_topics_.push_back(globalName(p.topic));
    jle::applyBiasFile(pipeline_);
  }

  void run();

 private:
  void checkTopics(const rosbag::Bag& in, rosbag::View& view);
  void dispatch(const rosbag::MessageInstance& m);
  void onTf(const rosbag::MessageInstance& m, bool is_static);
  void note(jle::Outcome outcome);
  std::string noLoads() const;
  void summarize(double total_s) const;
  void printDrops() const;

  const Options& options_;
  tf2::BufferCore tf_;
  jle::Tf2FrameSource frames_;
  jle::Pipeline pipeline_;
  std::unique_ptr<Outputs> outputs_;
  std::string joint_topic_;
  std::vector<std::string> wrench_topics_, plate_topics_;  // settings order
  bool have_tf_ = false;                                   // the bag has /tf or /tf_static
  ReuseBuffer buffer_;
  sensor_msgs::JointState joint_msg_;
  geometry_msgs::WrenchStamped wrench_msg_;
  tf2_msgs::TFMessage tf_msg_;
  Clock::duration compute_{0};
  // Each problem (problemKey) is said once (the node throttles), its count in the summary.
  std::unordered_set<std::size_t> said_;
  bool said_unknown_ = false;
};

void BagProcessor::run() {
  rosbag::Bag in;
  try {
    in.open(options_.bag, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(options_.bag + ": " + e.what());
  }
  std::vector<std::string> topics{joint_topic_, "/tf", "/tf_static"};
  topics.insert(topics.end(), wrench_topics_.begin(), wrench_topics_.end());
  topics.insert(topics.end(), plate_topics_.begin(), plate_topics_.end());
  rosbag::View view(in, rosbag::TopicQuery(topics));
  checkTopics(in, view);
  outputs_ = std::make_unique<Outputs>(options_, pipeline_);

  const long total = static_cast<long>(view.size());
  const Clock::time_point start = Clock::now();
  Clock::time_point next_progress = start + std::chrono::seconds(1);
  const bool progress = isatty(STDERR_FILENO) != 0;
  bool progress_shown = false;
  long count = 0;
  for (const rosbag::MessageInstance& m : view) {
    dispatch(m);
    if (progress && (++count & 1023) == 0 && Clock::now() >= next_progress) {
      next_progress += std::chrono::seconds(1);
      std::fprintf(stderr, "\rprocess_bag: %3.0f%%  %ld of %ld messages  %ld loads",
                   100.0 * static_cast<double>(count) / static_cast<double>(total), count, total,
                   pipeline_.counters().count(jle::Outcome::kPublished));
      progress_shown = true;
    }
  }
  if (progress_shown) std::fputc('\n', stderr);
  if (pipeline_.counters().count(jle::Outcome::kPublished) == 0)
    throw std::runtime_error(noLoads());
  outputs_->commit();
  summarize(std::chrono::duration<double>(Clock::now() - start).count());
}

void BagProcessor::dispatch(const rosbag::MessageInstance& m) {
  const std::string& topic = m.getTopic();
  if (topic == "/tf" || topic == "/tf_static") return onTf(m, topic == "/tf_static");
  const bool joints = topic == joint_topic_;
  if (joints)
    deserialize(m, buffer_, joint_msg_);
  else
    deserialize(m, buffer_, wrench_msg_);
  const Clock::time_point c0 = Clock::now();
  if (joints) {
    const jle::Outcome outcome = jle::feed(pipeline_, joint_msg_, m.getTime());
    compute_ += Clock::now() - c0;
    note(outcome);
    if (outcome == jle::Outcome::kPublished)
      outputs_->write(pipeline_.record(), pipeline_.counters().count(jle::Outcome::kPublished) - 1);
    return;
  }
  for (std::size_t k = 0; k < wrench_topics_.size(); ++k)
    if (topic == wrench_topics_[k])
      note(jle::feedWrench(pipeline_, static_cast<int>(k), wrench_msg_, m.getTime()));
  for (std::size_t k = 0; k < plate_topics_.size(); ++k)
    if (topic == plate_topics_[k])
      note(jle::feedPlate(pipeline_, static_cast<int>(k), wrench_msg_, m.getTime()));
  compute_ += Clock::now() - c0;
}

void BagProcessor::onTf(const rosbag::MessageInstance& m, bool is_static) {
  deserialize(m, buffer_, tf_msg_);
  for (const geometry_msgs::TransformStamped& t : tf_msg_.transforms) {
    try {
      tf_.setTransform(t, "process_bag", is_static);
    } catch (const std::exception& e) {  // tf2 refuses a NaN or a frame named ""
      std::fprintf(stderr, "process_bag: warning: %s: %s\n", m.getTopic().c_str(), e.what());
    }
  }
}

void BagProcessor::note(jle::Outcome outcome) {
  if (!pipeline_.unknownJoint().empty() && !said_unknown_) {
    said_unknown_ = true;
    std::fprintf(stderr, "process_bag: warning: %s: joint '%s' is not in the model: ignored\n",
                 joint_topic_.c_str(), pipeline_.unknownJoint().c_str());
  }
  if (pipeline_.problem().empty()) return;
  // Without /tf nothing can resolve the frame later: a data error, as the usage says.
  if ((outcome == jle::Outcome::kFrame || outcome == jle::Outcome::kNoBasePose) && !have_tf_)
    throw std::runtime_error(pipeline_.problem() + " (" + options_.bag + " has no /tf)");
  if (said_.size() > 1024 || !said_.insert(jle::problemKey(pipeline_.problem())).second) return;
  std::fprintf(stderr, "process_bag: warning: %s (further ones counted in the summary)\n",
               pipeline_.problem().c_str());
}

std::string BagProcessor::noLoads() const {
  printDrops();
  const jle::PipelineCounters& c = pipeline_.counters();
  return "no loads from " + std::to_string(c.received(jle::InputKind::kJointState)) +
         " joint states on " + joint_topic_ + ": " +
         (pipeline_.problem().empty() ? "too few for the filter, or every one dropped"
                                      : "the last said: " + pipeline_.problem());
}

void BagProcessor::checkTopics(const rosbag::Bag& in, rosbag::View& view) {
  std::map<std::string, std::string> expected{{joint_topic_, "sensor_msgs/JointState"},
                                              {"/tf", "tf2_msgs/TFMessage"},
                                              {"/tf_static", "tf2_msgs/TFMessage"}};
  for (const std::string& w : wrench_topics_) expected[w] = "geometry_msgs/WrenchStamped";
  for (const std::string& p : plate_topics_) expected[p] = "geometry_msgs/WrenchStamped";
  const std::map<std::string, std::string> md5{
      {"sensor_msgs/JointState", ros::message_traits::md5sum<sensor_msgs::JointState>()},
      {"geometry_msgs/WrenchStamped", ros::message_traits::md5sum<geometry_msgs::WrenchStamped>()},
      {"tf2_msgs/TFMessage", ros::message_traits::md5sum<tf2_msgs::TFMessage>()}};
  std::map<std::string, bool> present;
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    const std::string& type = expected.at(c->topic);
    if (c->datatype != type || c->md5sum != md5.at(type))
      throw std::runtime_error(options_.bag + ": topic '" + c->topic + "' holds " + c->datatype +
                               ", expected " + type);
    present[c->topic] = true;
  }
  have_tf_ = present.count("/tf") || present.count("/tf_static");
  if (!present.count(joint_topic_)) {
    std::map<std::string, std::string> seen;
    for (const rosbag::ConnectionInfo* c : rosbag::View(in).getConnections())
      seen[c->topic] = c->datatype;
    std::string all;
    for (const auto& t : seen) all += (all.empty() ? "" : ", ") + t.first + " (" + t.second + ")";
    throw std::runtime_error(
        options_.bag + ": no messages on the joint states topic '" + joint_topic_ +
        "' (parameter joint_states_topic); the bag has: " + (all.empty() ? "nothing" : all));
  }
  for (const auto& inputs :
       {std::make_pair("wrench", &wrench_topics_), std::make_pair("force plate", &plate_topics_)})
    for (const std::string& topic : *inputs.second)
      if (!present.count(topic))
        std::fprintf(stderr,
                     "process_bag: warning: no messages on %s topic '%s' in %s: the loads are "
                     "computed without it\n",
                     inputs.first, topic.c_str(), options_.bag.c_str());
}

void BagProcessor::summarize(double total_s) const {
  const jle::PipelineCounters& c = pipeline_.counters();
  const double compute_s = std::chrono::duration<double>(compute_).count();
  const long joint_states = c.received(jle::InputKind::kJointState);
  const double samples = static_cast<double>(joint_states);
  std::fprintf(
      stderr,
      "process_bag: %ld joint states, %ld wrenches, %ld plate samples -> %ld loads%s\n"
      "process_bag: compute %.3f s (%.0f samples/s), total with I/O %.3f s "
      "(%.0f samples/s)\n",
      joint_states, c.received(jle::InputKind::kWrench), c.received(jle::InputKind::kPlate),
      c.count(jle::Outcome::kPublished), outputs_->destination().c_str(), compute_s,
      compute_s > 0 ? samples / compute_s : 0.0, total_s, total_s > 0 ? samples / total_s : 0.0);
  printDrops();
}

void BagProcessor::printDrops() const {
  const jle::PipelineCounters& c = pipeline_.counters();
  std::string drops;
  for (int o = static_cast<int>(jle::Outcome::kInvalid); o < static_cast<int>(jle::Outcome::kCount);
       ++o)
    if (const long n = c.count(static_cast<jle::Outcome>(o)))
      drops += (drops.empty() ? "" : ", ") + std::to_string(n) + " " +
               jle::toString(static_cast<jle::Outcome>(o));
  if (c.unknown_joints)
    drops +=
        (drops.empty() ? "" : ", ") + std::to_string(c.unknown_joints) + " with unknown joints";
  if (c.resets)
    drops += (drops.empty() ? "" : ", ") + std::to_string(c.resets) + " time jumps back";
  if (!drops.empty()) std::fprintf(stderr, "process_bag: not used: %s\n", drops.c_str());
}

void run(const Options& options) {
  jle::Settings settings;
  try {
    settings = jle::parseSettings(options.config.empty() ? XmlRpc::XmlRpcValue()
                                                         : jle::loadYaml(options.config));
  } catch (const jle::SettingsError& e) {
    throw std::runtime_error(options.config + ": " + e.what());
  }
  const jle::Model<double> model =
      jle::modelFromUrdfFile(options.urdf, jle::modelOptions(settings));
  for (const std::string& w : model.warnings)
    std::fprintf(stderr, "process_bag: warning: robot model: %s\n", w.c_str());
  std::unique_ptr<BagProcessor> processor;
  try {
    processor = std::make_unique<BagProcessor>(options, settings, model);
  } catch (const std::invalid_argument& e) {  // SettingsError too
    throw std::runtime_error((options.config.empty() ? options.urdf : options.config) + ": " +
                             e.what());
  }
  processor->run();
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "process_bag", kUsage, parseOptions, run);
}
