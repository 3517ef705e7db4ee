// A bag through the node's message path, offline (bag_processing.hpp): process_bag and the
// Python bindings run it. Moved out of process_bag.cpp unchanged but for its sink.
#include <joint_load_estimator/ros/bag_processing.hpp>

#include <joint_load_estimator/estimation/sensor_sign.hpp>
#include <joint_load_estimator/filters/zero_phase.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>
#include <joint_load_estimator/ros/bias_file.hpp>
#include <joint_load_estimator/ros/conversions.hpp>
#include <joint_load_estimator/settings/settings_reader.hpp>

#include "bag_errors.hpp"

#include <geometry_msgs/WrenchStamped.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

namespace jle {
namespace {

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

/// --zero-phase: the bag's joint states and wrench and plate messages, read whole and
/// smoothed (zero_phase.hpp); the message path then takes them in place of the bag's, in
/// the same order.
class SmoothedBag {
 public:
  SmoothedBag(const std::string& joint_topic, const std::vector<std::string>& force_topics)
      : joint_topic_(joint_topic) {
    for (const std::string& topic : force_topics) forces_[topic];
  }

  /// Every message of the joint and force topics in `view`.
  void read(rosbag::View& view, ReuseBuffer& buffer);
  /// Smooths them (the joint states' velocities, when every message has them, as the
  /// cutoff rule's evidence); how the cutoff was chosen.
  jle::CutoffChoice smooth(const jle::ZeroPhaseConfig& config);
  const sensor_msgs::JointState& nextJoint() { return joints_.at(next_joint_++); }
  const geometry_msgs::WrenchStamped& nextForce(const std::string& topic) {
    Series& s = forces_.at(topic);
    return s.messages.at(s.next++);
  }

 private:
  struct Series {
    std::vector<geometry_msgs::WrenchStamped> messages;
    std::vector<jle::Stamp> stamps;  // header stamps, the bag time where 0
    std::size_t next = 0;
  };
  std::vector<double> times(const std::vector<jle::Stamp>& stamps, const std::string& topic) const;
  Eigen::MatrixXd positions() const;
  Eigen::MatrixXd velocities() const;
  // The topic's wrenches, samples x (force, torque), at their times.
  jle::FilteredAlike wrenches(const std::string& topic, const Series& s) const;
  // The topic's wrenches filtered with `cutoff` [Hz].
  void filterForces(const std::string& topic, Series& s, const jle::ZeroPhaseConfig& config,
                    double cutoff);

  std::string joint_topic_;
  std::vector<sensor_msgs::JointState> joints_;
  std::vector<jle::Stamp> joint_stamps_;
  std::map<std::string, Series> forces_;
  std::size_t next_joint_ = 0;
};

void SmoothedBag::read(rosbag::View& view, ReuseBuffer& buffer) {
  for (const rosbag::MessageInstance& m : view) {
    const std::string& topic = m.getTopic();
    const auto stamp = [&](const std_msgs::Header& h) {
      return h.stamp.isZero() ? jle::toStamp(m.getTime()) : jle::toStamp(h.stamp);
    };
    if (topic == joint_topic_) {
      joints_.emplace_back();
      deserialize(m, buffer, joints_.back());
      joint_stamps_.push_back(stamp(joints_.back().header));
    } else if (forces_.count(topic)) {
      Series& s = forces_[topic];
      s.messages.emplace_back();
      deserialize(m, buffer, s.messages.back());
      s.stamps.push_back(stamp(s.messages.back().header));
    }
  }
}

// Seconds since the first joint state's stamp; they must increase.
std::vector<double> SmoothedBag::times(const std::vector<jle::Stamp>& stamps,
                                       const std::string& topic) const {
  std::vector<double> t;
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    if (i > 0 && stamps[i] <= stamps[i - 1])
      throw std::runtime_error("--zero-phase: " + topic + ": message " + std::to_string(i) +
                               " is not newer than the one before: a record is smoothed over "
                               "increasing stamps");
    t.push_back(1e-9 * static_cast<double>(stamps[i] - joint_stamps_.front()));
  }
  return t;
}

// The joint states' positions, samples x joints; every message with the first's joints.
Eigen::MatrixXd SmoothedBag::positions() const {
  if (joints_.size() < 3)
    throw std::runtime_error("--zero-phase: " + joint_topic_ + " has " +
                             std::to_string(joints_.size()) + " messages; at least 3 are needed");
  const std::vector<std::string>& names = joints_.front().name;
  Eigen::MatrixXd q(joints_.size(), names.size());
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const sensor_msgs::JointState& m = joints_[i];
    if (m.name != names || m.position.size() != names.size())
      throw std::runtime_error("--zero-phase: " + joint_topic_ + ": message " + std::to_string(i) +
                               " does not carry the joints of the first (with a position "
                               "each): partial joint states are not smoothed");
    for (std::size_t j = 0; j < names.size(); ++j) q(i, j) = m.position[j];
  }
  return q;
}

