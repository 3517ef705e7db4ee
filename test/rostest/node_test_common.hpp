// Helpers shared by the node tests: waiting on conditions, a simulated clock, recorders
// of the node's outputs, and reference loads computed with the core library from the
// exact trajectory (the node must reproduce them from the samples alone).
#pragma once

#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/WrenchStamped.h>
#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <ros/xmlrpc_manager.h>
#include <rosgraph_msgs/Clock.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/JointState.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

extern char** environ;

namespace jle_test {

using Eigen::Vector3d;
using Eigen::VectorXd;
using joint_load_estimator::JointLoads;

/// Wall-clock limit of any single wait [s]. Generous: a loaded CI machine may be slow,
/// and a wait that succeeds returns as soon as its condition holds.
constexpr double kTimeout = 10.0;

/// Spins the callbacks until pred() holds or `timeout` wall seconds have passed.
template <typename Pred>
bool waitFor(Pred pred, double timeout = kTimeout) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok()) {
    ros::spinOnce();
    if (pred()) return true;
    if (ros::WallTime::now() > end) return false;
    ros::WallDuration(0.0002).sleep();
  }
  return false;
}

/// Runs a program (PATH searched) to completion while spinning; its exit status, or -1
/// (also when it runs longer than `timeout` wall seconds: it is then interrupted).
inline int runSpinning(const std::vector<std::string>& args, double timeout) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    ros::spinOnce();
    if (ros::WallTime::now() > end) {
      kill(pid, SIGINT);
      waitpid(pid, &status, 0);
      return -1;
    }
    ros::WallDuration(0.001).sleep();
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// Spins until count() has not changed for `quiet` wall seconds (the last messages in
/// flight have arrived), or `timeout` has passed.
template <typename Count>
void spinUntilQuiet(Count count, double quiet = 1.0, double timeout = 30.0) {
  auto seen = count();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  ros::WallTime last_change = ros::WallTime::now();
  while (ros::ok() && ros::WallTime::now() - last_change < ros::WallDuration(quiet) &&
         ros::WallTime::now() < end) {
    ros::spinOnce();
    if (count() != seen) {
      seen = count();
      last_change = ros::WallTime::now();
    }
    ros::WallDuration(0.01).sleep();
  }
}

/// The test's node handle (created in main after ros::init).
inline ros::NodeHandle& nh() {
  static ros::NodeHandle handle;
  return handle;
}

/// The XML-RPC URI of a node (from the master); empty if unknown.
inline std::string nodeUri(const std::string& node) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, false)) return "";
  return static_cast<std::string>(payload);
}

/// Whether this process has an established connection on `topic` with `node`: as
/// publisher (`outbound`, the peer is the subscribing node) or as subscriber (the peer
/// is the publishing node's URI). From roscpp's bus information, as `rosnode info` shows.
inline bool connectedTo(const std::string& topic, const std::string& node, bool outbound) {
  const std::string peer = outbound ? node : nodeUri(node);
  if (peer.empty()) return false;
  // Our own getBusInfo (the slave API that `rosnode info` calls), over XML-RPC.
  std::string host;
  std::uint32_t port = 0;
  if (!ros::network::splitURI(ros::XMLRPCManager::instance()->getServerURI(), host, port))
    return false;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue args, result;
  args[0] = ros::this_node::getName();
  if (!client.execute("getBusInfo", args, result) ||
      result.getType() != XmlRpc::XmlRpcValue::TypeArray || result.size() < 3)
    return false;
  XmlRpc::XmlRpcValue info = result[2];
  // Each entry: [id, peer (caller id or URI), "o" or "i", transport, topic, connected, ...].
  for (int i = 0; i < info.size(); ++i) {
    XmlRpc::XmlRpcValue c = info[i];
    if (static_cast<std::string>(c[4]) == topic && static_cast<std::string>(c[1]) == peer &&
        static_cast<std::string>(c[2]) == (outbound ? "o" : "i"))
      return true;
  }
  return false;
}

/// Waits until `node` is connected to what we publish on `pub` (so that nothing
/// published next is lost: the topics are not latched).
inline bool waitForSubscriber(const ros::Publisher& pub, const std::string& node,
                              double timeout = kTimeout) {
  return waitFor([&] { return connectedTo(pub.getTopic(), node, true); }, timeout);
}

