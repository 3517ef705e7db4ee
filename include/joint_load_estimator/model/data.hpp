// The workspace of the algorithms: every buffer sized once from the model.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <vector>

namespace jle {

/// Preallocated workspace and results for one model. Building it allocates; the
/// algorithms (kinematics.hpp, dynamics.hpp) never do.
template <typename Scalar>
struct Data {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

  explicit Data(const Model<Scalar>& model) {
    const std::size_t n = static_cast<std::size_t>(model.nsegments());
    q.assign(n, Scalar(0));
    qd.assign(n, Scalar(0));
    qdd.assign(n, Scalar(0));
    sin_q.assign(n, Scalar(0));
    cos_q.assign(n, Scalar(1));
    R_parent_child.assign(n, Matrix3::Identity());
    p_parent_child.assign(n, Vector3::Zero());
    R_world.assign(n, Matrix3::Identity());
    p_world.assign(n, Vector3::Zero());
    omega.assign(n, Vector3::Zero());
    alpha.assign(n, Vector3::Zero());
    acc.assign(n, Vector3::Zero());
    f_ext.assign(n, Vector3::Zero());
    n_ext.assign(n, Vector3::Zero());
    force.assign(n, Vector3::Zero());
    moment.assign(n, Vector3::Zero());
    effort.assign(n, Scalar(0));
  }

  // Forward pass (kinematics.hpp), per segment.
  std::vector<Scalar> q, qd, qdd;  ///< joint coordinate of the segment (mimics expanded)
  /// sin and cos of q where the joint is revolute (elsewhere not meaningful), computed
  /// for all joints before the forward pass's loop (trig.hpp, sinCosArray).
  std::vector<Scalar> sin_q, cos_q;
  std::vector<Matrix3> R_parent_child;  ///< segment orientation in its parent segment
  std::vector<Vector3> p_parent_child;  ///< segment origin in its parent segment [m]
  /// World poses: forwardKinematics or worldPoses() (localKinematics sets the root's only).
  std::vector<Matrix3> R_world;  ///< segment orientation in the world
  std::vector<Vector3> p_world;  ///< segment origin in the world [m]
  std::vector<Vector3> omega;    ///< angular velocity, segment frame [rad/s]
  std::vector<Vector3> alpha;    ///< angular acceleration, segment frame [rad/s^2]
  /// Acceleration of the segment origin minus gravity, segment frame [m/s^2]. Gravity
  /// enters as an upward acceleration of the base, so no segment needs its weight added.
  std::vector<Vector3> acc;

  // External loads on each segment (addExternalWrench): segment frame, about its origin.
  std::vector<Vector3> f_ext;  ///< [N]
  std::vector<Vector3> n_ext;  ///< [N m]

  // Backward pass (dynamics.hpp): the wrench that the parent exerts on the segment
  // through its joint, in the segment frame, moment about the joint origin. For segment
  // 0 it is what the world must apply to the root: the base reaction of a fixed base,
  // the residual (what the loads fail to explain) of a floating one.
  std::vector<Vector3> force;   ///< [N]
  std::vector<Vector3> moment;  ///< [N m]
  std::vector<Scalar> effort;   ///< axis . moment (revolute), axis . force (prismatic), else 0
};

}  // namespace jle
