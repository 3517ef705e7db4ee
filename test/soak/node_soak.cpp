// Soak of the real node over ROS (run by test/soak/node_soak.sh, which starts a
// private master and the joint_load_estimator executable): SAMPLES joint states
// of the robot in robot_description at 500 Hz of simulated time, sent as fast as
// the node keeps up, with a wrench every 10 samples and a bad message every 10
// samples (every kind the node counts, cycled: invalid values and sizes, stamp
// order, rogue stamps of joint states and wrenches, unknown frames and joints),
// plus a few backward jumps of time (a looping bag, confirmed by
// stamps/jump_confirm joint states on the new timeline). Flow control: at most --window joint-state
// messages unacknowledged (a message is acknowledged by the loads of it or of a later sample; the
// node's subscriber queues hold 100), so no queue drops anything. Checks
//  1. every good sample produces its loads: the sequence of ~joint_loads stamps
//  equals the
//     expected one, derived from the filter's documented warm-up
//     (DifferentiatorBank::warmup(), "samples needed after a reset before the
//     first estimate", and its delay) after the start and after each jump back;
//  2. the node's diagnostics, in a message published after the last input,
//  equal the
//     injected counts under each key;
//  3. the node's VmRSS is flat: at 100% of the samples it exceeds the value at
//  10% (the
//     buffers have grown to size by then) by at most --rss-limit kB;
//  4. the node is alive at the end;
//  5. /diagnostics came at the node's diagnostic_period (wall clock) throughout.
//  6. the loads equal, to 1e-12 at every stamp, those of the clean stream (the good
//     messages alone, in the order sent) through an in-process jle::Pipeline with the
//     same settings. The tool wrench is constant, so that a joint state and a wrench
//     arriving in either order (two TCP connections) read the same value; after each
//     (re)start the first wrench is sent only once the node has taken the joint
//     states before it.
// Prints a summary; exits 1 on a failed check, 2 on a usage error.
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>
#include <joint_load_estimator/settings/settings_reader.hpp>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <signal.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

const char kUsage[] =
    "usage: node_soak --pid PID --config YAML [--samples N] "
    "[--window N] [--jumps N]\n"
    "                 [--rss-limit KB]\n"
    "Drives a running joint_load_estimator node (process "
    "PID, parameters from YAML, the\n"
    "same file the node was given; its wrenches[0] is fed) "
    "with N joint states (default\n"
    "1000000) and bad messages; checks its loads, "
    "diagnostics and memory. --window: joint\n"
    "states in flight (default 32, below the node's queue of "
    "100, and their time below the wrench timeout); --jumps: backward time\n"
    "jumps (default 3); --rss-limit: allowed VmRSS growth "
    "from 10% to 100% (default 256).\n";

struct Options {
  long samples = 1000000;
  long window = 32;
  long jumps = 3;
  long rss_limit_kb = 256;
  long pid = 0;
  std::string config;
};

long toLong(const std::map<std::string, std::string>& v, const std::string& key, long fallback,
            long min) {
  auto it = v.find(key);
  if (it == v.end()) return fallback;
  return static_cast<long>(
      jle::cli::parseInteger(key, it->second, static_cast<unsigned long long>(min),
                             static_cast<unsigned long long>(std::numeric_limits<long>::max())));
}

Options parseOptions(int argc, char** argv) {
  const auto v = jle::cli::optionValues(
      argc, argv, {"--samples", "--window", "--jumps", "--rss-limit", "--pid", "--config"});
  Options o;
  o.samples = toLong(v, "--samples", o.samples, 1000);
  o.window = toLong(v, "--window", o.window, 1);
  o.jumps = toLong(v, "--jumps", o.jumps, 1);
  o.rss_limit_kb = toLong(v, "--rss-limit", o.rss_limit_kb, 0);
  o.pid = toLong(v, "--pid", 0, 1);
  if (!o.pid) throw jle::cli::UsageError("--pid is required");
  if (!v.count("--config")) throw jle::cli::UsageError("--config is required");
  o.config = v.at("--config");
  return o;
}

