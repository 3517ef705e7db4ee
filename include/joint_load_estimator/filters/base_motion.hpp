// The velocity and acceleration of a floating base estimated from its sampled pose
// (offline: the samples on both sides are known). ROS-free.
//
// Method: the quadratic through three consecutive samples (t0, t1, t2), any spacing,
// differentiated at one of them. At the middle sample (centred):
//   x'  error  -h1 h2 x'''/6                      (second order)
//   x'' error  (h2 - h1) x'''/3 - (h1^2 - h1 h2 + h2^2) x''''/12
//              (second order on a uniform grid, first order where the step changes)
// with h1 = t1 - t0, h2 = t2 - t1. At the first and the last sample of a trial
// (one-sided), x' is second order (error h1 (h1 + h2) x'''/6 at t0) and x'' first
// order (error (2 h1 + h2) x'''/3 at t0).
// The orientation is differentiated through the rotation vectors of the three
// orientations relative to the one at the evaluated sample, r_j = log(R_m^T R_j): r is
// zero at t_m, where dr/dt is the body-frame angular velocity and d2r/dt2 the body-frame
// angular acceleration exactly, so the same stencils and error orders hold. A
// quaternion and its negative give the same R: sign flips in the input do not matter.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/kinematics.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace jle {

/// Weights of the quadratic through (t[0], y0), (t[1], y1), (t[2], y2) differentiated at
/// t[m] (m = 0, 1 or 2): y'(t_m) ~ sum_j d1[j] y_j, y''(t_m) ~ sum_j d2[j] y_j. The three
/// times must be distinct.
inline void threePointWeights(const double t[3], int m, double d1[3], double d2[3]) {
  for (int j = 0; j < 3; ++j) {
    const int a = (j + 1) % 3, b = (j + 2) % 3;
    const double den = (t[j] - t[a]) * (t[j] - t[b]);
    d1[j] = ((t[m] - t[a]) + (t[m] - t[b])) / den;
    d2[j] = 2.0 / den;
  }
}

/// Rotation vector (axis times angle [rad], angle in [0, pi]) of a rotation matrix.
inline Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double n = q.vec().norm();
  if (n == 0.0) return Eigen::Vector3d::Zero();
  return (2.0 * std::atan2(n, q.w()) / n) * q.vec();
}

/// One sample of the base pose: the root link's orientation and origin in the world.
struct BasePoseSample {
  double t = 0.0;  ///< [s]
  Eigen::Matrix3d R_world_base = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_world_base = Eigen::Vector3d::Zero();  ///< [m]
};

/// The twist of the base at sample m of three consecutive pose samples (method above):
/// v_world (velocity of the root link origin) and omega_world, world frame.
/// With `acceleration`, also a_world and alpha_world. The pose of `base` is left alone.
inline void baseMotionFromPoses(const BasePoseSample s[3], int m, BaseState<double>& base,
                                bool acceleration) {
  const double t[3] = {s[0].t, s[1].t, s[2].t};
  double d1[3], d2[3];
  threePointWeights(t, m, d1, d2);
  const Eigen::Matrix3d& R_m = s[m].R_world_base;
  Eigen::Vector3d v = Eigen::Vector3d::Zero(), a = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_body = Eigen::Vector3d::Zero(), al_body = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j) {
    v += d1[j] * s[j].p_world_base;
    a += d2[j] * s[j].p_world_base;
    if (j == m) continue;  // r_m = 0
    const Eigen::Vector3d r = rotationVector(R_m.transpose() * s[j].R_world_base);
    w_body += d1[j] * r;
    al_body += d2[j] * r;
  }
  base.v_world = v;
  base.omega_world = R_m * w_body;
  if (acceleration) {
    base.a_world = a;
    // d/dt (R w_body) = R (w_body x w_body + dw_body/dt) = R alpha_body.
    base.alpha_world = R_m * al_body;
  }
}

/// The acceleration of the base at sample m of three consecutive twist samples: the
/// first derivative of the quadratic through them (second order, above).
inline void baseAccelerationFromTwists(const double t[3], int m, const Eigen::Vector3d v_world[3],
                                       const Eigen::Vector3d omega_world[3],
                                       BaseState<double>& base) {
  double d1[3], d2[3];
  threePointWeights(t, m, d1, d2);
  base.a_world = d1[0] * v_world[0] + d1[1] * v_world[1] + d1[2] * v_world[2];
  base.alpha_world = d1[0] * omega_world[0] + d1[1] * omega_world[1] + d1[2] * omega_world[2];
}

}  // namespace jle
