// process_bag: the node's estimate, offline, for every joint state of a bag: the same
// settings file, the same jle::Estimator, the same message handling
// (ros/message_inputs.hpp), in the bag's time order. docs/demo.md.
#include <joint_load_estimator/command_line.hpp>
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/csv.hpp>
#include <joint_load_estimator/estimator.hpp>
#include <joint_load_estimator/ros/message_inputs.hpp>
#include <joint_load_estimator/ros/settings.hpp>
#include <joint_load_estimator/sto.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <geometry_msgs/WrenchStamped.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
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
                   [--output OUT.bag | --csv OUT.csv] [--sto OUT.sto]
                   [--topic-prefix /joint_load_estimator]

Runs the joint_load_estimator node's estimate over a bag, offline and as fast as the
machine allows: the joint states and the configured wrench topics are read in the
bag's time order and handled exactly as the node handles them (partial joint states,
stamps, time jumps, wrench frames, the filters), so the loads are the ones the node
publishes when the bag is played to it, without the timing of a live system.

  --bag PATH           the input bag
  --urdf PATH          the robot (the node reads it from robot_description)
  --config PATH        the node's parameters as a YAML file (config/default.yaml lists
                       them; robot_description is not used here). Topic names that are
                       not absolute are taken in the root namespace. Default: every
                       default, no wrench input.
  --output PATH        write joint_load_estimator/JointLoads messages on
                       PREFIX/joint_loads, bag time = the estimate's stamp
  --csv PATH           write the loads as CSV instead: t, then for every published
                       joint JOINT.fx, .fy, .fz, .mx, .my, .mz, .effort (the columns of
                       joint_loads; wrenches in the child link frame, moment about the
                       joint origin), %.17g; with uncertainty enabled, then
                       JOINT.effort_stddev for every joint
  --sto PATH           also (or only) write them as an OpenSim storage file: the
                       same numbers, tab-separated, under OpenSim's column names
                       (time, JOINT_moment or JOINT_force, and
                       JOINT_on_CHILD_in_CHILD_fx ... _mz; docs/joint_loads.md)
                       Every output is written beside PATH and renamed onto it on
                       success only. With none, the loads are computed and counted.
  --topic-prefix NS    namespace of the output topic (default /joint_load_estimator)
  --help               this text

Not supported offline: a floating base (its pose comes from tf2), and wrenches
expressed in a frame that moves relative to their link (the node asks tf2): a wrench's
frame must be a URDF link rigid to the configured link; any other is an error. Force
plates (force_plates) need their pose in the config (position, orientation): there
is no tf2 to look it up.

Progress goes to standard error about once a second when it is a terminal; a summary
line at the end gives the samples per second of the estimator alone (compute) and of
the whole run (with reading and writing).

Exit status: 0 success; 1 a data error (unreadable bag or URDF, a bad setting, a
missing topic, an unresolvable wrench frame, no loads at all: the message names the
culprit); 2 a usage error.
)";

struct Options {
  std::string bag, urdf, config, output, csv, sto;
  std::string prefix = "/joint_load_estimator";
};


Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v = optionValues(
      argc, argv,
      {"--bag", "--urdf", "--config", "--output", "--csv", "--sto", "--topic-prefix"});
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

bool allFinite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

using Clock = std::chrono::steady_clock;

/// Counts of what happened to the messages, for the summary (the node's diagnostics).
struct Counters {
  long joint_states = 0, wrenches = 0, published = 0;
  long dropped_invalid = 0, dropped_order = 0, unknown_joints = 0, stale = 0, resets = 0;
  long waiting = 0;  // joint states before every coordinate had a position
};