long vmRssKb(long pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  return -1;
}

// The kinds of bad input, each counted by the node under one diagnostics key.
enum Bad {
  kNanPosition,
  kInfPosition,
  kPositionLength,
  kVelocityLength,
  kUnknownJoint,
  kDuplicateStamp,
  kBackwardStamp,
  kNanWrench,
  kBackwardWrench,
  kUnresolvedFrame,
  kDuplicateName,  // a joint named twice
  kEmpty,          // a joint state with no joint: not a sample
  kNanEffort,      // a good sample with a NaN effort: its loads are published
  kRogueAhead,     // a joint state stamped 2 h ahead
  kRogueBack,      // a joint state stamped 2 h back
  kRogueZero,      // a joint state stamped 0 on a stamped stream
  kWrenchAhead,    // a wrench stamped 2 h ahead
  kWrenchBack,     // a wrench stamped 2 h back
  kWrenchZero,     // a wrench stamped 0
  kWrenchLead,     // a wrench ahead of the joint states by 0.5 s (timeout 0.1 s)
  kTimeJump,       // not in the periodic cycle: --jumps times
  kUnconfirmed,    // the joint states of a jump before the one confirming it
  kKinds
};
const char* const kBadName[kKinds] = {
    "nan_position",    "inf_position",   "position_length", "velocity_length", "unknown_joint",
    "duplicate_stamp", "backward_stamp", "nan_wrench",      "backward_wrench", "unresolved_frame",
    "duplicate_name",  "empty",          "nan_effort",      "rogue_ahead",     "rogue_back",
    "rogue_zero",      "wrench_ahead",   "wrench_back",     "wrench_zero",     "wrench_lead",
    "time_jump_back",  "unconfirmed"};
const char* const kBadKey[kKinds] = {"dropped: invalid",
                                     "dropped: invalid",
                                     "dropped: invalid",
                                     "dropped: invalid",
                                     "messages with unknown joints",
                                     "dropped: stamp order",
                                     "dropped: stamp order",
                                     "dropped: invalid",
                                     "dropped: stamp order",
                                     "dropped: unresolved frame",
                                     "dropped: invalid",
                                     "not used: no needed joint",
                                     "efforts not compared: non-finite",
                                     "dropped: rogue stamp",
                                     "dropped: rogue stamp",
                                     "dropped: rogue stamp",
                                     "dropped: rogue stamp",
                                     "dropped: rogue stamp",
                                     "dropped: rogue stamp",
                                     "dropped: rogue stamp",
                                     "time jumps back",
                                     "dropped: rogue stamp"};
constexpr long kBadPeriod = 10;          // one bad message per 10 good samples
constexpr long kWrenchPeriod = 10;       // one wrench per 10 joint samples (50 Hz)
constexpr std::int64_t kDtNs = 2000000;  // 500 Hz
constexpr std::int64_t kTwoHoursNs = 7200LL * 1000000000LL;
constexpr double kWrenchFx = 10.0;  // [N] the tool wrench's constant force along x
constexpr double kExact = 1e-12;    // [N, N m] the loads against the clean stream's
constexpr std::int64_t kEpochNs = 1700000000LL * 1000000000LL;

ros::Time fromNs(std::int64_t ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(ns));
  return t;
}

