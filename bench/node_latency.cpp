// End-to-end latency and throughput of the running node on loopback: publishes joint
// states of a 7-joint arm and two wrench inputs at increasing rates, receives
// ~joint_loads, and reports latency (publication of the joint state to reception of
// its loads: median, p99, max) and losses per rate, with the loss the node itself
// counted (the header.seq gaps of its joint-state input, /diagnostics). Run by
// bench/node_latency.sh, which starts a master and the node.
#include <joint_load_estimator/JointLoads.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace {

struct Run {
  double rate = 0;
  long sent = 0;
  long received = 0;
  std::vector<double> latency;  // [s]
};

std::unordered_map<std::uint64_t, double> g_sent_at;  // stamp (ns) -> wall time sent
Run* g_run = nullptr;
std::mutex g_mutex;  // the spinner thread receives while the main thread publishes

void onLoads(const joint_load_estimator::JointLoads::ConstPtr& msg) {
  const double now = ros::WallTime::now().toSec();
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_run) return;
  auto it = g_sent_at.find(msg->header.stamp.toNSec());
  if (it == g_sent_at.end()) return;
  g_run->latency.push_back(now - it->second);
  ++g_run->received;
  g_sent_at.erase(it);
}

long g_node_lost = 0;  // the node's count of joint states lost before it (header.seq gaps)

void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
  for (const auto& status : msg->status)
    for (const auto& kv : status.values)
      if (kv.key == "input '/joint_states': lost (header.seq gaps)") {
        std::lock_guard<std::mutex> lock(g_mutex);
        g_node_lost = std::stol(kv.value);
      }
}

long nodeLost() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_node_lost;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "node_latency_bench");
  ros::NodeHandle nh, pnh("~");
  double seconds = 2.0;
  std::vector<double> rates = {1000, 2000, 5000, 10000, 15000, 20000, 30000, 40000};
  pnh.param("seconds", seconds, seconds);
  std::vector<double> r;
  if (pnh.getParam("rates", r)) rates = r;
  std::vector<std::string> names;
  for (int i = 1; i <= 7; ++i) names.push_back("panda_joint" + std::to_string(i));

  ros::Publisher js = nh.advertise<sensor_msgs::JointState>("joint_states", 1000);
  ros::Publisher w1 = nh.advertise<geometry_msgs::WrenchStamped>("ft_sensor/wrench", 1000);
  ros::Publisher w2 = nh.advertise<geometry_msgs::WrenchStamped>("handle/wrench", 1000);
  ros::Subscriber sub = nh.subscribe("joint_load_estimator/joint_loads", 10000, onLoads,
                                     ros::TransportHints().tcpNoDelay());
  ros::Subscriber diag = nh.subscribe("/diagnostics", 100, onDiagnostics);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(20.0);
  while ((sub.getNumPublishers() == 0 || js.getNumSubscribers() == 0 ||
          w1.getNumSubscribers() == 0 || w2.getNumSubscribers() == 0) &&
         ros::WallTime::now() < deadline)
    ros::WallDuration(0.01).sleep();
  if (sub.getNumPublishers() == 0 || js.getNumSubscribers() == 0) {
    std::fprintf(stderr, "node_latency: the node is not connected\n");
    return 1;
  }

  sensor_msgs::JointState state;
  state.name = names;
  state.position.assign(7, 0.0);
  geometry_msgs::WrenchStamped wrench;
  wrench.header.frame_id = "panda_link8";
  geometry_msgs::WrenchStamped handle;
  handle.header.frame_id = "panda_link5";
  std::printf(
      "| input rate [Hz] | sent | loads received | lost | lost, counted by the node | latency "
      "median [us] | p99 [us] | max [us] |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  std::uint32_t seq = 0;  // every joint state numbered, as rospy and many drivers do
  double t_sim = 0.0;
  for (double rate : rates) {
    Run run;
    run.rate = rate;
    const long lost_before = nodeLost();
    const ros::WallTime start = ros::WallTime::now();
    const long n = static_cast<long>(rate * seconds);
    for (long k = 0; k < n; ++k) {
      // Paced by the wall clock: sample k is due at start + k / rate.
      // Sleep to within 60 us of it, then spin: the node needs the other core.
      const ros::WallTime due = start + ros::WallDuration(k / rate);
      const ros::WallDuration ahead = due - ros::WallTime::now();
      if (ahead > ros::WallDuration(60e-6)) (ahead - ros::WallDuration(60e-6)).sleep();
      while (ros::WallTime::now() < due) {
      }
      t_sim += 1.0 / rate;
      const ros::Time stamp = ros::Time::now();
      for (int i = 0; i < 7; ++i) state.position[i] = 0.5 * std::sin(t_sim + i);
      wrench.header.stamp = stamp;
      wrench.wrench.force.z = -10.0 + std::sin(t_sim);
      handle.header.stamp = stamp;
      handle.wrench.force.x = 2.0 * std::cos(t_sim);
      w1.publish(wrench);
      w2.publish(handle);
      state.header.stamp = stamp;
      if (k >= 20) {  // past the filter's warm-up
        std::lock_guard<std::mutex> lock(g_mutex);
        g_run = &run;
        g_sent_at[stamp.toNSec()] = ros::WallTime::now().toSec();
        ++run.sent;
      }
      state.header.seq = ++seq;
      js.publish(state);
    }
    // Let the last loads arrive.
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(0.5);
    while (ros::WallTime::now() < until) {
      {
        std::lock_guard<std::mutex> lock(g_mutex);
        if (run.received >= run.sent) break;
      }
      ros::WallDuration(0.001).sleep();
    }
    std::vector<double> latency;
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      g_run = nullptr;
      g_sent_at.clear();
      latency = run.latency;
    }
    // A gap: the node's filters restart, and its diagnostics (diagnostic_period 0.2 s
    // in node_latency.yaml) report what it lost.
    ros::WallDuration(1.0).sleep();
    std::printf("| %.0f | %ld | %ld | %ld | %ld | %.0f | %.0f | %.0f |\n", rate, run.sent,
                run.received, run.sent - run.received, nodeLost() - lost_before,
                1e6 * percentile(latency, 0.5), 1e6 * percentile(latency, 0.99),
                1e6 * percentile(latency, 1.0));
    std::fflush(stdout);
  }
  return 0;
}