/// Publishes /clock (the launch files set use_sim_time): the stamps the tests choose
/// are the node's time too, so logs, throttling and diagnostics follow them.
class SimClock {
 public:
  SimClock() : pub_(nh().advertise<rosgraph_msgs::Clock>("/clock", 100)) {}
  void set(const ros::Time& t) {
    rosgraph_msgs::Clock c;
    c.clock = t;
    pub_.publish(c);
  }
  const ros::Publisher& publisher() const { return pub_; }

 private:
  ros::Publisher pub_;
};

/// The one clock of the test process.
inline SimClock& simClock() {
  static SimClock clock;
  return clock;
}

/// Records every message of a topic, in arrival order.
template <typename Msg>
class Recorder {
 public:
  using Ptr = typename Msg::ConstPtr;
  explicit Recorder(const std::string& topic) {
    sub_ = nh().subscribe<Msg>(topic, 10000, [this](const Ptr& m) { msgs_.push_back(m); });
  }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  const std::vector<Ptr>& msgs() const { return msgs_; }
  std::size_t size() const { return msgs_.size(); }
  /// Waits until connected to `node`'s publisher of the topic.
  bool connectTo(const std::string& node, double timeout = kTimeout) const {
    return waitFor([&] { return connectedTo(sub_.getTopic(), node, false); }, timeout);
  }

 private:
  ros::Subscriber sub_;
  std::vector<Ptr> msgs_;
};

/// The loads of one node: waits for the publication of a given stamp.
class LoadsRecorder : public Recorder<JointLoads> {
 public:
  using Recorder<JointLoads>::Recorder;
  /// The message stamped `stamp`, waiting up to `timeout`; null if none came.
  Ptr waitForStamp(const ros::Time& stamp, double timeout = kTimeout) {
    Ptr found;
    waitFor([&] { return (found = find(stamp)) != nullptr; }, timeout);
    return found;
  }
  Ptr find(const ros::Time& stamp) const {
    for (auto it = msgs().rbegin(); it != msgs().rend(); ++it)
      if ((*it)->header.stamp == stamp) return *it;
    return nullptr;
  }
};

/// /rosout messages: what a node logged.
class LogRecorder : public Recorder<rosgraph_msgs::Log> {
 public:
  LogRecorder() : Recorder<rosgraph_msgs::Log>("/rosout") {}
  /// Messages of `node` (its full name) at `level` or above whose text contains all of `parts`.
  std::size_t count(const std::string& node, std::uint8_t level,
                    const std::vector<std::string>& parts) const {
    std::size_t n = 0;
    for (const auto& m : msgs()) {
      if (m->name != node || m->level < level) continue;
      bool all = true;
      for (const std::string& p : parts) all = all && m->msg.find(p) != std::string::npos;
      n += all ? 1 : 0;
    }
    return n;
  }
  bool waitFor(const std::string& node, std::uint8_t level, const std::vector<std::string>& parts,
               double timeout = kTimeout) {
    return jle_test::waitFor([&] { return count(node, level, parts) > 0; }, timeout);
  }
};

/// /diagnostics: the node's counters, by the key the node gives them.
class DiagnosticsRecorder : public Recorder<diagnostic_msgs::DiagnosticArray> {
 public:
  DiagnosticsRecorder() : Recorder<diagnostic_msgs::DiagnosticArray>("/diagnostics") {}
  /// The newest value of `key` in the status `status_name`; -1 if not seen yet.
  long latest(const std::string& status_name, const std::string& key) const {
    for (auto it = msgs().rbegin(); it != msgs().rend(); ++it)
      for (const auto& s : (*it)->status) {
        if (s.name != status_name) continue;
        for (const auto& kv : s.values)
          if (kv.key == key) return std::stol(kv.value);
      }
    return -1;
  }
};

/// The /rosout and /diagnostics recorders of the test process (one subscription each).
inline LogRecorder& logs() {
  static LogRecorder recorder;
  return recorder;
}
inline DiagnosticsRecorder& diagnostics() {
  static DiagnosticsRecorder recorder;
  return recorder;
}

/// Reference loads: the core library given the exact q, qd, qdd (and base motion and
/// applied wrenches) at a stamp, against which the node's estimate from the samples is
/// compared.
class Reference {
 public:
  explicit Reference(const std::string& urdf_path, bool floating_base = false)
      : model(load(urdf_path, floating_base)), data(model) {}