class Driver {
 public:
  Driver(const Options& o) : o_(o) {
    const jle::Settings settings = jle::parseSettings(jle::loadYaml(o.config));
    if (settings.wrenches.empty())
      throw std::runtime_error(o.config + ": the soak needs at least one entry in 'wrenches'");
    if (settings.estimator.decimation != 1)
      throw std::runtime_error(o.config + ": the soak expects decimation 1");
    // A wrench is sent beside the newest joint state, up to `window` samples ahead of
    // the one the node is taking: within its timeout, or it is a rogue stamp.
    if (1e-9 * static_cast<double>(o.window * kDtNs) >= settings.estimator.wrenches[0].timeout)
      throw std::runtime_error("--window " + std::to_string(o.window) +
                               ": its joint states span the wrench timeout");
    const jle::DifferentiatorBank bank(settings.estimator.differentiator, 1);
    warmup_ = bank.warmup();
    delay_ = bank.config().delay;
    jump_back_ns_ = static_cast<std::int64_t>(2e9 * settings.time_jump_threshold);
    wrench_link_ = settings.estimator.wrenches[0].link;
    diag_period_ = settings.diagnostic_period;

    jump_confirm_ = settings.stamps.jump_confirm;

    std::string urdf;
    if (!nh_.getParam(settings.robot_description, urdf))
      throw std::runtime_error("parameter '" + settings.robot_description + "' is not set");
    if (settings.floating_base) throw std::runtime_error("the soak drives fixed-base models");
    model_ = jle::modelFromUrdfString(urdf, jle::modelOptions(settings));
    names_ = model_.coordinate_names;
    reference_ = std::make_unique<jle::Pipeline>(model_, settings, nullptr);

    const std::string node = "/joint_load_estimator";
    joint_pub_ = nh_.advertise<sensor_msgs::JointState>(settings.joint_states_topic, 1000);
    wrench_pub_ = nh_.advertise<geometry_msgs::WrenchStamped>(settings.wrenches[0].topic, 1000);
    loads_sub_ = nh_.subscribe(node + "/joint_loads", 1000, &Driver::onLoads, this,
                               ros::TransportHints().tcpNoDelay());
    diag_sub_ = nh_.subscribe("/diagnostics", 100, &Driver::onDiagnostics, this);
  }

  bool run();

 private:
  // Sample i of the schedule: a jump back when due, the good sample, its wrench, a bad
  // message when due.
  bool step(long i, long& next_jump);
  void onLoads(const joint_load_estimator::JointLoads::ConstPtr& msg) {
    const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
    compareWithCleanStream(*msg, stamp);
    const std::size_t r = received_.size();
    received_.push_back(stamp);
    if (r < expected_.size()) acked_ = std::max(acked_, trigger_[r]);
    bool finite = msg->name.size() == names_.size() && msg->effort.size() == names_.size();
    for (double e : msg->effort) finite = finite && std::isfinite(e);
    for (const auto& w : msg->wrench)
      finite = finite && std::isfinite(w.force.x) && std::isfinite(w.force.y) &&
               std::isfinite(w.force.z) && std::isfinite(w.torque.x) && std::isfinite(w.torque.y) &&
               std::isfinite(w.torque.z);
    if (!finite) ++bad_loads_;
  }

  // The next loads of the clean stream (reference_) against the node's, in order.
  void compareWithCleanStream(const joint_load_estimator::JointLoads& msg, std::int64_t stamp) {
    if (clean_.empty() || clean_.front().stamp != stamp ||
        clean_.front().values.size() != 7 * msg.name.size()) {
      ++mismatched_;
      if (!clean_.empty()) clean_.pop_front();
      return;
    }
    const std::vector<double>& v = clean_.front().values;
    for (std::size_t j = 0; j < msg.name.size(); ++j) {
      const auto& w = msg.wrench[j];
      const double got[7] = {w.force.x,  w.force.y,  w.force.z,    w.torque.x,
                             w.torque.y, w.torque.z, msg.effort[j]};
      for (int c = 0; c < 7; ++c) {
        const double d = std::abs(got[c] - v[7 * j + c]);
        worst_difference_ = std::max(worst_difference_, std::isnan(d) ? HUGE_VAL : d);
      }
    }
    ++compared_;
    clean_.pop_front();
  }

