// Writing the example bags (make_example_bag, make_gait_bag): stamps, wrench messages,
// and a bag written beside its path and renamed onto it on success only.
#pragma once

#include <geometry_msgs/WrenchStamped.h>
#include <ros/time.h>
#include <rosbag/bag.h>

#include <Eigen/Core>

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

namespace jle_tools {

/// A time in nanoseconds since the epoch as a ros::Time.
inline ros::Time stampOf(std::int64_t ns) {
  return ros::Time(static_cast<std::uint32_t>(ns / 1000000000),
                   static_cast<std::uint32_t>(ns % 1000000000));
}

/// Sets the force [N] and the moment [N m] of a wrench message.
inline void setWrench(geometry_msgs::WrenchStamped& msg, const Eigen::Vector3d& force,
                      const Eigen::Vector3d& moment) {
  msg.wrench.force.x = force.x();
  msg.wrench.force.y = force.y();
  msg.wrench.force.z = force.z();
  msg.wrench.torque.x = moment.x();
  msg.wrench.torque.y = moment.y();
  msg.wrench.torque.z = moment.z();
}

/// A bag written to PATH.partial and renamed onto PATH by commit(); the partial file is
/// removed if commit() is never reached (an error, an exception).
class PartialBag {
 public:
  explicit PartialBag(std::string path) : path_(std::move(path)), temporary_(path_ + ".partial") {
    try {
      bag_.open(temporary_, rosbag::bagmode::Write);
    } catch (...) {
      std::remove(temporary_.c_str());
      throw;
    }
  }
  ~PartialBag() {
    if (!committed_) std::remove(temporary_.c_str());
  }
  PartialBag(const PartialBag&) = delete;
  PartialBag& operator=(const PartialBag&) = delete;

  rosbag::Bag& bag() { return bag_; }

  /// Closes the bag and renames it onto the path.
  void commit() {
    bag_.close();
    if (std::rename(temporary_.c_str(), path_.c_str()) != 0)
      throw std::runtime_error(path_ + ": cannot rename " + temporary_ + " onto it");
    committed_ = true;
  }

 private:
  std::string path_, temporary_;
  rosbag::Bag bag_;
  bool committed_ = false;
};

}  // namespace jle_tools
