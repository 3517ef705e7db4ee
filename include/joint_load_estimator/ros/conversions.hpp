// Between ROS messages and the Pipeline: the only translation every front end (the node,
// the nodelet, process_bag) shares, so that online and offline feed the same numbers.
#pragma once

#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/pipeline.hpp>

#include <geometry_msgs/WrenchStamped.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>

#include <string>

namespace jle {

inline Stamp toStamp(const ros::Time& t) { return static_cast<Stamp>(t.toNSec()); }
inline ros::Time toRosTime(Stamp stamp) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(stamp));
  return t;
}

/// Frames from a tf2 buffer: the node's listener's, or one process_bag fills from a bag.
/// Never waits: a transform not yet known at the stamp is a miss.
class Tf2FrameSource : public FrameSource {
 public:
  explicit Tf2FrameSource(const tf2::BufferCore& buffer) : buffer_(buffer) {}
  bool lookup(const std::string& target, const std::string& frame, Stamp stamp,
              Eigen::Isometry3d& X_target_frame, std::string& error) override;

 private:
  std::string lookupError(const tf2::TransformException& e, const std::string& target,
                          const std::string& frame, Stamp stamp) const;

  const tf2::BufferCore& buffer_;
};

/// Feeds one message to the pipeline; `clock` is the front end's time of arrival
/// (ros::Time::now() in the node, the bag time offline).
Outcome feed(Pipeline& pipeline, const sensor_msgs::JointState& msg, const ros::Time& clock);
Outcome feedWrench(Pipeline& pipeline, int k, const geometry_msgs::WrenchStamped& msg,
                   const ros::Time& clock);
Outcome feedPlate(Pipeline& pipeline, int k, const geometry_msgs::WrenchStamped& msg,
                  const ros::Time& clock);

/// Sizes `msg` for `record`'s joints (once: later calls reuse its storage).
void prepare(const LoadsRecord& record, joint_load_estimator::JointLoads& msg);
/// The record as a JointLoads message (prepare()d), no allocation.
void toMessage(const LoadsRecord& record, joint_load_estimator::JointLoads& msg);
/// Sizes `msg` (~joint_efforts) for `record`'s joints (once).
void prepare(const LoadsRecord& record, sensor_msgs::JointState& msg);
/// The record as a sensor_msgs/JointState (prepare()d), no allocation: name, the
/// position and velocity the loads were computed from, and the estimated effort; the
/// stamp of the JointLoads message of the same record.
void toJointState(const LoadsRecord& record, sensor_msgs::JointState& msg);
/// Joint i of the record as a wrench message in its child link frame.
void toWrenchMessage(const LoadsRecord& record, std::size_t i, geometry_msgs::WrenchStamped& msg);

}  // namespace jle
