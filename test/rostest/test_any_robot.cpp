// estimator.launch in a namespace with a remapped joint-states topic (any_robot.test),
// the URDF from a file and from an existing parameter; ~joint_efforts against
// ~joint_loads and the joint states sent; ~reconfigure: the decimation applied with the
// filters kept (exactly the loads of a node left alone), a new differentiator restarting
// them, a bad value refused with the node publishing on.
#include "node_test_common.hpp"

#include <dynamic_reconfigure/Reconfigure.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace {

using jle_test::kTimeout;
using jle_test::nh;
using jle_test::Recorder;
using jle_test::waitFor;

const std::vector<std::string> kJoints{"shoulder_pan_joint", "shoulder_lift_joint",
                                       "elbow_joint",        "wrist_1_joint",
                                       "wrist_2_joint",      "wrist_3_joint"};
constexpr double kPeriod = 0.005;  // [s] the joint states' spacing

// The joint states sent: a smooth motion of every joint.
Eigen::VectorXd position(double t) {
  Eigen::VectorXd q(6);
  for (int i = 0; i < 6; ++i) q[i] = 0.3 * std::sin(1.5 * t + 0.7 * i) + 0.1 * i;
  return q;
}

class AnyRobot : public ::testing::Test {
 protected:
  AnyRobot()
      : joint_pub_(nh().advertise<sensor_msgs::JointState>("/arm1/driver/joint_states", 1000)),
        loads1_("/arm1/joint_load_estimator/joint_loads"),
        efforts1_("/arm1/joint_load_estimator/joint_efforts"),
        loads2_("/arm2/joint_load_estimator/joint_loads"),
        loads3_("/arm3/joint_load_estimator/joint_loads") {}

  void SetUp() override {
    for (const char* node :
         {"/arm1/joint_load_estimator", "/arm2/joint_load_estimator", "/arm3/joint_load_estimator"})
      ASSERT_TRUE(jle_test::waitForSubscriber(joint_pub_, node)) << node;
    ASSERT_TRUE(loads1_.connectTo("/arm1/joint_load_estimator"));
    ASSERT_TRUE(efforts1_.connectTo("/arm1/joint_load_estimator"));
    ASSERT_TRUE(loads2_.connectTo("/arm2/joint_load_estimator"));
    ASSERT_TRUE(loads3_.connectTo("/arm3/joint_load_estimator"));
    start_ = ros::Time::now();
  }

  // Sends n joint states (paced at their period), waits until both nodes are quiet.
  void send(int n) {
    for (int k = 0; k < n; ++k, ++sent_) {
      const ros::Time stamp = start_ + ros::Duration(sent_ * kPeriod);
      stamps_[stamp.toNSec()] = sent_;
      joint_pub_.publish(jle_test::jointState(stamp, kJoints, position(sent_ * kPeriod)));
      ros::spinOnce();
      ros::WallDuration(kPeriod).sleep();
    }
    jle_test::spinUntilQuiet(
        [&] { return loads1_.size() + loads2_.size() + loads3_.size() + efforts1_.size(); });
  }

  // arm2's (or arm3's) loads stamped like `msg`, or null.
  const jle_test::JointLoads* peer(const jle_test::JointLoads& msg, int arm = 2) const {
    for (const auto& m : (arm == 2 ? loads2_ : loads3_).msgs())
      if (m->header.stamp == msg.header.stamp) return m.get();
    return nullptr;
  }

  // Sets arm1's parameters through its dynamic_reconfigure service; the config in force.
  dynamic_reconfigure::Config reconfigure(const std::map<std::string, int>& ints,
                                          const std::map<std::string, double>& doubles,
                                          const std::map<std::string, std::string>& strs) {
    dynamic_reconfigure::Reconfigure srv;
    for (const auto& [name, value] : ints) {
      dynamic_reconfigure::IntParameter p;
      p.name = name;
      p.value = value;
      srv.request.config.ints.push_back(p);
    }
    for (const auto& [name, value] : doubles) {
      dynamic_reconfigure::DoubleParameter p;
      p.name = name;
      p.value = value;
      srv.request.config.doubles.push_back(p);
    }
    for (const auto& [name, value] : strs) {
      dynamic_reconfigure::StrParameter p;
      p.name = name;
      p.value = value;
      srv.request.config.strs.push_back(p);
    }
    const std::string service = "/arm1/joint_load_estimator/reconfigure/set_parameters";
    EXPECT_TRUE(ros::service::waitForService(service, ros::Duration(kTimeout)));
    EXPECT_TRUE(ros::service::call(service, srv)) << service;
    return srv.response.config;
  }