  /// q, qd, qdd in model.coordinate_names order. Fills data (loads in data.force/moment/effort).
  void compute(const VectorXd& q, const VectorXd& qd, const VectorXd& qdd,
               const jle::BaseState<double>& base = jle::BaseState<double>(),
               const std::string& wrench_link = "", const Vector3d& f_link = Vector3d::Zero(),
               const Vector3d& m_link = Vector3d::Zero()) {
    jle::forwardKinematics(model, data, q, qd, qdd, gravity, base);
    if (!wrench_link.empty())
      jle::addExternalWrench(model, data, model.frameIndex(wrench_link), f_link, m_link,
                             jle::WrenchFrame::kLocal);
    jle::inverseDynamics(model, data);
  }

  /// Largest deviation of msg from data over every joint and component, each relative to
  /// the norm of that joint's reference wrench |F| + |M| (a component near zero is
  /// compared at the scale of the loads it is computed from). Throws on a joint name the
  /// model does not have (the test fails).
  double relativeError(const JointLoads& msg) const {
    double worst = 0.0;
    EXPECT_EQ(msg.name.size(), msg.wrench.size());
    EXPECT_EQ(msg.name.size(), msg.effort.size());
    for (std::size_t j = 0; j < msg.name.size(); ++j) {
      const int s = model.segmentOfJoint(msg.name[j]);
      const Vector3d& f = data.force[static_cast<std::size_t>(s)];
      const Vector3d& m = data.moment[static_cast<std::size_t>(s)];
      const double scale = std::max(f.norm() + m.norm(), 1e-6);
      const auto& w = msg.wrench[j];
      const double e[7] = {w.force.x - f.x(),
                           w.force.y - f.y(),
                           w.force.z - f.z(),
                           w.torque.x - m.x(),
                           w.torque.y - m.y(),
                           w.torque.z - m.z(),
                           msg.effort[j] - data.effort[static_cast<std::size_t>(s)]};
      for (double d : e) worst = std::max(worst, std::abs(d) / scale);
    }
    return worst;
  }

  jle::Model<double> model;
  jle::Data<double> data;
  Vector3d gravity{0.0, 0.0, -9.80665};

 private:
  static jle::Model<double> load(const std::string& path, bool floating_base) {
    jle::ModelOptions options;
    options.floating_base = floating_base;
    return jle::modelFromUrdfFile(path, options);
  }
};

/// A JointState of the given joints.
inline sensor_msgs::JointState jointState(const ros::Time& stamp,
                                          const std::vector<std::string>& names,
                                          const VectorXd& q) {
  sensor_msgs::JointState js;
  js.header.stamp = stamp;
  js.name = names;
  js.position.assign(q.data(), q.data() + q.size());
  return js;
}

/// One node under test, in its own namespace: its joint_states input, its loads output.
class NodeUnderTest {
 public:
  explicit NodeUnderTest(const std::string& ns)
      : ns_(ns),
        joint_pub_(nh().advertise<sensor_msgs::JointState>("/" + ns + "/joint_states", 1000)),
        loads_("/" + ns + "/joint_load_estimator/joint_loads") {}

  /// Full name of the node (as in /rosout), its diagnostics status name.
  std::string name() const { return "/" + ns_ + "/joint_load_estimator"; }
  std::string status() const { return ns_ + "/joint_load_estimator: joint loads"; }

  /// Waits until the node is subscribed to our joint states and the clock, and we to
  /// its loads, its log and its diagnostics.
  ::testing::AssertionResult connect() {
    const std::string node = name();
    if (!waitForSubscriber(joint_pub_, node))
      return ::testing::AssertionFailure() << node << " did not subscribe to our joint states";
    if (!waitForSubscriber(simClock().publisher(), node))
      return ::testing::AssertionFailure() << node << " did not subscribe to our /clock";
    if (!loads_.connectTo(node) || !logs().connectTo(node) || !diagnostics().connectTo(node))
      return ::testing::AssertionFailure() << "no connection to the outputs of " << node;
    return ::testing::AssertionSuccess();
  }

  /// Sets the clock to the message's stamp and sends it.
  void send(const sensor_msgs::JointState& js) {
    simClock().set(js.header.stamp);
    sendKeepingClock(js);
  }
  /// Sends it without touching the clock (a stamp older than the clock).
  void sendKeepingClock(const sensor_msgs::JointState& js) {
    joint_pub_.publish(js);
    ++sent_;
  }
  /// JointState messages sent so far (the node's "joint states received" counter).
  long sent() const { return sent_; }
  LoadsRecorder& loads() { return loads_; }

 private:
  std::string ns_;
  ros::Publisher joint_pub_;
  LoadsRecorder loads_;
  long sent_ = 0;
};

}  // namespace jle_test