  // The clean stream's joint state: the good sample alone (no ghost joint, no effort).
  void takeClean(std::int64_t stamp, const std::vector<double>& position) {
    static const std::vector<double> none;
    if (reference_->onJointState(stamp, nowNs(), names_, position, none, none) !=
        jle::Outcome::kPublished)
      return;
    const jle::LoadsRecord& r = reference_->record();
    CleanLoads c{r.stamp, {}};
    for (std::size_t j = 0; j < r.effort.size(); ++j) {
      for (int a = 0; a < 3; ++a) c.values.push_back(r.force[j][a]);
      for (int a = 0; a < 3; ++a) c.values.push_back(r.moment[j][a]);
      c.values.push_back(r.effort[j]);
    }
    clean_.push_back(std::move(c));
  }

  static std::int64_t nowNs() { return static_cast<std::int64_t>(ros::Time::now().toNSec()); }

  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
    for (const auto& status : msg->status) {
      if (status.name.find("joint loads") == std::string::npos) continue;
      std::map<std::string, long> values;
      for (const auto& kv : status.values) {
        char* end = nullptr;
        const long x = std::strtol(kv.value.c_str(), &end, 10);
        if (end && *end == '\0' && !kv.value.empty()) values[kv.key] = x;
      }
      last_diag_ = values;
      ++diag_count_;
    }
  }

  long diag(const std::string& key) const {
    auto it = last_diag_.find(key);
    return it == last_diag_.end() ? -1 : it->second;
  }

  // Spins until pred() holds; false after 10 s without a new load or
  // diagnostics message (the node stalled or died).
  template <typename Pred>
  bool spinUntil(Pred pred, const char* what) {
    std::size_t seen = received_.size();
    long seen_diag = diag_count_;
    auto last_progress = std::chrono::steady_clock::now();
    while (!pred()) {
      if (!ros::ok()) return false;
      ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.01));
      if (received_.size() != seen || diag_count_ != seen_diag) {
        seen = received_.size();
        seen_diag = diag_count_;
        last_progress = std::chrono::steady_clock::now();
      } else if (std::chrono::steady_clock::now() - last_progress > std::chrono::seconds(10)) {
        std::printf(
            "FAILED: no progress for 10 s while waiting for %s (loads expected "
            "so far "
            "%zu, received %zu: a sample was dropped or not published)\n",
            what, expected_.size(), received_.size());
        return false;
      }
    }
    return true;
  }

  // Waits for room in the window, then publishes one joint-state message.
  bool sendJoint(const sensor_msgs::JointState& msg) {
    if (!spinUntil([&] { return sent_ - (acked_ + 1) < o_.window; }, "the node's loads"))
      return false;
    joint_pub_.publish(msg);
    ++sent_;
    ros::getGlobalCallbackQueue()->callAvailable();
    return true;
  }

  // The tool wrench (constant), to the node and the clean stream.
  void sendGoodWrench(std::int64_t stamp) {
    sendWrench(stamp, kWrenchFx, wrench_link_);
    reference_->onWrench(0, stamp, nowNs(), wrench_link_, Eigen::Vector3d(kWrenchFx, 2.0, -5.0),
                         Eigen::Vector3d(0.1, 0.0, 0.0));
    last_wrench_ns_ = stamp;
    wrench_in_segment_ = true;
  }

  // After a (re)start: the first wrench once the node has taken every joint state sent
  // (so that it reads no wrench at them, as the clean stream), then nothing more until
  // it has taken the wrench.
  bool startWrench() {
    if (!spinUntil([&] { return diag("joint states received") >= sent_; },
                   "the node to take the joint states of the (re)start"))
      return false;
    sendGoodWrench(last_good_ns_);
    return spinUntil([&] { return diag("wrenches received") >= wrenches_sent_; },
                     "the node to take the first wrench of the (re)start");
  }

  void sendWrench(std::int64_t stamp, double fx, const std::string& frame) {
    wrench_msg_.header.stamp = fromNs(stamp);
    wrench_msg_.header.frame_id = frame;
    wrench_msg_.wrench.force.x = fx;
    wrench_msg_.wrench.force.y = 2.0;
    wrench_msg_.wrench.force.z = -5.0;
    wrench_msg_.wrench.torque.x = 0.1;
    wrench_pub_.publish(wrench_msg_);
    ++wrenches_sent_;
  }

  // The next good sample (positions: slow sines), the loads it must produce
  // recorded; `unconfirmed`: a joint state of a jump before the one confirming it,
  // which publishes nothing.
  bool sendGood(bool ghost, bool nan_effort = false, bool unconfirmed = false) {
    const std::int64_t stamp = next_ns_;
    next_ns_ += kDtNs;
    const double t = 1e-9 * static_cast<double>(stamp - kEpochNs);
    good_msg_.header.stamp = fromNs(stamp);
    good_msg_.name = names_;
    good_msg_.position.resize(names_.size());
    for (std::size_t k = 0; k < names_.size(); ++k)
      good_msg_.position[k] = 0.5 * std::sin(2.0 * M_PI * (0.2 + 0.05 * k) * t + k);
    takeClean(stamp, good_msg_.position);
    if (ghost) {
      good_msg_.name.push_back("ghost_joint");
      good_msg_.position.push_back(1.0);
    }
    good_msg_.effort.clear();
    if (nan_effort) {
      good_msg_.effort.assign(names_.size(), 1.0);
      good_msg_.effort[0] = std::nan("");
    }
    last_good_ns_ = stamp;
    ++good_;
    if (unconfirmed) return sendJoint(good_msg_);
    // The filter publishes from the warmup()-th sample after a (re)start on,
    // each time the estimate for the sample `delay` samples back.
    segment_.push_back(stamp);
    if (static_cast<int>(segment_.size()) > delay_ + 1) segment_.pop_front();
    if (segment_count_++ >= warmup_ - 1) {
      expected_.push_back(segment_.front());
      trigger_.push_back(sent_);
    }
    return sendJoint(good_msg_);
  }

  // Sends good samples (no wrench) until a diagnostics message shows every
  // wrench sent as received and at least `joints` joint states, then waits for
  // the loads of the last one: every input has been handled, none of the old
  // timeline can arrive after what follows (wrenches and joint states come on
  // different connections).
  bool barrier(long joints) {
    long guard = 0;
    while (
        !(diag("wrenches received") == wrenches_sent_ && diag("joint states received") >= joints)) {
      if (!sendGood(false)) return false;
      if (++guard > 1000000) {
        std::printf("FAILED: no diagnostics caught up with the inputs\n");
        return false;
      }
    }
    // And every joint state handled (the last one is a good sample past the
    // warm-up).
    return spinUntil([&] { return acked_ + 1 == sent_; }, "the loads of the last sample");
  }

  bool sendBad(Bad kind) {
    sensor_msgs::JointState m;
    m.name = names_;
    m.position = good_msg_.position;
    m.position.resize(names_.size());
    m.header.stamp = fromNs(last_good_ns_ + kDtNs / 2);
    switch (kind) {
      case kNanPosition: m.position[names_.size() / 2] = std::nan(""); break;
      case kInfPosition: m.position[0] = -std::numeric_limits<double>::infinity(); break;
      case kPositionLength: m.position.pop_back(); break;
      case kVelocityLength: m.velocity.assign(names_.size() - 1, 0.0); break;
      case kDuplicateStamp: m.header.stamp = fromNs(last_good_ns_); break;
      case kBackwardStamp: m.header.stamp = fromNs(last_good_ns_ - kDtNs / 2); break;
      case kNanWrench:
        sendWrench(last_good_ns_ + kDtNs / 4, std::nan(""), wrench_link_);
        return true;
      case kBackwardWrench:
        // Refused only if a wrench came since the last reset (an empty history
        // takes any).
        if (!wrench_in_segment_) return false;
        sendWrench(last_wrench_ns_ - kDtNs / 2, 1.0, wrench_link_);
        return true;
      case kUnresolvedFrame:
        sendWrench(last_good_ns_ + kDtNs / 4, 1.0, "no_such_frame");
        return true;
      case kDuplicateName:
        m.name.push_back(names_[0]);
        m.position.push_back(m.position[0] + 0.5);
        break;
      case kEmpty:
        m.name.clear();
        m.position.clear();
        break;
      case kRogueAhead:
      case kRogueBack:
      case kRogueZero:
        m.header.stamp = fromNs(kind == kRogueZero    ? 0
                                : kind == kRogueAhead ? last_good_ns_ + kTwoHoursNs
                                                      : last_good_ns_ - kTwoHoursNs);
        for (double& q : m.position) q += 0.3;  // used, it would change every load
        break;
      case kWrenchAhead: sendWrench(last_good_ns_ + kTwoHoursNs, 1000.0, wrench_link_); return true;
      case kWrenchBack: sendWrench(last_good_ns_ - kTwoHoursNs, 1000.0, wrench_link_); return true;
      case kWrenchZero: sendWrench(0, 1000.0, wrench_link_); return true;
      case kWrenchLead: sendWrench(last_good_ns_ + 500000000, 1000.0, wrench_link_); return true;
      default: return false;
    }
    return sendJoint(m);
  }

  const Options o_;
  ros::NodeHandle nh_;
  ros::Publisher joint_pub_, wrench_pub_;
  ros::Subscriber loads_sub_, diag_sub_;
  std::vector<std::string> names_;
  std::string wrench_link_;
  int warmup_ = 0, delay_ = 0, jump_confirm_ = 1;
  jle::Model<double> model_;
  std::unique_ptr<jle::Pipeline> reference_;  // the clean stream
  struct CleanLoads {
    std::int64_t stamp;
    std::vector<double> values;  // per joint: force, moment, effort
  };
  std::deque<CleanLoads> clean_;  // the clean stream's loads the node has yet to publish
  long compared_ = 0, mismatched_ = 0;
  double worst_difference_ = 0.0;
  std::int64_t jump_back_ns_ = 0;

  sensor_msgs::JointState good_msg_;
  geometry_msgs::WrenchStamped wrench_msg_;
  std::int64_t next_ns_ = kEpochNs, last_good_ns_ = 0, last_wrench_ns_ = 0;
  std::deque<std::int64_t> segment_;  // the last delay + 1 stamps since the (re)start
  long segment_count_ = 0;            // good samples since the (re)start
  bool wrench_in_segment_ = false;
  long good_ = 0, sent_ = 0, acked_ = -1, wrenches_sent_ = 0, bad_loads_ = 0;
  std::vector<std::int64_t> expected_, received_;  // loads stamps [ns]
  std::vector<long> trigger_;  // index of the joint-state message that publishes expected_[r]
  std::map<std::string, long> last_diag_;
  long diag_count_ = 0;
  double diag_period_ = 1.0;  // [s] the node's diagnostic_period (wall clock)
  long injected_[kKinds] = {};
};

