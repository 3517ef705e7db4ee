// One message path (agreement.test): for the same bag and the same settings files, the
// node (the bag played with rosbag play under use_sim_time) and process_bag publish the
// same loads on every stamp both publish, to 1e-12. Three scenarios, one node each:
//  - floating: a floating base whose pose comes from the bag's /tf;
//  - partial: Talos publishing one joint, the bag holding only the left leg's joints;
//  - bias: a wrist force/torque sensor whose readings carry the offsets of a bias file,
//    joint states with measured efforts (paired with the estimate's stamp).
// Stamps jitter by 10% of the 10 ms period, as receive-time stamps do. The wrenches and
// /tf of a stamp are written half a period before its joint state, and the bag is
// played at a quarter of its pace, so that the node receives them in the bag's order.
#include "node_test_common.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Geometry>

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

namespace {

using jle_test::JointLoads;
using jle_test::runSpinning;

constexpr int kSamples = 150;
constexpr double kPeriod = 0.01;         // [s]
constexpr double kLead = 0.5 * kPeriod;  // [s] wrenches and /tf ahead of their joint state
constexpr double kPi = 3.14159265358979323846;
const ros::Time kStart(1700000000, 123456789);

// Sample k's stamp: the period with a deterministic jitter of up to 10%.
ros::Time stampOf(int k) {
  return kStart + ros::Duration(k * kPeriod + 0.1 * kPeriod * std::sin(1.7 * k));
}

sensor_msgs::JointState jointState(const std::string& ns, const ros::Time& stamp,
                                   const std::vector<std::string>& names, double t) {
  sensor_msgs::JointState js;
  js.header.stamp = stamp;
  js.header.frame_id = ns;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const double f = 0.4 + 0.15 * static_cast<double>(i);
    js.name.push_back(names[i]);
    js.position.push_back(0.1 * static_cast<double>(i) + 0.4 * std::sin(2 * kPi * f * t + i));
  }
  return js;
}

geometry_msgs::TransformStamped basePose(const ros::Time& stamp, double t) {
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = stamp;
  tf.header.frame_id = "world";
  tf.child_frame_id = "torso";
  tf.transform.translation.x = 0.05 * std::sin(2 * kPi * 0.5 * t);
  tf.transform.translation.y = 0.2 * t;
  tf.transform.translation.z = 1.0 + 0.03 * std::sin(2 * kPi * 0.9 * t);
  const Eigen::Quaterniond q(
      Eigen::AngleAxisd(0.05 * t, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(0.1 * std::sin(2 * kPi * 0.6 * t), Eigen::Vector3d::UnitY()));
  tf.transform.rotation.w = q.w();
  tf.transform.rotation.x = q.x();
  tf.transform.rotation.y = q.y();
  tf.transform.rotation.z = q.z();
  return tf;
}

// What the sensor reads: a slowly varying load plus the bias file's offsets.
geometry_msgs::WrenchStamped reading(const ros::Time& stamp, double t) {
  geometry_msgs::WrenchStamped w;
  w.header.stamp = stamp;
  w.header.frame_id = "ft_sensor";
  w.wrench.force.x = 2.0 * std::sin(2 * kPi * 0.8 * t) + 1.5;
  w.wrench.force.y = 1.0 - 2.25;
  w.wrench.force.z = -5.0 + std::cos(2 * kPi * 0.3 * t) + 3.0;
  w.wrench.torque.x = 0.2 * std::sin(2 * kPi * 0.5 * t) + 0.125;
  w.wrench.torque.y = -0.0625;
  w.wrench.torque.z = 0.1 * t + 0.25;
  return w;
}

void writeBag(const std::string& path) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  const std::vector<std::string> leg = {"leg_left_1_joint", "leg_left_2_joint", "leg_left_3_joint",
                                        "leg_left_4_joint", "leg_left_5_joint", "leg_left_6_joint"};
  const ros::Duration lead(kLead);
  for (int k = 0; k < kSamples; ++k) {
    const ros::Time stamp = stampOf(k);
    const double t = (stamp - kStart).toSec();
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(basePose(stamp, t));
    bag.write("/tf", stamp - lead, tf);
    bag.write("/bias/ft/wrench", stamp - lead, reading(stamp, t));
    bag.write("/floating/joint_states", stamp, jointState("floating", stamp, {"hip", "knee"}, t));
    bag.write("/partial/joint_states", stamp, jointState("partial", stamp, leg, t));
    sensor_msgs::JointState arm = jointState("bias", stamp, {"j1", "j2"}, t);
    arm.effort = {3.0 * std::sin(t), -1.0 + t};
    bag.write("/bias/joint_states", stamp, arm);
  }
}

