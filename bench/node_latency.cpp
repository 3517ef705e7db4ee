// End-to-end latency and throughput of the estimator on one machine: the driver side
// of a robot as a nodelet, `joint_load_estimator/LatencyBenchNodelet`. It publishes
// joint states of a 7-joint arm and two wrench inputs at increasing rates, each as a
// fresh boost::shared_ptr<const M> (what a zero-copy driver does), receives
// ~joint_loads, and prints per rate: latency (publication of the joint state to the
// reception of its loads: median, p99, max), losses (its own count and the node's,
// header.seq gaps in /diagnostics), and where the time went (the node's own figures
// from /diagnostics; the receiver's queue wait from the receipt time roscpp stamps).
//
// bench/node_latency.sh runs it twice: in the same nodelet manager as
// joint_load_estimator/EstimatorNodelet (messages passed as pointers, no
// serialisation), and in a process of its own (`nodelet standalone`) beside the
// joint_load_estimator node (roscpp's TCP transport, tcpNoDelay). The code is the same.
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/ros/inline_callback_queue.hpp>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/WrenchStamped.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <time.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

namespace jle_bench {
namespace {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

double mean(const std::vector<double>& v) {
  if (v.empty()) return NAN;
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

// Sleeps until an absolute instant of CLOCK_REALTIME (ros::WallTime's clock), without
// spinning: the bench must not take a core from the node it measures.
void sleepUntil(const ros::WallTime& due) {
  timespec t;
  t.tv_sec = static_cast<time_t>(due.sec);
  t.tv_nsec = static_cast<long>(due.nsec);
  while (clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &t, nullptr) != 0) {
  }
}

}  // namespace

// One rate's figures.
struct Run {
  double rate = 0;
  long sent = 0;
  long received = 0;
  long node_lost = 0;
  std::vector<double> latency;        // [s] publication -> the receiver's callback
  std::vector<double> delivered;      // [s] publication -> the loads in the receiver's queue
  std::vector<double> node_wait;      // [s] per diagnostics period: the node's mean queue wait
  std::vector<double> node_callback;  // [s] per period: the node's mean callback to publish
};

class LatencyBench {
 public:
  using LoadsEvent = ros::MessageEvent<const joint_load_estimator::JointLoads>;

  LatencyBench(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh) {
    pnh.param("seconds", seconds_, seconds_);
    pnh.param("path", path_, path_);
    bool inline_receiver = false;
    pnh.param("inline_receiver", inline_receiver, inline_receiver);
    std::vector<double> r;
    if (pnh.getParam("rates", r)) rates_ = r;
    for (int i = 1; i <= 7; ++i) names_.push_back("panda_joint" + std::to_string(i));
    js_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 1000);
    w1_ = nh_.advertise<geometry_msgs::WrenchStamped>("ft_sensor/wrench", 1000);
    w2_ = nh_.advertise<geometry_msgs::WrenchStamped>("handle/wrench", 1000);
    // The receiver: on the callback queue of the node handle (the process's spinner, a
    // nodelet's worker threads) or, with ~inline_receiver, in the delivering thread.
    ros::SubscribeOptions options;
    options.initByFullCallbackType<const LoadsEvent&>(
        "joint_load_estimator/joint_loads", 10000,
        [this](const LoadsEvent& event) { onLoads(event); });
    options.transport_hints = ros::TransportHints().tcpNoDelay();
    if (inline_receiver) {
      options.callback_queue = &inline_queue_;
      options.allow_concurrent_callbacks = true;  // onLoads locks mutex_
    }
    loads_ = nh_.subscribe(options);
    diagnostics_ = nh_.subscribe("/diagnostics", 100, &LatencyBench::onDiagnostics, this);
  }

  // Publishes at every rate, prints the table; false if the node never connected.
  bool run(const std::atomic<bool>& stop) {
    if (!waitForNode(stop)) return false;
    std::printf(
        "| path | input rate [Hz] | sent | loads received | lost | lost, counted by the node | "
        "latency median [us] | p99 [us] | max [us] | delivered median [us] | p99 [us] | node: "
        "queue wait, mean [us] | node: callback to published, mean [us] |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (double rate : rates_) {
      if (stop) return true;
      Run result = runRate(rate, stop);
      const auto us = [](double s) { return 1e6 * s; };
      std::printf(
          "| %s | %.0f | %ld | %ld | %ld | %ld | %.0f | %.0f | %.0f | %.0f | %.0f | %.1f | %.1f "
          "|\n",
          path_.c_str(), rate, result.sent, result.received, result.sent - result.received,
          result.node_lost, us(percentile(result.latency, 0.5)),
          us(percentile(result.latency, 0.99)), us(percentile(result.latency, 1.0)),
          us(percentile(result.delivered, 0.5)), us(percentile(result.delivered, 0.99)),
          us(mean(result.node_wait)), us(mean(result.node_callback)));
      std::fflush(stdout);
    }
    return true;
  }