bool Driver::step(long i, long& next_jump) {
  bool restart = i == 0;
  if (next_jump <= o_.jumps && i == next_jump * o_.samples / (o_.jumps + 1)) {
    // A looping bag: back to the first stamp (or further, so that the jump is
    // at least twice the node's time_jump_threshold), once every input of the
    // old timeline has been handled.
    ++next_jump;
    if (!barrier(0)) return false;
    next_ns_ = std::min(kEpochNs, last_good_ns_ - jump_back_ns_);
    segment_.clear();
    segment_count_ = 0;
    wrench_in_segment_ = false;
    ++injected_[kTimeJump];
    restart = true;
    // stamps/jump_confirm joint states on the new timeline confirm the jump; those
    // before the last are rogue stamps.
    for (int c = 1; c < jump_confirm_; ++c) {
      if (!sendGood(false, false, true)) return false;
      ++injected_[kUnconfirmed];
    }
  }
  const Bad kind = static_cast<Bad>((i / kBadPeriod) % kTimeJump);
  const bool bad_here = i % kBadPeriod == kBadPeriod / 5;
  const bool ghost = bad_here && kind == kUnknownJoint;
  const bool nan_effort = bad_here && kind == kNanEffort;
  if (ghost) ++injected_[kUnknownJoint];
  if (nan_effort) ++injected_[kNanEffort];
  if (!sendGood(ghost, nan_effort)) return false;
  if (restart) {
    if (!startWrench()) return false;
  } else if (i % kWrenchPeriod == 0) {
    sendGoodWrench(last_good_ns_);
  }
  if (bad_here && !ghost && !nan_effort && sendBad(kind)) ++injected_[kind];
  return ros::ok();
}