jle::FilteredAlike SmoothedBag::wrenches(const std::string& topic, const Series& s) const {
  jle::FilteredAlike f{times(s.stamps, topic), Eigen::MatrixXd(s.messages.size(), 6), topic};
  for (std::size_t i = 0; i < s.messages.size(); ++i) {
    const geometry_msgs::Wrench& w = s.messages[i].wrench;
    f.x.row(i) << w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z;
  }
  return f;
}

void SmoothedBag::filterForces(const std::string& topic, Series& s,
                               const jle::ZeroPhaseConfig& config, double cutoff) {
  if (s.messages.size() < 3) return;  // too few to filter: the message path counts them
  const jle::FilteredAlike raw = wrenches(topic, s);
  const Eigen::MatrixXd f = jle::lowPassZeroPhase(raw.t, raw.x, cutoff, config.order);
  for (std::size_t i = 0; i < s.messages.size(); ++i) {
    geometry_msgs::Wrench& w = s.messages[i].wrench;
    w.force.x = f(i, 0), w.force.y = f(i, 1), w.force.z = f(i, 2);
    w.torque.x = f(i, 3), w.torque.y = f(i, 4), w.torque.z = f(i, 5);
  }
}

// The joint states' measured velocities, samples x joints, when every message carries
// one per joint; else empty (no evidence).
Eigen::MatrixXd SmoothedBag::velocities() const {
  const std::size_t joints = joints_.front().name.size();
  for (const sensor_msgs::JointState& m : joints_)
    if (m.velocity.size() != joints) return Eigen::MatrixXd();
  Eigen::MatrixXd v(joints_.size(), joints);
  for (std::size_t i = 0; i < joints_.size(); ++i)
    for (std::size_t j = 0; j < joints; ++j) v(i, j) = joints_[i].velocity[j];
  return v;
}

jle::CutoffChoice SmoothedBag::smooth(const jle::ZeroPhaseConfig& config) {
  const Eigen::MatrixXd q = positions();
  jle::ZeroPhaseResult r;
  try {
    std::vector<jle::FilteredAlike> alike;
    for (const auto& [topic, series] : forces_)
      if (series.messages.size() >= 3) alike.push_back(wrenches(topic, series));
    r = jle::smoothZeroPhase(times(joint_stamps_, joint_topic_), q, config, velocities(), alike);
    for (auto& [topic, series] : forces_) filterForces(topic, series, config, r.cutoff);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("--zero-phase: ") + e.what());
  }
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    sensor_msgs::JointState& m = joints_[i];
    m.velocity.resize(m.position.size());
    for (std::size_t j = 0; j < m.position.size(); ++j)
      m.position[j] = r.value(i, j), m.velocity[j] = r.rate(i, j);
  }
  return r.choice;
}

/// The bag's messages through the pipeline, in the bag's order. Everything the loop
/// touches is allocated in the constructor or by the first messages.
class BagProcessor {
 public:
  BagProcessor(const BagOptions& options, const jle::Settings& settings,
               const jle::Model<double>& model, LoadsSink& sink)
      : options_(options),
        sink_(sink),
        tf_(ros::Duration(tf2::BufferCore::DEFAULT_CACHE_TIME)),  // the node's tf2_ros::Buffer
        frames_(tf_),
        pipeline_(model, settings, &frames_) {
    joint_topic_ = globalName(settings.joint_states_topic);
    for (const jle::WrenchTopicSettings& w : settings.wrenches)
      wrench_topics_.push_back(globalName(w.topic));
    signs_.resize(settings.wrenches.size());
    for (const jle::PlateTopicSettings& p : settings.force_plates)
      plate_topics_.push_back(globalName(p.topic));
    jle::applyBiasFile(pipeline_);
  }