 private:
  bool waitForNode(const std::atomic<bool>& stop) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(20.0);
    while (!stop &&
           (loads_.getNumPublishers() == 0 || js_.getNumSubscribers() == 0 ||
            w1_.getNumSubscribers() == 0 || w2_.getNumSubscribers() == 0) &&
           ros::WallTime::now() < deadline)
      ros::WallDuration(0.01).sleep();
    if (loads_.getNumPublishers() > 0 && js_.getNumSubscribers() > 0) return true;
    std::fprintf(stderr, "node_latency: the estimator is not connected\n");
    return false;
  }

  Run runRate(double rate, const std::atomic<bool>& stop) {
    Run run;
    run.rate = rate;
    const long lost_before = nodeLost();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      run_ = &run;
    }
    const ros::WallTime start = ros::WallTime::now();
    const long n = static_cast<long>(rate * seconds_);
    for (long k = 0; k < n && !stop; ++k) {
      // Paced by the wall clock: sample k is due at start + k / rate.
      sleepUntil(start + ros::WallDuration(k / rate));
      publishSample(run, k >= 20);  // the first 20: the filter's warm-up
    }
    // Let the last loads arrive.
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(0.5);
    while (ros::WallTime::now() < until) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (run.received >= run.sent) break;
      }
      ros::WallDuration(0.001).sleep();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      run_ = nullptr;
      sent_at_.clear();
    }
    // A gap: the node's filters restart, and its diagnostics (diagnostic_period 0.2 s
    // in node_latency.yaml) report what it lost.
    ros::WallDuration(1.0).sleep();
    run.node_lost = nodeLost() - lost_before;
    return run;
  }

  void publishSample(Run& run, bool measured) {
    t_sim_ += 1.0 / run.rate;
    const ros::Time stamp = ros::Time::now();
    // Fresh messages each time: a message handed to publish() as a shared_ptr is not
    // modified afterwards (the subscribers in the process hold the same object).
    geometry_msgs::WrenchStampedPtr wrench = boost::make_shared<geometry_msgs::WrenchStamped>();
    wrench->header.frame_id = "panda_link8";
    wrench->header.stamp = stamp;
    wrench->wrench.force.z = -10.0 + std::sin(t_sim_);
    geometry_msgs::WrenchStampedPtr handle = boost::make_shared<geometry_msgs::WrenchStamped>();
    handle->header.frame_id = "panda_link5";
    handle->header.stamp = stamp;
    handle->wrench.force.x = 2.0 * std::cos(t_sim_);
    sensor_msgs::JointStatePtr state = boost::make_shared<sensor_msgs::JointState>();
    state->name = names_;
    state->position.resize(7);
    for (int i = 0; i < 7; ++i) state->position[i] = 0.5 * std::sin(t_sim_ + i);
    state->header.stamp = stamp;
    state->header.seq = ++seq_;  // numbered, as roscpp does over TCP and many drivers do
    w1_.publish(geometry_msgs::WrenchStampedConstPtr(wrench));
    w2_.publish(geometry_msgs::WrenchStampedConstPtr(handle));
    if (measured) {
      std::lock_guard<std::mutex> lock(mutex_);
      sent_at_[stamp.toNSec()] = ros::WallTime::now().toSec();
      ++run.sent;
    }
    js_.publish(sensor_msgs::JointStateConstPtr(state));
  }

  void onLoads(const LoadsEvent& event) {
    const double now = ros::WallTime::now().toSec();
    const double receipt = event.getReceiptTime().toSec();  // entered our subscription queue
    std::lock_guard<std::mutex> lock(mutex_);
    if (!run_) return;
    auto it = sent_at_.find(event.getConstMessage()->header.stamp.toNSec());
    if (it == sent_at_.end()) return;
    run_->latency.push_back(now - it->second);
    run_->delivered.push_back(receipt - it->second);
    ++run_->received;
    sent_at_.erase(it);
  }

  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
    for (const auto& status : msg->status) {
      if (status.name.find("joint loads") == std::string::npos) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& kv : status.values) {
        if (kv.key == "input '/joint_states': lost (header.seq gaps)")
          node_lost_ = std::stol(kv.value);
        if (!run_) continue;
        if (kv.key == "mean queue wait [s]") run_->node_wait.push_back(std::stod(kv.value));
        if (kv.key == "mean latency [s]") run_->node_callback.push_back(std::stod(kv.value));
      }
    }
  }

  long nodeLost() {
    std::lock_guard<std::mutex> lock(mutex_);
    return node_lost_;
  }

  ros::NodeHandle nh_;
  double seconds_ = 2.0;
  std::string path_ = "nodelet";
  std::vector<double> rates_ = {1000, 5000, 10000};
  std::vector<std::string> names_;
  ros::Publisher js_, w1_, w2_;
  jle::InlineCallbackQueue inline_queue_;
  ros::Subscriber loads_, diagnostics_;
  std::uint32_t seq_ = 0;
  double t_sim_ = 0.0;
  std::mutex mutex_;  // the callbacks' threads receive while the bench's thread publishes
  Run* run_ = nullptr;
  std::unordered_map<std::uint64_t, double> sent_at_;  // stamp (ns) -> wall time sent [s]
  long node_lost_ = 0;  // the node's count of joint states lost before it
};

// The bench as a nodelet: its publisher runs on a thread of its own (the driver's
// loop); its callbacks on the manager's worker threads, as any nodelet's. When every
// rate is done it asks the process to shut down.
class LatencyBenchNodelet : public nodelet::Nodelet {
 public:
  ~LatencyBenchNodelet() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    bench_ = std::make_unique<LatencyBench>(getNodeHandle(), getPrivateNodeHandle());
    thread_ = std::thread([this] {
      if (!bench_->run(stop_)) NODELET_ERROR("node_latency: the estimator never connected");
      ros::requestShutdown();
    });
  }

  std::unique_ptr<LatencyBench> bench_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace jle_bench

PLUGINLIB_EXPORT_CLASS(jle_bench::LatencyBenchNodelet, nodelet::Nodelet)