// The loads of one stream of process_bag's output: "joint_loads" or "smoothed/joint_loads".
std::map<std::uint64_t, JointLoads> readLoads(const std::string& path, const std::string& topic) {
  std::map<std::uint64_t, JointLoads> loads;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m :
       rosbag::View(bag, rosbag::TopicQuery("/joint_load_estimator/" + topic))) {
    const JointLoads::ConstPtr msg = m.instantiate<JointLoads>();
    if (msg) loads[msg->header.stamp.toNSec()] = *msg;
  }
  return loads;
}

// The largest |online - offline| / max(1, |offline|) of the scenario being compared,
// printed after it (the figure the bound 1e-12 is checked against).
double worst_difference = 0.0;

void expectSame(double online, double offline, const std::string& what) {
  if (std::isnan(offline)) {
    EXPECT_TRUE(std::isnan(online)) << what;
    return;
  }
  const double scale = std::max(1.0, std::abs(offline));
  worst_difference = std::max(worst_difference, std::abs(online - offline) / scale);
  EXPECT_NEAR(online, offline, 1e-12 * scale) << what;
}

void expectSameLoads(const JointLoads& online, const JointLoads& offline) {
  ASSERT_EQ(online.name, offline.name);
  const std::string at = " at " + std::to_string(online.header.stamp.toSec());
  for (std::size_t i = 0; i < online.name.size(); ++i) {
    const std::string joint = online.name[i];
    const geometry_msgs::Wrench& a = online.wrench[i];
    const geometry_msgs::Wrench& b = offline.wrench[i];
    expectSame(a.force.x, b.force.x, joint + ".fx" + at);
    expectSame(a.force.y, b.force.y, joint + ".fy" + at);
    expectSame(a.force.z, b.force.z, joint + ".fz" + at);
    expectSame(a.torque.x, b.torque.x, joint + ".mx" + at);
    expectSame(a.torque.y, b.torque.y, joint + ".my" + at);
    expectSame(a.torque.z, b.torque.z, joint + ".mz" + at);
    expectSame(online.effort[i], offline.effort[i], joint + ".effort" + at);
    expectSame(online.measured_effort[i], offline.measured_effort[i], joint + ".measured" + at);
  }
}

struct Scenario {
  std::string ns, urdf, config;
  std::vector<std::string> joints;  // expected published joints
  bool measured = false;            // the joint states carry efforts
};

class Agreement : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    char dir[] = "/tmp/jle_agreement_XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr);
    dir_ = dir;
    writeBag(dir_ + "/in.bag");
  }
  static std::string dir_;
};
std::string Agreement::dir_;

// process_bag with the node's settings file (and, for the sensor, its bias file): its
// output bag.
std::string offline(const std::string& dir, const Scenario& s) {
  std::ifstream in(std::string(JLE_ROSTEST_DIR) + "/" + s.config);
  std::stringstream yaml;
  yaml << in.rdbuf();
  if (s.ns == "bias") yaml << "bias_file: " << JLE_ROSTEST_DIR << "/agreement_bias_file.yaml\n";
  const std::string config = dir + "/" + s.ns + ".yaml", out = dir + "/" + s.ns + "_loads.bag";
  std::ofstream(config) << yaml.str();
  EXPECT_EQ(runSpinning({JLE_PROCESS_BAG, "--bag", dir + "/in.bag", "--urdf", s.urdf, "--config",
                         config, "--output", out},
                        120.0),
            0);
  return out;
}