  void run();

 private:
  void process(rosbag::Bag& in);
  void checkTopics(const rosbag::Bag& in, rosbag::View& view);
  void smoothInputs(rosbag::View& view);
  void dispatch(const rosbag::MessageInstance& m);
  void onTf(const rosbag::MessageInstance& m, bool is_static);
  void preloadStatic(const rosbag::Bag& in);
  void note(jle::Outcome outcome);
  void write();
  void writeSmoothed();
  std::string noLoads() const;
  void summarize(double total_s) const;
  void printDrops() const;

  const BagOptions& options_;
  LoadsSink& sink_;
  tf2::BufferCore tf_;
  jle::Tf2FrameSource frames_;
  jle::Pipeline pipeline_;
  std::unique_ptr<SmoothedBag> smoothed_;  // --zero-phase
  std::string joint_topic_;
  std::vector<std::string> wrench_topics_, plate_topics_;  // settings order
  bool have_tf_ = false;                                   // the bag has /tf or /tf_static
  long written_ = 0;                                       // loads given to the sink
  long smoothed_written_ = 0;                              // the smoothed stream's
  std::vector<jle::SignTally> signs_;  // per wrench input: its readings against the model
  ReuseBuffer buffer_;
  sensor_msgs::JointState joint_msg_;
  geometry_msgs::WrenchStamped wrench_msg_;
  tf2_msgs::TFMessage tf_msg_;
  Clock::duration compute_{0};
  // Each problem (problemKey) is said once (the node throttles), its count in the summary.
  std::unordered_set<std::size_t> said_;
  bool said_unknown_ = false;
  bool said_mimic_ = false;
};

void BagProcessor::run() {
  rosbag::Bag in;
  try {
    in.open(options_.bag, rosbag::bagmode::Read);
    process(in);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(jle::bagReadError(options_.bag, e));
  }
}

void BagProcessor::process(rosbag::Bag& in) {
  std::vector<std::string> topics{joint_topic_, "/tf", "/tf_static"};
  topics.insert(topics.end(), wrench_topics_.begin(), wrench_topics_.end());
  topics.insert(topics.end(), plate_topics_.begin(), plate_topics_.end());
  rosbag::View view(in, rosbag::TopicQuery(topics));
  checkTopics(in, view);
  preloadStatic(in);
  if (options_.smooth) smoothInputs(view);
  sink_.open(pipeline_);

  const long total = static_cast<long>(view.size());
  const Clock::time_point start = Clock::now();
  Clock::time_point next_progress = start + std::chrono::seconds(1);
  const bool progress = options_.summary && isatty(STDERR_FILENO) != 0;
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
  // A smoother's last joint states (differentiator/lag, the smoothed stream): their loads
  // too, numbered on.
  while (pipeline_.flush()) write();
  while (pipeline_.flushSmoothed()) writeSmoothed();
  if (written_ == 0) throw std::runtime_error(noLoads());
  sink_.commit();
  if (options_.summary) summarize(std::chrono::duration<double>(Clock::now() - start).count());
}