/// The node's message handling over a bag. Everything the loop touches is allocated in
/// the constructor or by the first messages.
class BagProcessor {
 public:
  BagProcessor(const Options& options, const jle::Settings& settings,
               const jle::Model<double>& model)
      : options_(options),
        settings_(settings),
        estimator_(model, settings.estimator),
        segments_(jle::publishedSegments(model, settings.estimator.joints)),
        joints_(model, segments_),
        effort_ring_(kEffortHistory, std::vector<double>(segments_.size())),
        effort_time_(kEffortHistory, std::numeric_limits<double>::quiet_NaN()),
        row_(1 + (settings.estimator.uncertainty.enabled ? 8 : 7) * segments_.size()) {
    joint_topic_ = globalName(settings.joint_states_topic);
    for (std::size_t k = 0; k < settings.wrenches.size(); ++k) {
      WrenchTopic topic;
      topic.settings = settings.wrenches[k];
      topic.input = settings.estimator.wrenches[k];
      topic.topic = globalName(topic.settings.topic);
      wrench_topics_.push_back(topic);
    }
    for (const jle::PlateTopicSettings& p : settings.force_plates) plate_topics_.push_back(globalName(p.topic));
    if (settings.body_mass != 0.0) {
      body_mass_ = settings.body_mass > 0.0 ? settings.body_mass : model.totalMass();
      if (!(body_mass_ > 0.0))
        throw jle::SettingsError("parameter 'body_mass' is -1 but the URDF's total mass is " +
                                 std::to_string(body_mass_) + " kg");
      loads_.effort_per_kg.resize(segments_.size());
    }
    const std::size_t n = segments_.size();
    loads_.name.resize(n);
    loads_.wrench.resize(n);
    loads_.effort.resize(n);
    loads_.measured_effort.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      loads_.name[i] = model.joint_name[static_cast<std::size_t>(segments_[i])];
  }

  // An output not committed (an error on the way) is removed.
  ~BagProcessor() {
    if (out_bag_) out_bag_->close();
    if (!bag_temporary_.empty()) std::remove(bag_temporary_.c_str());
  }

  BagProcessor(const BagProcessor&) = delete;
  BagProcessor& operator=(const BagProcessor&) = delete;

  void run() {
    rosbag::Bag in;
    try {
      in.open(options_.bag, rosbag::bagmode::Read);
    } catch (const rosbag::BagException& e) {
      throw std::runtime_error(options_.bag + ": " + e.what());
    }
    std::vector<std::string> topics{joint_topic_};
    for (const WrenchTopic& w : wrench_topics_) topics.push_back(w.topic);
    for (const std::string& p : plate_topics_) topics.push_back(p);
    rosbag::View view(in, rosbag::TopicQuery(topics));
    checkTopics(in, view);
    openOutputs();

    const long total = static_cast<long>(view.size());
    const Clock::time_point start = Clock::now();
    Clock::time_point next_progress = start + std::chrono::seconds(1);
    const bool progress = isatty(STDERR_FILENO) != 0;
    bool progress_shown = false;
    long count = 0;
    for (const rosbag::MessageInstance& m : view) {
      const std::string& topic = m.getTopic();
      if (topic == joint_topic_) {
        deserialize(m, buffer_, joint_msg_);
        onJointState(m.getTime());
      } else {
        for (std::size_t k = 0; k < wrench_topics_.size(); ++k)
          if (topic == wrench_topics_[k].topic) {
            deserialize(m, buffer_, wrench_msg_);
            onWrench(k, m.getTime());
          }
        for (std::size_t k = 0; k < plate_topics_.size(); ++k)
          if (topic == plate_topics_[k]) {
            deserialize(m, buffer_, wrench_msg_);
            onPlate(k, m.getTime());
          }
      }
      if (progress && (++count & 1023) == 0 && Clock::now() >= next_progress) {
        next_progress += std::chrono::seconds(1);
        std::fprintf(stderr, "\rprocess_bag: %3.0f%%  %ld of %ld messages  %ld loads",
                     100.0 * static_cast<double>(count) / static_cast<double>(total), count, total,
                     counters_.published);
        progress_shown = true;
      }
    }
    if (progress_shown) std::fputc('\n', stderr);
    if (counters_.published == 0) throw std::runtime_error(noLoads());
    closeOutputs();
    const double total_s = std::chrono::duration<double>(Clock::now() - start).count();
    summarize(total_s);
  }

