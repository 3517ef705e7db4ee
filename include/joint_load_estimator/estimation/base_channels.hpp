// A floating base's pose filtered online: written into seven channels of the filter bank
// at each joint sample, and its pose, twist and acceleration read back at the bank's
// stamp. ROS-free.
#pragma once

#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/kinematics.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace jle {

struct BasePose;  // estimator.hpp

/// The pose into channels[0..7): the position [m] (world frame), then the orientation as
/// a unit quaternion (w, x, y, z), its sign chosen continuous with last_orientation's
/// (updated): then every component is smooth in time. base.orientation need not be unit.
void writeBasePose(const BasePose& base, Eigen::Quaterniond& last_orientation, double* channels);

/// The base's state at the bank's stamp from the seven channels from `channel`: the pose,
/// the velocity and acceleration of its origin, and from the quaternion q and its
/// derivatives (renormalised) omega = 2 vec(q' q*), alpha = 2 vec(q'' q*), world frame.
BaseState<double> baseStateFromBank(const DifferentiatorBank& bank, int channel);

}  // namespace jle