void BagProcessor::dispatch(const rosbag::MessageInstance& m) {
  const std::string& topic = m.getTopic();
  if (topic == "/tf" || topic == "/tf_static") return onTf(m, topic == "/tf_static");
  const bool joints = topic == joint_topic_;
  if (smoothed_ && joints)
    joint_msg_ = smoothed_->nextJoint();
  else if (smoothed_)
    wrench_msg_ = smoothed_->nextForce(topic);
  else if (joints)
    deserialize(m, buffer_, joint_msg_);
  else
    deserialize(m, buffer_, wrench_msg_);
  const Clock::time_point c0 = Clock::now();
  if (joints) {
    const jle::Outcome outcome = jle::feed(pipeline_, joint_msg_, m.getTime());
    compute_ += Clock::now() - c0;
    note(outcome);
    if (outcome == jle::Outcome::kPublished) write();
  } else {
    for (std::size_t k = 0; k < wrench_topics_.size(); ++k)
      if (topic == wrench_topics_[k])
        note(jle::feedWrench(pipeline_, static_cast<int>(k), wrench_msg_, m.getTime()));
    for (std::size_t k = 0; k < plate_topics_.size(); ++k)
      if (topic == plate_topics_[k])
        note(jle::feedPlate(pipeline_, static_cast<int>(k), wrench_msg_, m.getTime()));
    compute_ += Clock::now() - c0;
  }
  // A smoother's loads still to come when the bag looped back in time (Pipeline::takeDrained).
  while (pipeline_.takeDrained()) write();
  if (pipeline_.smoothedPublished()) writeSmoothed();
  while (pipeline_.takeDrainedSmoothed()) writeSmoothed();
}

void BagProcessor::write() {
  const jle::LoadsRecord& record = pipeline_.record();
  for (std::size_t k = 0; k < signs_.size(); ++k)
    jle::tallySign(record.inputs[k], pipeline_.settings().wrenches[k].force_threshold, signs_[k]);
  sink_.write(record, written_++);
}

void BagProcessor::writeSmoothed() {
  sink_.writeSmoothed(pipeline_.smoothedRecord(), smoothed_written_++);
}

// --zero-phase: the whole bag's inputs read and smoothed before the message path runs.
void BagProcessor::smoothInputs(rosbag::View& view) {
  std::vector<std::string> forces = wrench_topics_;
  forces.insert(forces.end(), plate_topics_.begin(), plate_topics_.end());
  smoothed_ = std::make_unique<SmoothedBag>(joint_topic_, forces);
  smoothed_->read(view, buffer_);
  const jle::CutoffChoice choice = smoothed_->smooth(options_.smoothing);
  std::fprintf(stderr,
               "process_bag: --zero-phase: Butterworth order %d per pass, forward and backward, "
               "cutoff %.6g Hz (%s); differentiator: central differences of the smoothed "
               "positions\n",
               options_.smoothing.order, choice.cutoff, jle::toString(choice.rule));
  for (const std::string& warning : choice.warnings)
    std::fprintf(stderr, "process_bag: warning: %s\n", warning.c_str());
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

// A static transform holds for all time, but a recorder may write the latched /tf_static
// after the first messages that need it (the node's listener waits for it, tf_wait):
// each static frame's first value is set before the bag is read; the messages in order
// then set theirs as they come (with their warnings), as before.
void BagProcessor::preloadStatic(const rosbag::Bag& in) {
  std::unordered_set<std::string> seen;
  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery("/tf_static"))) {
    deserialize(m, buffer_, tf_msg_);
    for (const geometry_msgs::TransformStamped& t : tf_msg_.transforms) {
      if (!seen.insert(t.child_frame_id).second) continue;
      try {
        tf_.setTransform(t, "process_bag", true);
      } catch (const std::exception&) {  // said when the message comes in order
      }
    }
  }
}