 private:
  static constexpr std::size_t kEffortHistory = 128;  // as the node

  struct WrenchTopic {
    jle::WrenchTopicSettings settings;
    jle::WrenchInputConfig input;  // settings.estimator.wrenches[k]
    std::string topic;
    std::string last_frame;
    bool resolved = false;
    Eigen::Matrix3d R_link_frame = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p_link_frame = Eigen::Vector3d::Zero();
  };

  std::string noLoads() const {
    printDrops();
    const int missing = joints_.firstMissing();
    if (missing >= 0)
      return "no loads: joint '" +
             estimator_.model().coordinate_names[static_cast<std::size_t>(missing)] +
             "' never had a position in " + joint_topic_;
    return "no loads from " + std::to_string(counters_.joint_states) + " joint states on " +
           joint_topic_ + ": too few for the filter, or every one dropped";
  }

  void checkTopics(const rosbag::Bag& in, rosbag::View& view) {
    const std::map<std::string, std::string> expected = [&] {
      std::map<std::string, std::string> e{{joint_topic_, "sensor_msgs/JointState"}};
      for (const WrenchTopic& w : wrench_topics_) e[w.topic] = "geometry_msgs/WrenchStamped";
      for (const std::string& p : plate_topics_) e[p] = "geometry_msgs/WrenchStamped";
      return e;
    }();
    std::map<std::string, bool> present;
    for (const rosbag::ConnectionInfo* c : view.getConnections()) {
      const std::string& type = expected.at(c->topic);
      const std::string md5 = type == "sensor_msgs/JointState"
                                  ? ros::message_traits::md5sum<sensor_msgs::JointState>()
                                  : ros::message_traits::md5sum<geometry_msgs::WrenchStamped>();
      if (c->datatype != type || c->md5sum != md5)
        throw std::runtime_error(options_.bag + ": topic '" + c->topic + "' holds " + c->datatype +
                                 ", expected " + type);
      present[c->topic] = true;
    }
    if (!present.count(joint_topic_)) {
      std::string all;
      rosbag::View everything(in);
      std::map<std::string, std::string> seen;
      for (const rosbag::ConnectionInfo* c : everything.getConnections())
        seen[c->topic] = c->datatype;
      for (const auto& t : seen) all += (all.empty() ? "" : ", ") + t.first + " (" + t.second + ")";
      throw std::runtime_error(
          options_.bag + ": no messages on the joint states topic '" + joint_topic_ +
          "' (parameter joint_states_topic); the bag has: " + (all.empty() ? "nothing" : all));
    }
    for (const WrenchTopic& w : wrench_topics_)
      if (!present.count(w.topic))
        std::fprintf(stderr,
                     "process_bag: warning: no messages on wrench topic '%s' in %s: the loads "
                     "are computed without it\n",
                     w.topic.c_str(), options_.bag.c_str());
    for (const std::string& p : plate_topics_)
      if (!present.count(p))
        std::fprintf(stderr,
                     "process_bag: warning: no messages on force plate topic '%s' in %s: the "
                     "loads are computed without it\n",
                     p.c_str(), options_.bag.c_str());
  }