  ros::Publisher joint_pub_;
  jle_test::LoadsRecorder loads1_;
  Recorder<sensor_msgs::JointState> efforts1_;
  jle_test::LoadsRecorder loads2_;
  jle_test::LoadsRecorder loads3_;
  ros::Time start_;
  long sent_ = 0;
  std::map<std::uint64_t, long> stamps_;  // sample index of each stamp sent
};

int intValue(const dynamic_reconfigure::Config& c, const std::string& name) {
  for (const auto& p : c.ints)
    if (p.name == name) return p.value;
  return -1;
}

double doubleValue(const dynamic_reconfigure::Config& c, const std::string& name) {
  for (const auto& p : c.doubles)
    if (p.name == name) return p.value;
  return -1.0;
}

std::string strValue(const dynamic_reconfigure::Config& c, const std::string& name) {
  for (const auto& p : c.strs)
    if (p.name == name) return p.value;
  return "";
}

TEST_F(AnyRobot, EffortsLaunchAndLiveTuning) {
  // 1. Both nodes up in their namespaces, on the remapped topic; ~joint_efforts is the
  // JointLoads' content as a JointState.
  send(200);
  ASSERT_GT(loads1_.size(), 150u);
  ASSERT_EQ(efforts1_.size(), loads1_.size());
  for (std::size_t i = 0; i < efforts1_.size(); ++i) {
    const sensor_msgs::JointState& e = *efforts1_.msgs()[i];
    const jle_test::JointLoads& l = *loads1_.msgs()[i];
    ASSERT_EQ(e.header.stamp, l.header.stamp);
    ASSERT_EQ(e.name, kJoints);
    ASSERT_EQ(e.name, l.name);
    EXPECT_EQ(e.position, l.position);
    EXPECT_EQ(e.velocity, l.velocity);
    EXPECT_EQ(e.effort, l.effort);
    // The positions used are the filter's estimate of those sent at that stamp: the
    // default Kalman filter follows this slow motion to well below 1 mrad.
    const auto sample = stamps_.find(e.header.stamp.toNSec());
    ASSERT_NE(sample, stamps_.end());
    const Eigen::VectorXd q = position(sample->second * kPeriod);
    if (i > 50) {
      for (int j = 0; j < 6; ++j) EXPECT_NEAR(e.position[j], q[j], 1e-3) << kJoints[j];
    }
  }
  // The URDF from a file (arm1), from an existing parameter (arm2) and as the text of
  // ~robot_description (arm3): the same loads.
  for (int arm : {2, 3}) {
    for (const auto& m : loads1_.msgs()) {
      const jle_test::JointLoads* other = peer(*m, arm);
      ASSERT_NE(other, nullptr) << "arm" << arm;
      EXPECT_EQ(m->effort, other->effort) << "arm" << arm;
    }
  }

  // 2. decimation 2: every second sample, the filters kept (arm2's loads exactly).
  dynamic_reconfigure::Config c = reconfigure({{"decimation", 2}}, {}, {});
  EXPECT_EQ(intValue(c, "decimation"), 2);
  EXPECT_EQ(strValue(c, "status"), "applied: decimation 2, thresholds (filters kept)");
  std::size_t before = loads1_.size();
  send(100);
  EXPECT_NEAR(static_cast<double>(loads1_.size() - before), 50.0, 1.0);
  for (std::size_t i = before; i < loads1_.size(); ++i) {
    const jle_test::JointLoads* other = peer(*loads1_.msgs()[i]);
    ASSERT_NE(other, nullptr);
    EXPECT_EQ(loads1_.msgs()[i]->effort, other->effort) << "filters not kept";
  }

  // 3. Another differentiator: the filters restart (a warm-up without loads), then
  // loads of the new filter, not arm2's.
  c = reconfigure({{"decimation", 1}, {"differentiator_window", 7}}, {},
                  {{"differentiator_type", "savitzky_golay"}});
  EXPECT_EQ(strValue(c, "differentiator_type"), "savitzky_golay");
  EXPECT_EQ(strValue(c, "status"), "applied: differentiator 'savitzky_golay': the filters restart");
  before = loads1_.size();
  const long first = sent_;
  send(100);
  ASSERT_GT(loads1_.size(), before + 80);
  // Savitzky-Golay 7 causal: the first estimate needs 7 samples.
  EXPECT_EQ(stamps_.at(loads1_.msgs()[before]->header.stamp.toNSec()), first + 6);
  int differ = 0;
  for (std::size_t i = before; i < loads1_.size(); ++i) {
    const jle_test::JointLoads* other = peer(*loads1_.msgs()[i]);
    ASSERT_NE(other, nullptr);
    differ += loads1_.msgs()[i]->effort != other->effort;
  }
  EXPECT_EQ(differ, static_cast<int>(loads1_.size() - before));

  // 4. A bad value is refused whole (order 7 > 5): the settings in force are kept, the
  // answer says why where a client reads it (the config's `status`), and the node
  // publishes on.
  c = reconfigure({{"differentiator_order", 7}}, {}, {});
  EXPECT_EQ(intValue(c, "differentiator_order"), 2);
  EXPECT_EQ(strValue(c, "status").rfind("refused: ", 0), 0u) << strValue(c, "status");
  EXPECT_NE(strValue(c, "status").find("order"), std::string::npos) << strValue(c, "status");
  EXPECT_EQ(strValue(c, "differentiator_type"), "savitzky_golay");
  before = loads1_.size();
  send(20);
  EXPECT_EQ(loads1_.size(), before + 20);

  // 5. The Kalman smoother live (differentiator_lag 0.1 s: D = 20 samples at 200 Hz),
  // then back to the causal filter: the retune publishes the smoother's 20 pending
  // joint states first, so every joint state sent to the smoother has its loads, once,
  // in order.
  c = reconfigure({}, {{"differentiator_lag", 0.1}}, {{"differentiator_type", "kalman"}});
  EXPECT_EQ(doubleValue(c, "differentiator_lag"), 0.1);
  before = loads1_.size();
  const long smoothed = sent_;
  send(100);
  EXPECT_EQ(loads1_.size(), before + 80);  // 20 still to come
  c = reconfigure({}, {{"differentiator_lag", 0.0}}, {});
  EXPECT_EQ(doubleValue(c, "differentiator_lag"), 0.0);
  jle_test::spinUntilQuiet([&] { return loads1_.size(); });
  ASSERT_EQ(loads1_.size(), before + 100);
  for (std::size_t i = 0; i < 100; ++i)
    EXPECT_EQ(stamps_.at(loads1_.msgs()[before + i]->header.stamp.toNSec()),
              smoothed + static_cast<long>(i));

  // 6. A setting the running filter does not read (a Savitzky-Golay order while the
  // Kalman filter runs) is applied and said so; the filters are kept: every sample sent
  // has its loads at once, no warm-up (the causal filter warmed up first).
  send(20);
  c = reconfigure({{"differentiator_order", 3}}, {}, {});
  EXPECT_EQ(intValue(c, "differentiator_order"), 3);
  EXPECT_EQ(strValue(c, "status"),
            "applied: the filters kept (differentiator 'kalman' does not read the setting "
            "changed)");
  before = loads1_.size();
  const long kept = sent_;
  send(20);
  ASSERT_EQ(loads1_.size(), before + 20);
  EXPECT_EQ(stamps_.at(loads1_.msgs()[before]->header.stamp.toNSec()), kept);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_any_robot");
  return RUN_ALL_TESTS();
}
