// Between ROS messages and the Pipeline: the only translation every front end (the node,
// the nodelet, process_bag) shares, so that online and offline feed the same numbers.
#pragma once

#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <geometry_msgs/WrenchStamped.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>

#include <string>
#include <vector>

namespace jle {

inline Stamp toStamp(const ros::Time& t) { return static_cast<Stamp>(t.toNSec()); }
inline ros::Time toRosTime(Stamp stamp) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(stamp));
  return t;
}

/// Frames from a tf2 buffer: the node's listener's, or one process_bag fills from a bag.
/// With a wait (the node's tf_wait; process_bag has none: the bag's order is the
/// buffer's), a transform that is late, its stamp newer than tf2's newest between the
/// two frames by at most the wait, is waited for up to the wait of wall time while the
/// buffer's own thread (the node's listener) fills it. Once a wait has run out, no
/// other is started until the newest transform moves (a stopped stream costs one wait).
/// A pair of frames with no chain between them yet (a latched /tf_static not delivered
/// yet) is waited for once, the first time it is asked for.
class Tf2FrameSource : public FrameSource {
 public:
  explicit Tf2FrameSource(const tf2::BufferCore& buffer) : buffer_(buffer) {}
  /// [s] of wall time, >= 0 (0: never wait).
  void setWait(double seconds) { wait_ = seconds; }
  bool lookup(const std::string& target, const std::string& frame, Stamp stamp,
              Eigen::Isometry3d& X_target_frame, std::string& error) override;

  /// Waits started and those that ran out; the longest [s] since clearLongestWait().
  long waits() const { return waits_; }
  long waitsRunOut() const { return waits_run_out_; }
  double longestWait() const { return longest_wait_; }
  void clearLongestWait() { longest_wait_ = 0.0; }

 private:
  std::string lookupError(const tf2::TransformException& e, const std::string& target,
                          const std::string& frame, Stamp stamp) const;
  // Whether the transform at `time` is late (see the class) and worth a wait.
  bool late(const std::string& target, const std::string& frame, const ros::Time& time);
  void waitFor(const std::string& target, const std::string& frame, const ros::Time& time);

  const tf2::BufferCore& buffer_;
  double wait_ = 0.0;
  ros::Time newest_;   // tf2's newest transform between the frames of the last late()
  ros::Time gave_up_;  // the newest when a wait last ran out
  std::string chain_;  // the pair of the last late() with no chain, or empty
  std::vector<std::string> missing_chains_;  // pairs already waited for with no chain
  long waits_ = 0, waits_run_out_ = 0;
  double longest_wait_ = 0.0;
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
