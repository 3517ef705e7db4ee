// The joint_load_estimator node: parameters from ~ (config/default.yaml), model from
// robot_description. A bad configuration exits non-zero with the culprit named.
#include <joint_load_estimator/ros/estimator_node.hpp>

#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "joint_load_estimator");
  ros::NodeHandle nh, private_nh("~");
  try {
    jle::EstimatorNode node(nh, private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("joint_load_estimator: %s", e.what());
    return 1;
  }
  return 0;
}