void BagProcessor::note(jle::Outcome outcome) {
  if (!pipeline_.unknownJoint().empty() && !said_unknown_) {
    said_unknown_ = true;
    std::fprintf(stderr, "process_bag: warning: %s: joint '%s' is not in the model: ignored\n",
                 joint_topic_.c_str(), pipeline_.unknownJoint().c_str());
  }
  if (!pipeline_.mimicContradiction().empty() && !said_mimic_) {
    said_mimic_ = true;
    std::fprintf(stderr, "process_bag: warning: %s: %s (further ones counted in the summary)\n",
                 joint_topic_.c_str(), pipeline_.mimicContradiction().c_str());
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
  std::fprintf(stderr,
               "process_bag: %ld joint states, %ld wrenches, %ld plate samples -> %ld loads%s\n"
               "process_bag: compute %.3f s (%.0f samples/s), total with I/O %.3f s "
               "(%.0f samples/s)\n",
               joint_states, c.received(jle::InputKind::kWrench),
               c.received(jle::InputKind::kPlate), c.count(jle::Outcome::kPublished),
               sink_.destination().c_str(), compute_s, compute_s > 0 ? samples / compute_s : 0.0,
               total_s, total_s > 0 ? samples / total_s : 0.0);
  if (pipeline_.hasSmoothed())
    std::fprintf(stderr,
                 "process_bag: smoothed stream (lag %.3g s): %ld loads; bandwidth %.3g Hz, "
                 "rates from the %s\n",
                 pipeline_.settings().smoothed.differentiator.lag, smoothed_written_,
                 pipeline_.smoothedBandwidth(),
                 pipeline_.smoothedVelocities() ? "measured velocities" : "positions");
  for (std::size_t k = 0; k < signs_.size(); ++k) {
    const jle::WrenchInputConfig& input = pipeline_.settings().estimator.wrenches[k];
    const std::string sign = jle::signWarning(input.sensor_joint, input.sign, signs_[k]);
    if (!sign.empty()) std::fprintf(stderr, "process_bag: warning: %s\n", sign.c_str());
  }
  const std::string bound = pipeline_.smoothedBandwidthBound();
  if (!bound.empty())
    std::fprintf(stderr, "process_bag: warning: smoothed stream's bandwidth on a bound: %s\n",
                 bound.c_str());
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
  if (c.mimic_contradictions)
    drops += (drops.empty() ? "" : ", ") + std::to_string(c.mimic_contradictions) +
             " with a mimic joint contradicting its leader";
  if (c.backJumps())
    drops += (drops.empty() ? "" : ", ") + std::to_string(c.backJumps()) + " time jumps back";
  if (c.forward_jumps)
    drops += (drops.empty() ? "" : ", ") + std::to_string(c.forward_jumps) + " time jumps forward";
  if (!drops.empty()) std::fprintf(stderr, "process_bag: not used: %s\n", drops.c_str());
  if (const long merged = c.count(jle::InputKind::kJointState, jle::Outcome::kMerged))
    std::fprintf(stderr,
                 "process_bag: %ld joint states merged with other publishers' of their instant "
                 "(stamps/merge_window)\n",
                 merged);
  if (c.held_samples)
    std::fprintf(stderr,
                 "process_bag: %ld samples held a joint from an earlier message (a publisher of "
                 "split joint states slower than the others, or stopped: flagged HELD_JOINT)\n",
                 c.held_samples);
}

}  // namespace

void processBag(const BagOptions& options, LoadsSink& sink) {
  jle::Settings settings;
  try {
    settings = jle::parseSettings(options.config.empty() ? jle::ParamValue()
                                                         : jle::loadYaml(options.config));
  } catch (const jle::SettingsError& e) {
    throw std::runtime_error(options.config + ": " + e.what());
  }
  if (options.accept_nonphysical_inertia) settings.accept_nonphysical_inertia = true;
  if (options.smooth) {
    // The positions are smoothed already: central differences differentiate them (exact
    // for the parabola through three samples, any spacing) and pass the forces as they are.
    jle::DifferentiatorConfig& d = settings.estimator.differentiator;
    d.type = jle::DifferentiatorType::kFiniteDifference;
    d.order = 2;
    d.window = 3;
    d.delay = 1;
    // Their velocities are the smoothed positions' rates: the positions say it all. And
    // the offline smoothing is the smoothed stream.
    settings.estimator.measured_velocity = jle::MeasuredVelocity::kNever;
    settings.smoothed.enabled = false;
  }
  const jle::Model<double> model =
      jle::modelFromUrdfFile(options.urdf, jle::modelOptions(settings));
  for (const std::string& w : model.warnings)
    std::fprintf(stderr, "process_bag: warning: robot model: %s\n", w.c_str());
  std::unique_ptr<BagProcessor> processor;
  try {
    processor = std::make_unique<BagProcessor>(options, settings, model, sink);
  } catch (const std::invalid_argument& e) {  // SettingsError too
    throw std::runtime_error((options.config.empty() ? options.urdf : options.config) + ": " +
                             e.what());
  }
  processor->run();
}

}  // namespace jle