  void openOutputs() {
    if (!options_.output.empty()) {
      bag_temporary_ = options_.output + ".partial";
      out_bag_ = std::make_unique<rosbag::Bag>();
      try {
        out_bag_->open(bag_temporary_, rosbag::bagmode::Write);
        // rosbag writes an uncompressed chunk to the file record by record; an LZ4 chunk
        // is built in memory and written at once: a third faster here, and smaller.
        out_bag_->setCompression(rosbag::compression::LZ4);
      } catch (const rosbag::BagException& e) {
        throw std::runtime_error(options_.output + ": " + e.what());
      }
      out_topic_ = options_.prefix + "/joint_loads";
    }
    std::vector<std::string> names{"t"};
    for (const std::string& joint : loads_.name)
      for (const char* c : {".fx", ".fy", ".fz", ".mx", ".my", ".mz", ".effort"})
        names.push_back(joint + c);
    if (!options_.csv.empty()) {
      csv_ = std::make_unique<jle::CsvWriter>(options_.csv);
      std::vector<std::string> csv_names = names;
      if (settings_.estimator.uncertainty.enabled)
        for (const std::string& joint : loads_.name) csv_names.push_back(joint + ".effort_stddev");
      csv_->writeHeader(csv_names);
    }
    if (!options_.sto.empty()) {
      sto_ = std::make_unique<jle::StoWriter>(options_.sto);
      sto_->writeHeader(
          jle::stoColumnNames(estimator_.model(), names, jle::WrenchFrame::kChild));
    }
  }

  void closeOutputs() {
    if (out_bag_) {
      out_bag_->close();
      out_bag_.reset();
      if (std::rename(bag_temporary_.c_str(), options_.output.c_str()) != 0)
        throw std::runtime_error(options_.output + ": cannot rename " + bag_temporary_ +
                                 " onto it");
      bag_temporary_.clear();
    }
    if (csv_) csv_->commit();
    if (sto_) sto_->commit();
  }

  // Once per kind of problem, with the count in the summary (the node throttles). The
  // callers test `said` first, so that a repeated problem builds no message.
  void warnOnce(bool& said, const std::string& what) {
    said = true;
    std::fprintf(stderr, "process_bag: warning: %s (further ones counted in the summary)\n",
                 what.c_str());
  }

  // The estimator's time axis, as the node's: seconds since the whole second of the
  // first stamp (a double holds epoch seconds only to 2.4e-7 s), mapped back exactly
  // for the output.
  double relative(const ros::Time& stamp) {
    if (time_ref_.isZero()) time_ref_ = ros::Time(stamp.sec, 0);
    return (stamp - time_ref_).toSec();
  }
  ros::Time absolute(double t) const { return time_ref_ + ros::Duration(t); }

  void onJointState(const ros::Time& bag_time) {
    ++counters_.joint_states;
    const sensor_msgs::JointState& msg = joint_msg_;
    const std::size_t n = msg.name.size();
    if (msg.position.size() != n || (!msg.velocity.empty() && msg.velocity.size() != n) ||
        (!msg.effort.empty() && msg.effort.size() != n) || !allFinite(msg.position) ||
        !allFinite(msg.velocity) || !allFinite(msg.effort)) {
      ++counters_.dropped_invalid;
      if (!said_invalid_)
        warnOnce(said_invalid_, joint_topic_ +
                                    ": a message with mismatched sizes or a "
                                    "non-finite value was dropped (stamp " +
                                    std::to_string(msg.header.stamp.toSec()) + ")");
      return;
    }
    const ros::Time stamp = msg.header.stamp.isZero() ? bag_time : msg.header.stamp;
    const double t = relative(stamp);
    // A stamp older than the previous by more than the threshold: a jump back (the node
    // also resets when its clock goes back, which a bag read in order cannot do).
    if (have_last_ && last_t_ - t > settings_.time_jump_threshold) {
      const Clock::time_point c0 = Clock::now();
      estimator_.reset();
      compute_ += Clock::now() - c0;
      effort_count_ = 0;
      have_last_ = false;
      ++counters_.resets;
    }
    const int unknown = joints_.update(msg.name, msg.position, msg.effort);
    if (unknown >= 0) {
      ++counters_.unknown_joints;
      if (!said_unknown_)
        warnOnce(said_unknown_, joint_topic_ + ": joint '" +
                                    msg.name[static_cast<std::size_t>(unknown)] +
                                    "' is not in the model: ignored");
    }
    if (!msg.effort.empty()) {
      effort_ring_[effort_head_] = joints_.effort();  // same size: no allocation
      effort_time_[effort_head_] = t;
      effort_head_ = (effort_head_ + 1) % kEffortHistory;
      if (effort_count_ < kEffortHistory) ++effort_count_;
    }
    if (joints_.firstMissing() >= 0) {
      ++counters_.waiting;
      return;
    }
    const Clock::time_point c0 = Clock::now();
    const jle::SampleStatus status = estimator_.addJointSample(t, joints_.q().data());
    compute_ += Clock::now() - c0;
    switch (status) {
      case jle::SampleStatus::kPublished: write(); break;
      case jle::SampleStatus::kDuplicate:
      case jle::SampleStatus::kOutOfOrder: ++counters_.dropped_order; return;
      case jle::SampleStatus::kNonFinite: ++counters_.dropped_invalid; return;
      case jle::SampleStatus::kStale: ++counters_.stale; break;
      default: break;
    }
    have_last_ = true;
    last_t_ = t;
  }