// The smoothed stream (on by default): every stamp the node published, process_bag
// published alike; process_bag also gives the last `lag` (0.2 s: 20 samples) at the end of
// the bag, which the live node is still waiting for.
void compareSmoothed(const Scenario& s, const std::vector<JointLoads>& on,
                     const std::map<std::uint64_t, JointLoads>& off) {
  EXPECT_GE(on.size(), static_cast<std::size_t>(kSamples - 10 - 22));
  EXPECT_GE(off.size(), on.size() + 18);
  std::size_t common = 0;
  worst_difference = 0.0;
  for (const JointLoads& m : on) {
    const auto it = off.find(m.header.stamp.toNSec());
    if (it == off.end()) continue;
    ++common;
    EXPECT_EQ(m.name, s.joints);
    expectSameLoads(m, it->second);
  }
  EXPECT_EQ(common, on.size()) << "smoothed stamps published by the node only";
  std::printf(
      "agreement %s, smoothed: %zu stamps compared (%zu offline), worst |difference| / "
      "max(1, |value|) %.3g\n",
      s.ns.c_str(), common, off.size(), worst_difference);
}

TEST_F(Agreement, NodeAndProcessBagPublishTheSameLoads) {
  const std::vector<Scenario> scenarios = {{"floating",
                                            JLE_ROSTEST_DIR "/two_link_floating.urdf",
                                            "agreement_floating.yaml",
                                            {"hip", "knee"}},
                                           {"partial",
                                            JLE_TEST_DATA "/urdf/talos_reduced.urdf",
                                            "agreement_partial.yaml",
                                            {"leg_left_4_joint"}},
                                           {"bias",
                                            JLE_TEST_DATA "/urdf/wrist_sensor_arm.urdf",
                                            "agreement_bias.yaml",
                                            {"j1", "j2"},
                                            true}};
  ros::NodeHandle nh;
  // Per scenario, the immediate and the smoothed stream.
  std::map<std::string, std::vector<JointLoads>> online, online_smoothed;
  std::vector<ros::Subscriber> subs;
  for (const Scenario& s : scenarios) {
    subs.push_back(nh.subscribe<JointLoads>(
        "/" + s.ns + "/joint_load_estimator/joint_loads", 10000,
        [&online, s](const JointLoads::ConstPtr& m) { online[s.ns].push_back(*m); }));
    subs.push_back(
        nh.subscribe<JointLoads>("/" + s.ns + "/joint_load_estimator/smoothed/joint_loads", 10000,
                                 [&online_smoothed, s](const JointLoads::ConstPtr& m) {
                                   online_smoothed[s.ns].push_back(*m);
                                 }));
  }
  ASSERT_TRUE(jle_test::waitFor(
      [&] {
        for (const ros::Subscriber& sub : subs)
          if (sub.getNumPublishers() == 0) return false;
        return true;
      },
      60.0));
  // rosbag play waits until the nodes listen to every input topic, then drives /clock.
  ASSERT_EQ(runSpinning({"rosbag", "play", "--clock", "--quiet", "--wait-for-subscribers", "--rate",
                         "0.25", dir_ + "/in.bag"},
                        120.0),
            0);
  jle_test::spinUntilQuiet([&] {
    std::size_t n = 0;
    for (const auto& o : online) n += o.second.size();
    for (const auto& o : online_smoothed) n += o.second.size();
    return n;
  });

  for (const Scenario& s : scenarios) {
    SCOPED_TRACE(s.ns);
    const std::string out = offline(dir_, s);
    compareSmoothed(s, online_smoothed[s.ns], readLoads(out, "smoothed/joint_loads"));
    const std::map<std::uint64_t, JointLoads> off = readLoads(out, "joint_loads");
    const std::vector<JointLoads>& on = online[s.ns];
    // Every stamp but the filter's start is published, online and offline alike.
    EXPECT_GE(on.size(), static_cast<std::size_t>(kSamples - 10));
    EXPECT_EQ(on.size(), off.size());
    std::size_t common = 0;
    worst_difference = 0.0;
    for (const JointLoads& m : on) {
      const auto it = off.find(m.header.stamp.toNSec());
      if (it == off.end()) continue;
      ++common;
      EXPECT_EQ(m.name, s.joints);
      expectSameLoads(m, it->second);
      if (s.measured) {
        EXPECT_FALSE(std::isnan(m.measured_effort[0]));
      }
    }
    EXPECT_EQ(common, on.size()) << "stamps published by the node only";
    std::printf("agreement %s: %zu stamps compared, worst |difference| / max(1, |value|) %.3g\n",
                s.ns.c_str(), common, worst_difference);
    RecordProperty("worst_difference_" + s.ns, std::to_string(worst_difference));
  }
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_agreement");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
