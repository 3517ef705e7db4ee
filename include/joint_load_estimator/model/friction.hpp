// The optional friction term of a joint: the effort a motor must add to the rigid-body
// joint effort to overcome the joint's viscous damping and Coulomb friction, from the
// URDF's <dynamics damping friction> (Model::damping, Model::friction). ROS-free.
//
// Sign convention: the rigid-body effort is what the parent exerts on the child through
// the joint about (along) its axis; friction opposes the joint velocity, so the motor
// supplies it on top:
//   motor_effort = effort + damping * qd + friction * tanh(qd / velocity_scale)
// tanh replaces sign(qd) so that the term is smooth through qd = 0: within
// +-velocity_scale of rest the Coulomb part ramps from -friction to +friction
// (0.76 friction at qd = velocity_scale, 0.995 at 3 velocity_scale).
#pragma once

#include <cmath>

namespace jle {

/// The friction effort [N m or N] of a joint of viscous `damping` [N m s/rad or N s/m]
/// and Coulomb `friction` [N m or N] at velocity `qd` [rad/s or m/s], with the smooth
/// sign's `velocity_scale` [rad/s or m/s] > 0: damping qd + friction tanh(qd /
/// velocity_scale). Odd in qd; zero at rest.
inline double frictionEffort(double damping, double friction, double qd, double velocity_scale) {
  return damping * qd + friction * std::tanh(qd / velocity_scale);
}

}  // namespace jle