  void onWrench(std::size_t k, const ros::Time& bag_time) {
    ++counters_.wrenches;
    WrenchTopic& topic = wrench_topics_[k];
    const geometry_msgs::WrenchStamped& msg = wrench_msg_;
    const Eigen::Vector3d f(msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z);
    const Eigen::Vector3d m(msg.wrench.torque.x, msg.wrench.torque.y, msg.wrench.torque.z);
    if (!f.allFinite() || !m.allFinite()) {
      ++counters_.dropped_invalid;
      if (!said_wrench_invalid_)
        warnOnce(said_wrench_invalid_, topic.topic + ": non-finite force or torque: dropped");
      return;
    }
    const std::string& frame =
        topic.settings.frame.empty() ? msg.header.frame_id : topic.settings.frame;
    if (!topic.resolved || frame != topic.last_frame) {
      const std::string& link = topic.input.link;
      if (frame.empty())
        throw std::runtime_error(topic.topic +
                                 ": empty header.frame_id and no 'frame' "
                                 "configured for it");
      if (!jle::rigidFrameInLink(estimator_.model(), link, frame, topic.R_link_frame,
                                 topic.p_link_frame))
        throw std::runtime_error(topic.topic + ": frame '" + frame +
                                 "' is not a URDF link rigid to link '" + link +
                                 "'; process_bag has no tf2 (the node would ask tf2 for it)");
      topic.last_frame = frame;
      topic.resolved = true;
    }
    const ros::Time stamp = msg.header.stamp.isZero() ? bag_time : msg.header.stamp;
    const Clock::time_point c0 = Clock::now();
    Eigen::Vector3d f_link, m_link;
    jle::wrenchInLink(topic.R_link_frame, topic.p_link_frame, f, m, f_link, m_link);
    const bool taken = estimator_.addWrench(static_cast<int>(k), relative(stamp), f_link, m_link);
    compute_ += Clock::now() - c0;
    if (!taken) ++counters_.dropped_order;
  }

  // A force plate sample: as the node, with the configured plate pose.
  void onPlate(std::size_t k, const ros::Time& bag_time) {
    ++counters_.wrenches;
    const geometry_msgs::WrenchStamped& msg = wrench_msg_;
    const Eigen::Vector3d f(msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z);
    const Eigen::Vector3d m(msg.wrench.torque.x, msg.wrench.torque.y, msg.wrench.torque.z);
    if (!f.allFinite() || !m.allFinite()) {
      ++counters_.dropped_invalid;
      if (!said_wrench_invalid_)
        warnOnce(said_wrench_invalid_, plate_topics_[k] + ": non-finite force or torque: dropped");
      return;
    }
    const ros::Time stamp = msg.header.stamp.isZero() ? bag_time : msg.header.stamp;
    const Clock::time_point c0 = Clock::now();
    const bool taken = estimator_.addPlateSample(static_cast<int>(k), relative(stamp), f, m);
    compute_ += Clock::now() - c0;
    if (!taken) ++counters_.dropped_order;
  }

