// The joint_load_estimator node: parameters from ~ (config/default.yaml), model from
// robot_description. A bad configuration exits non-zero with the culprit named.
// --help and --version print and exit 0 before ros::init (no master, no parameters).
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/ros/estimator_node.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <ros/ros.h>

#include <cstdio>
#include <cstring>
#include <string>

namespace {

const char* const kUsage =
    R"(usage: rosrun joint_load_estimator joint_load_estimator [ROS remappings, e.g. joint_states:=/arm/joint_states]
       roslaunch joint_load_estimator estimator.launch model:=ROBOT.urdf [ns:=NS] [joint_states:=TOPIC] [config:=FILE.yaml]

Estimates, at every joint state, the 6-D wrench and the effort of every joint of the
robot in the parameter robot_description (URDF), and publishes them:
  ~joint_loads     joint_load_estimator/JointLoads (wrenches, efforts, q, q-dot, q-ddot)
  ~joint_efforts   sensor_msgs/JointState (names, the q and q-dot used, the efforts)
  ~wrench/<joint>  geometry_msgs/WrenchStamped in the joint's child link frame (rviz)
  /diagnostics
Input: joint_states (sensor_msgs/JointState), the wrench and force plate topics of the
parameters. Parameters: the private namespace (config/default.yaml lists every key
with its default; docs/node.md "Parameters"). Live tuning: ~reconfigure (dynamic_reconfigure).

Options (handled before ROS starts):
  --help, -h   this text
  --version    the package's version
Exit status: 0 on shutdown; 1 a bad configuration or model (the culprit is named).
)";

// The robot_description parameter not set yet (a launch file whose xacro or
// robot_state_publisher step comes later, a description loaded by hand): waited for,
// said every 5 s, not taken for an error. Here, not in the node's constructor: a
// nodelet's onInit must not block its manager (the nodelet refuses it at once).
bool waitForRobotDescription(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh) {
  std::string name;
  private_nh.param<std::string>("robot_description", name, jle::Settings().robot_description);
  if (jle::isUrdfText(name)) return true;  // the URDF itself
  const std::string resolved = jle::resolveParameter(nh, name);
  ros::WallTime said;
  while (!nh.hasParam(resolved)) {
    if (!ros::ok()) return false;
    if (said.isZero() || (ros::WallTime::now() - said).toSec() >= 5.0) {
      said = ros::WallTime::now();
      ROS_WARN("waiting for the parameter '%s' (robot_description): not set yet", resolved.c_str());
    }
    ros::WallDuration(0.1).sleep();
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (std::strcmp(argv[i], "--version") == 0) {
      std::printf("joint_load_estimator %s\n", jle::cli::version());
      return 0;
    }
  }
  ros::init(argc, argv, "joint_load_estimator");
  ros::NodeHandle nh, private_nh("~");
  try {
    if (!waitForRobotDescription(nh, private_nh)) return 0;  // shut down while waiting
    jle::EstimatorNode node(nh, private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("joint_load_estimator: %s", e.what());
    return 1;
  }
  return 0;
}
