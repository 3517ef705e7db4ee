#include <joint_load_estimator/ros/conversions.hpp>

#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <chrono>
#include <thread>

namespace jle {
namespace {

// Pipeline::onWrench or Pipeline::onPlate: one shape for both.
using WrenchInput = Outcome (Pipeline::*)(int, Stamp, Stamp, const std::string&,
                                          const Eigen::Vector3d&, const Eigen::Vector3d&);

Outcome feedWrenchStamped(Pipeline& pipeline, WrenchInput input, int k,
                          const geometry_msgs::WrenchStamped& msg, const ros::Time& clock) {
  const auto& w = msg.wrench;
  return (pipeline.*input)(k, toStamp(msg.header.stamp), toStamp(clock), msg.header.frame_id,
                           Eigen::Vector3d(w.force.x, w.force.y, w.force.z),
                           Eigen::Vector3d(w.torque.x, w.torque.y, w.torque.z));
}

}  // namespace

// What tf2 could not do, in the user's terms (its own texts name its functions and
// arguments).
std::string Tf2FrameSource::lookupError(const tf2::TransformException& e, const std::string& target,
                                        const std::string& frame, Stamp stamp) const {
  if (dynamic_cast<const tf2::LookupException*>(&e)) {
    const std::string& unknown = buffer_._frameExists(frame) ? target : frame;
    return "tf2 has no frame '" + unknown + "' (nothing has published it)";
  }
  if (dynamic_cast<const tf2::ConnectivityException*>(&e))
    return "tf2 has no chain of transforms between '" + frame + "' and '" + target + "'";
  if (dynamic_cast<const tf2::ExtrapolationException*>(&e))
    return "tf2 has no transform between '" + frame + "' and '" + target + "' at " +
           std::to_string(toRosTime(stamp).toSec()) + " s (before or after what it holds)";
  return "tf2 cannot give '" + frame + "' in '" + target + "'";
}

bool Tf2FrameSource::late(const std::string& target, const std::string& frame,
                          const ros::Time& time) {
  try {
    newest_ = buffer_.lookupTransform(target, frame, ros::Time(0)).header.stamp;
  } catch (const tf2::TransformException&) {
    // No chain yet (a latched /tf_static the listener has not delivered, the first
    // poses): one wait per pair of frames, the first time.
    chain_ = target + '\n' + frame;
    return std::find(missing_chains_.begin(), missing_chains_.end(), chain_) ==
           missing_chains_.end();
  }
  chain_.clear();
  const double behind = (time - newest_).toSec();
  return behind > 0.0 && behind <= wait_ && newest_ != gave_up_;
}

void Tf2FrameSource::waitFor(const std::string& target, const std::string& frame,
                             const ros::Time& time) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const Clock::time_point deadline =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait_));
  ++waits_;
  bool arrived = false;
  while (!(arrived = buffer_.canTransform(target, frame, time)) && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  if (!arrived) {
    ++waits_run_out_;
    gave_up_ = newest_;
  }
  if (!chain_.empty()) missing_chains_.push_back(chain_);  // waited for once
  longest_wait_ =
      std::max(longest_wait_, std::chrono::duration<double>(Clock::now() - start).count());
}

bool Tf2FrameSource::lookup(const std::string& target, const std::string& frame, Stamp stamp,
                            Eigen::Isometry3d& X_target_frame, std::string& error) {
  const ros::Time time = toRosTime(stamp);
  // The lookup first: the wait (and tf2's second walk of the chain) only where it fails.
  for (bool waited = false;; waited = true) {
    try {
      X_target_frame = tf2::transformToEigen(buffer_.lookupTransform(target, frame, time));
      return true;
    } catch (const tf2::TransformException& e) {
      if (waited || !(wait_ > 0.0 && late(target, frame, time))) {
        error = lookupError(e, target, frame, stamp);
        return false;
      }
    }
    waitFor(target, frame, time);
  }
}

Outcome feed(Pipeline& pipeline, const sensor_msgs::JointState& msg, const ros::Time& clock) {
  return pipeline.onJointState(toStamp(msg.header.stamp), toStamp(clock), msg.name, msg.position,
                               msg.velocity, msg.effort);
}

Outcome feedWrench(Pipeline& pipeline, int k, const geometry_msgs::WrenchStamped& msg,
                   const ros::Time& clock) {
  return feedWrenchStamped(pipeline, &Pipeline::onWrench, k, msg, clock);
}

Outcome feedPlate(Pipeline& pipeline, int k, const geometry_msgs::WrenchStamped& msg,
                  const ros::Time& clock) {
  return feedWrenchStamped(pipeline, &Pipeline::onPlate, k, msg, clock);
}

void prepare(const LoadsRecord& record, joint_load_estimator::JointLoads& msg) {
  const std::size_t n = record.joint.size();
  msg.name = record.joint;
  msg.wrench.resize(n);
  msg.effort.resize(n);
  msg.measured_effort.resize(n);
  msg.effort_stddev.resize(record.effort_stddev.size());
  msg.covariance.resize(record.covariance.size());
  msg.effort_per_kg.resize(record.effort_per_kg.size());
  msg.position.resize(n);
  msg.velocity.resize(n);
  msg.acceleration.resize(n);
  msg.motor_effort.resize(record.motor_effort.size());
  msg.external_effort.resize(record.external_effort.size());
  msg.external_effort_stddev.resize(record.external_effort_stddev.size());
}

void toMessage(const LoadsRecord& record, joint_load_estimator::JointLoads& msg) {
  msg.header.stamp = toRosTime(record.stamp);
  msg.status = record.status;
  for (std::size_t i = 0; i < record.joint.size(); ++i) {
    geometry_msgs::Wrench& w = msg.wrench[i];
    w.force.x = record.force[i].x();
    w.force.y = record.force[i].y();
    w.force.z = record.force[i].z();
    w.torque.x = record.moment[i].x();
    w.torque.y = record.moment[i].y();
    w.torque.z = record.moment[i].z();
  }
  msg.effort = record.effort;  // equal sizes: copies, no allocation
  msg.measured_effort = record.measured_effort;
  msg.effort_stddev = record.effort_stddev;
  msg.covariance = record.covariance;
  msg.effort_per_kg = record.effort_per_kg;
  msg.position = record.position;
  msg.velocity = record.velocity;
  msg.acceleration = record.acceleration;
  msg.motor_effort = record.motor_effort;
  msg.external_effort = record.external_effort;
  msg.external_effort_stddev = record.external_effort_stddev;
}

void prepare(const LoadsRecord& record, sensor_msgs::JointState& msg) {
  const std::size_t n = record.joint.size();
  msg.name = record.joint;
  msg.position.resize(n);
  msg.velocity.resize(n);
  msg.effort.resize(n);
}

void toJointState(const LoadsRecord& record, sensor_msgs::JointState& msg) {
  msg.header.stamp = toRosTime(record.stamp);
  msg.position = record.position;  // equal sizes: copies, no allocation
  msg.velocity = record.velocity;
  msg.effort = record.effort;
}

void toWrenchMessage(const LoadsRecord& record, std::size_t i, geometry_msgs::WrenchStamped& msg) {
  msg.header.stamp = toRosTime(record.stamp);
  msg.header.frame_id = record.link[i];
  msg.wrench.force = tf2::toMsg(record.force[i], msg.wrench.force);
  msg.wrench.torque = tf2::toMsg(record.moment[i], msg.wrench.torque);
}

}  // namespace jle