  void write() {
    ++counters_.published;
    if (!out_bag_ && !csv_ && !sto_) return;
    const jle::Data<double>& data = estimator_.data();
    const double stamp = estimator_.stamp();
    // The measured efforts that belong to the stamp the estimate describes (as the node).
    const std::vector<double>* measured = nullptr;
    for (std::size_t i = 0; i < effort_count_; ++i) {
      const std::size_t slot = (effort_head_ + kEffortHistory - 1 - i) % kEffortHistory;
      if (effort_time_[slot] == stamp) {
        measured = &effort_ring_[slot];
        break;
      }
    }
    const ros::Time t = absolute(stamp);
    double* row = row_.data();
    *row++ = t.toSec();
    for (std::size_t i = 0; i < segments_.size(); ++i) {
      const std::size_t s = static_cast<std::size_t>(segments_[i]);
      geometry_msgs::Wrench& w = loads_.wrench[i];
      w.force.x = *row++ = data.force[s].x();
      w.force.y = *row++ = data.force[s].y();
      w.force.z = *row++ = data.force[s].z();
      w.torque.x = *row++ = data.moment[s].x();
      w.torque.y = *row++ = data.moment[s].y();
      w.torque.z = *row++ = data.moment[s].z();
      loads_.effort[i] = *row++ = data.effort[s];
      loads_.measured_effort[i] =
          measured ? (*measured)[i] : std::numeric_limits<double>::quiet_NaN();
    }
    const jle::UncertaintyConfig& u = settings_.estimator.uncertainty;
    if (u.enabled) {  // the node's covariance fields (estimator_node.cpp publish())
      const std::size_t per_joint = u.diagonal_only ? 6 : 36;
      loads_.covariance.resize(per_joint * segments_.size());
      loads_.effort_stddev.resize(segments_.size());
      for (std::size_t i = 0; i < segments_.size(); ++i) {
        const Eigen::Matrix<double, 6, 6>& C = estimator_.covariance(segments_[i]);
        double* out = &loads_.covariance[per_joint * i];
        for (int r = 0; r < 6; ++r)
          if (u.diagonal_only)
            out[r] = C(r, r);
          else
            for (int c = 0; c < 6; ++c) out[6 * r + c] = C(r, c);
        loads_.effort_stddev[i] = *row++ = std::sqrt(estimator_.effortVariance(segments_[i]));
      }
    }
    for (std::size_t i = 0; i < loads_.effort_per_kg.size(); ++i)
      loads_.effort_per_kg[i] = loads_.effort[i] / body_mass_;
    if (csv_) csv_->writeRow(row_.data(), row_.size());
    if (sto_) sto_->writeRow(row_.data(), row_.size());
    if (out_bag_) {
      loads_.header.stamp = t;
      loads_.header.seq = static_cast<std::uint32_t>(counters_.published - 1);
      out_bag_->write(out_topic_, t, loads_);
    }
  }

  void summarize(double total_s) const {
    const double compute_s = std::chrono::duration<double>(compute_).count();
    const double samples = static_cast<double>(counters_.joint_states);
    const std::string to = !options_.output.empty() ? " to " + options_.output
                           : !options_.csv.empty()  ? " to " + options_.csv
                           : !options_.sto.empty()  ? " to " + options_.sto
                                                    : " (not written)";
    std::fprintf(stderr,
                 "process_bag: %ld joint states, %ld wrenches -> %ld loads%s\n"
                 "process_bag: compute %.3f s (%.0f samples/s), total with I/O %.3f s "
                 "(%.0f samples/s)\n",
                 counters_.joint_states, counters_.wrenches, counters_.published, to.c_str(),
                 compute_s, compute_s > 0 ? samples / compute_s : 0.0, total_s,
                 total_s > 0 ? samples / total_s : 0.0);
    printDrops();
  }

