// summarize_loads: listens to a joint_load_estimator's joint_loads and, when it stops,
// prints a table per joint (RMS and max |effort|, max |force|, max |moment|, and the
// RMS difference from the measured effort when the joint states carried one). Used by
// the headless demo (launch/demo.launch rviz:=false).
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/io/command_line.hpp>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

const char* const kUsage =
    R"(usage: rosrun joint_load_estimator summarize_loads [--topic T] [--count N]
                                                   [--idle S] [--output FILE]

Subscribes to T (default /joint_load_estimator/joint_loads, joint_load_estimator/
JointLoads) and, when it stops, prints for every joint: RMS and maximum of |effort|
[N m, or N for a prismatic joint], maximum |force| [N] and |moment| [N m] of its joint
wrench, and the RMS and maximum of effort - measured_effort where a measured effort
came with the joint states; then the number of messages and the span of their stamps.

It stops on SIGINT or SIGTERM (roslaunch stopping it), when ROS shuts down, after N
messages (--count), or when no message has arrived for S seconds of wall time once the
first has (--idle). The table goes to standard output and, with --output, to FILE.
Exit status: 0; 1 if FILE cannot be written; 2 a usage error (an unknown or repeated
option, a bad value).
)";

std::atomic<bool> g_stop{false};

void onSignal(int) { g_stop = true; }

struct JointStats {
  long n = 0;
  double sum_effort2 = 0.0, max_effort = 0.0, max_force = 0.0, max_moment = 0.0;
  long n_measured = 0;
  double sum_error2 = 0.0, max_error = 0.0;
};

class Summary {
 public:
  void add(const joint_load_estimator::JointLoads& msg) {
    if (names_.empty()) {
      names_ = msg.name;
      stats_.assign(names_.size(), JointStats());
    }
    if (msg.name != names_) {
      ++skipped_;  // another set of joints: not this table's
      return;
    }
    const double t = msg.header.stamp.toSec();
    if (messages_ == 0) first_ = t;
    last_ = t;
    ++messages_;
    const std::size_t n = names_.size();
    for (std::size_t i = 0; i < n && i < msg.wrench.size() && i < msg.effort.size(); ++i) {
      JointStats& s = stats_[i];
      const geometry_msgs::Wrench& w = msg.wrench[i];
      const double e = msg.effort[i];
      ++s.n;
      s.sum_effort2 += e * e;
      s.max_effort = std::max(s.max_effort, std::abs(e));
      s.max_force = std::max(s.max_force, std::sqrt(w.force.x * w.force.x + w.force.y * w.force.y +
                                                    w.force.z * w.force.z));
      s.max_moment = std::max(
          s.max_moment,
          std::sqrt(w.torque.x * w.torque.x + w.torque.y * w.torque.y + w.torque.z * w.torque.z));
      if (i < msg.measured_effort.size() && std::isfinite(msg.measured_effort[i])) {
        const double d = e - msg.measured_effort[i];
        ++s.n_measured;
        s.sum_error2 += d * d;
        s.max_error = std::max(s.max_error, std::abs(d));
      }
    }
  }

  long messages() const { return messages_; }

  std::string table(const std::string& topic) const {
    std::string out;
    char line[256];
    if (messages_ == 0) return "summarize_loads: no message on " + topic + "\n";
    std::snprintf(line, sizeof line,
                  "joint loads on %s: %ld messages, stamps %.3f .. %.3f s (%.3f s)\n",
                  topic.c_str(), messages_, first_, last_, last_ - first_);
    out += line;
    if (skipped_)
      out += "(" + std::to_string(skipped_) + " messages with another set of joints skipped)\n";
    bool measured = false;
    for (const JointStats& s : stats_) measured = measured || s.n_measured > 0;
    std::snprintf(line, sizeof line, "%-22s %12s %12s %12s %12s%s\n", "joint", "RMS effort",
                  "max |effort|", "max |force|", "max |moment|",
                  measured ? "    RMS error   max |error|" : "");
    out += line;
    std::snprintf(line, sizeof line, "%-22s %12s %12s %12s %12s%s\n", "", "[N m]", "[N m]", "[N]",
                  "[N m]", measured ? "        [N m]         [N m]" : "");
    out += line;
    for (std::size_t i = 0; i < names_.size(); ++i) {
      const JointStats& s = stats_[i];
      std::snprintf(line, sizeof line, "%-22s %12.4g %12.4g %12.4g %12.4g", names_[i].c_str(),
                    s.n ? std::sqrt(s.sum_effort2 / static_cast<double>(s.n)) : 0.0, s.max_effort,
                    s.max_force, s.max_moment);
      out += line;
      if (measured) {
        if (s.n_measured > 0)
          std::snprintf(line, sizeof line, " %12.3g  %12.3g",
                        std::sqrt(s.sum_error2 / static_cast<double>(s.n_measured)), s.max_error);
        else
          std::snprintf(line, sizeof line, " %12s  %12s", "-", "-");
        out += line;
      }
      out += "\n";
    }
    if (measured)
      out +=
          "(error = estimated - measured effort, where the joint states carried an effort; "
          "prismatic joints in N)\n";
    return out;
  }

 private:
  std::vector<std::string> names_;
  std::vector<JointStats> stats_;
  long messages_ = 0, skipped_ = 0;
  double first_ = 0.0, last_ = 0.0;
};

struct Options {
  std::string topic = "/joint_load_estimator/joint_loads";
  std::string output;
  long count = 0;     // 0: no limit
  double idle = 0.0;  // 0: none
};

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v =
      jle::cli::optionValues(argc, argv, {"--topic", "--output", "--count", "--idle"});
  Options o;
  if (v.count("--topic")) o.topic = v["--topic"];
  if (v.count("--output")) o.output = v["--output"];
  if (v.count("--count"))
    o.count = static_cast<long>(
        jle::cli::parseInteger("--count", v["--count"], 1, std::numeric_limits<long>::max()));
  if (v.count("--idle"))
    o.idle = jle::cli::parseNumber("--idle", v["--idle"], jle::cli::Sign::kPositive);
  return o;
}

// Listens until told to stop (kUsage), then prints the table.
void run(const Options& options) {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  ros::NodeHandle nh;
  Summary summary;
  ros::WallTime last_message;
  const ros::Subscriber sub = nh.subscribe<joint_load_estimator::JointLoads>(
      options.topic, 1000,
      [&](const joint_load_estimator::JointLoads::ConstPtr& msg) {
        summary.add(*msg);
        last_message = ros::WallTime::now();
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  while (!g_stop && ros::ok()) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.05));
    if (options.count > 0 && summary.messages() >= options.count) break;
    if (options.idle > 0.0 && summary.messages() > 0 &&
        (ros::WallTime::now() - last_message).toSec() > options.idle)
      break;
  }
  // What already arrived is part of the run.
  ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.0));
  const std::string table = summary.table(nh.resolveName(options.topic));
  std::fputs(table.c_str(), stdout);
  std::fflush(stdout);
  ros::shutdown();
  if (!options.output.empty()) {
    std::FILE* f = std::fopen(options.output.c_str(), "w");
    if (f == nullptr || std::fputs(table.c_str(), f) < 0 || std::fclose(f) != 0)
      throw std::runtime_error("cannot write " + options.output);
  }
}

}  // namespace

int main(int argc, char** argv) {
  // Our own handlers: the table is printed on the way out, not lost to ROS's. ros::init
  // takes its remappings out of argv.
  ros::init(argc, argv, "summarize_loads", ros::init_options::NoSigintHandler);
  return jle::cli::runTool(argc, argv, "summarize_loads", kUsage, parseOptions, run);
}