bool Driver::run() {
  std::printf(
      "node_soak: %zu joints, wrench on '%s', warm-up %d samples (%d "
      "unpublished), "
      "delay %d, window %ld\n",
      names_.size(), wrench_link_.c_str(), warmup_, warmup_ - 1, delay_, o_.window);
  if (!spinUntil(
          [&] {
            return joint_pub_.getNumSubscribers() > 0 && wrench_pub_.getNumSubscribers() > 0 &&
                   loads_sub_.getNumPublishers() > 0 && diag_sub_.getNumPublishers() > 0;
          },
          "the connections to the node"))
    return false;
  expected_.reserve(static_cast<std::size_t>(o_.samples + o_.samples / 10));
  trigger_.reserve(expected_.capacity());
  received_.reserve(expected_.capacity());

  long next_jump = 1;
  long rss_10 = -1;
  const auto start = std::chrono::steady_clock::now();
  const long diag_at_start = diag_count_;
  for (long i = 0; i < o_.samples; ++i) {
    if (i == o_.samples / 10) rss_10 = vmRssKb(o_.pid);
    if (!step(i, next_jump)) return false;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Every input has been sent: a diagnostics message after all of them, then
  // every load.
  const long joints_sent = sent_;
  if (!barrier(joints_sent)) return false;
  const std::map<std::string, long> final_diag = last_diag_;
  if (!spinUntil([&] { return received_.size() >= expected_.size(); }, "the last loads"))
    return false;
  const long rss_100 = vmRssKb(o_.pid);
  const bool alive = kill(static_cast<pid_t>(o_.pid), 0) == 0 && rss_100 > 0;

  bool ok = true;
  auto expect = [&](bool c, const std::string& what) {
    if (!c) {
      std::printf("FAILED: %s\n", what.c_str());
      ok = false;
    }
  };
  std::size_t first_mismatch = std::min(expected_.size(), received_.size());
  for (std::size_t r = 0; r < first_mismatch; ++r)
    if (expected_[r] != received_[r]) {
      first_mismatch = r;
      break;
    }
  const double total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // /diagnostics on the node's wall-clock timer: its rate whatever the inputs do (one
  // period of slack at each end, 10% for a loaded machine's timer).
  const long diag_seen = diag_count_ - diag_at_start;
  const double diag_due = total_seconds / diag_period_;
  std::printf("diagnostics: %ld in %.2f s, %.0f due at %.3f s\n", diag_seen, total_seconds,
              diag_due, diag_period_);
  expect(diag_seen >= 0.9 * diag_due - 2 && diag_seen <= 1.1 * diag_due + 2,
         "diagnostics not at their configured rate");
  std::printf(
      "good samples %ld (%ld scheduled + %ld while waiting for "
      "diagnostics at the %ld "
      "jumps and the end), %.0f simulated s\n",
      good_, o_.samples, good_ - o_.samples, injected_[kTimeJump],
      1e-9 * static_cast<double>(kDtNs) * static_cast<double>(good_));
  std::printf(
      "wall time %.2f s (%.2f s to the last scheduled sample): %.0f samples/s, "
      "%.1f us/sample\n",
      total_seconds, seconds, static_cast<double>(good_) / total_seconds,
      1e6 * total_seconds / static_cast<double>(good_));
  std::printf(
      "node VmRSS at 10%%: %ld kB, at 100%%: %ld kB, growth %ld kB "
      "(limit %ld)\n",
      rss_10, rss_100, rss_100 - rss_10, o_.rss_limit_kb);
  std::printf(
      "loads: expected %zu, received %zu, in sequence %zu, non-finite %ld; "
      "unpublished warm-up %ld = %ld (re)starts x %d\n",
      expected_.size(), received_.size(), first_mismatch, bad_loads_,
      good_ - static_cast<long>(expected_.size()), injected_[kTimeJump] + 1, warmup_ - 1);
  std::printf("%-18s %9s   %-30s %9s %9s\n", "injected", "count", "diagnostics key", "expected",
              "diagnosed");
  std::map<std::string, long> expected_key;
  for (int k = 0; k < kKinds; ++k) expected_key[kBadKey[k]] += injected_[k];
  for (int k = 0; k < kKinds; ++k) {
    const long got = final_diag.count(kBadKey[k]) ? final_diag.at(kBadKey[k]) : -1;
    std::printf("%-18s %9ld   %-30s %9ld %9ld\n", kBadName[k], injected_[k], kBadKey[k],
                expected_key[kBadKey[k]], got);
    if (k != kUnconfirmed || jump_confirm_ > 1)
      expect(injected_[k] > 0, std::string("no ") + kBadName[k] + " injected");
  }
  // The loads the node had published when it sent that diagnostics message.
  const long at_diag =
      final_diag.count("joint states received") ? final_diag.at("joint states received") : -1;
  long loads_at_diag = 0;
  for (long s : trigger_) loads_at_diag += s < at_diag;
  const std::pair<const char*, long> totals[] = {{"joint states received", sent_},
                                                 {"wrenches received", wrenches_sent_},
                                                 {"loads published", loads_at_diag},
                                                 {"not published: stale input", 0}};
  for (const auto& [key, want] : totals) {
    const long got = final_diag.count(key) ? final_diag.at(key) : -1;
    const std::string range = std::string(key) == "joint states received"
                                  ? std::to_string(joints_sent) + ".." + std::to_string(want)
                                  : std::to_string(want);
    std::printf("%-18s %9s   %-30s %9s %9ld\n", "", "", key, range.c_str(), got);
  }
  for (const auto& [key, want] : expected_key)
    expect(final_diag.count(key) && final_diag.at(key) == want, "diagnostics '" + key + "'");
  expect(at_diag >= joints_sent && at_diag <= sent_, "diagnostics 'joint states received'");
  expect(
      final_diag.count("wrenches received") && final_diag.at("wrenches received") == wrenches_sent_,
      "diagnostics 'wrenches received'");
  expect(final_diag.count("loads published") && final_diag.at("loads published") == loads_at_diag,
         "diagnostics 'loads published'");
  expect(final_diag.count("not published: stale input") &&
             final_diag.at("not published: stale input") == 0,
         "diagnostics 'not published: stale input'");
  expect(received_.size() == expected_.size() && first_mismatch == expected_.size(),
         "the loads' stamps differ from the good samples' (first difference at "
         "load " +
             std::to_string(first_mismatch) + ")");
  expect(bad_loads_ == 0, "loads with the wrong size or non-finite values");
  std::printf(
      "loads against the clean stream's: %ld compared, %ld at another stamp or size, worst "
      "|difference| %.3g (limit %.0e), %zu never published\n",
      compared_, mismatched_, worst_difference_, kExact, clean_.size());
  expect(compared_ == static_cast<long>(received_.size()) && mismatched_ == 0 &&
             worst_difference_ <= kExact && clean_.empty(),
         "the loads differ from the clean stream's");
  expect(rss_10 > 0 && rss_100 > 0 && rss_100 - rss_10 <= o_.rss_limit_kb,
         "node VmRSS grew by more than " + std::to_string(o_.rss_limit_kb) + " kB");
  expect(alive, "the node is not alive at the end");
  std::printf("node soak: %s\n", ok ? "ok" : "FAILED");
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "node_soak", ros::init_options::AnonymousName);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // the summary before any error line
  return jle::cli::runTool(argc, argv, "node_soak", kUsage, parseOptions, [](const Options& o) {
    Driver driver(o);
    if (!driver.run()) throw std::runtime_error("failed");
  });
}