  void printDrops() const {
    const Counters& c = counters_;
    if (c.dropped_invalid || c.dropped_order || c.unknown_joints || c.stale || c.resets ||
        c.waiting)
      std::fprintf(stderr,
                   "process_bag: dropped %ld invalid, %ld stamp order; %ld with unknown "
                   "joints; %ld before every joint had a position; %ld stale; %ld time "
                   "jumps back\n",
                   c.dropped_invalid, c.dropped_order, c.unknown_joints, c.waiting, c.stale,
                   c.resets);
  }

 private:
  const Options& options_;
  const jle::Settings& settings_;
  jle::Estimator estimator_;
  std::vector<int> segments_;
  jle::JointStateMap joints_;
  std::string joint_topic_;
  std::vector<WrenchTopic> wrench_topics_;
  std::vector<std::string> plate_topics_;  // settings.force_plates order
  double body_mass_ = 0.0;                 // [kg] effort_per_kg divisor; 0: none
  ReuseBuffer buffer_;
  sensor_msgs::JointState joint_msg_;
  geometry_msgs::WrenchStamped wrench_msg_;
  joint_load_estimator::JointLoads loads_;
  std::vector<std::vector<double>> effort_ring_;
  std::vector<double> effort_time_;
  std::size_t effort_head_ = 0, effort_count_ = 0;
  std::vector<double> row_;
  std::unique_ptr<rosbag::Bag> out_bag_;
  std::string bag_temporary_, out_topic_;
  std::unique_ptr<jle::CsvWriter> csv_;
  std::unique_ptr<jle::StoWriter> sto_;
  bool have_last_ = false;
  ros::Time time_ref_;  // origin of the estimator's time axis
  double last_t_ = 0.0;
  Clock::duration compute_{0};
  Counters counters_;
  bool said_invalid_ = false, said_unknown_ = false, said_wrench_invalid_ = false;
};

void run(const Options& options) {
  jle::Settings settings;
  try {
    settings = jle::parseSettings(options.config.empty() ? XmlRpc::XmlRpcValue()
                                                         : jle::loadYaml(options.config));
  } catch (const jle::SettingsError& e) {
    throw std::runtime_error(options.config + ": " + e.what());
  }
  if (settings.floating_base)
    throw std::runtime_error(options.config +
                             ": floating_base is not supported by process_bag "
                             "(the base pose comes from tf2); use the node");
  for (std::size_t k = 0; k < settings.force_plates.size(); ++k)
    if (!settings.force_plates[k].pose_configured)
      throw std::runtime_error(options.config + ": force_plates[" + std::to_string(k) + "] '" +
                               settings.estimator.plates[k].plate.name +
                               "' has no position/orientation: process_bag has no tf2 to look "
                               "up the plate's pose");
  const jle::Model<double> model =
      jle::modelFromUrdfFile(options.urdf, jle::modelOptions(settings));
  jle::completeSensorLinks(model, settings);
  if (model.floating_base)
    throw std::runtime_error(options.urdf +
                             ": a floating-base model is not supported by "
                             "process_bag (the base pose comes from tf2); use the node");
  for (const std::string& w : model.warnings)
    std::fprintf(stderr, "process_bag: warning: robot model: %s\n", w.c_str());
  std::unique_ptr<BagProcessor> processor;
  try {
    processor = std::make_unique<BagProcessor>(options, settings, model);
  } catch (const jle::SettingsError& e) {
    throw std::runtime_error((options.config.empty() ? options.urdf : options.config) + ": " +
                             e.what());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error((options.config.empty() ? options.urdf : options.config) + ": " +
                             e.what());
  }
  processor->run();
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "process_bag", kUsage, parseOptions, run);
}
