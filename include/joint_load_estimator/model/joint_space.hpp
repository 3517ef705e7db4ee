// Joint-space dynamics terms for the external-effort estimators (external_effort.hpp):
// the joint-space inertia matrix M(q) by a composite-rigid-body pass, the generalised
// gravity g(q), the Coriolis term C(q, qd)^T qd of the momentum observer through the
// subtree momenta, and a link point's geometric Jacobian. ROS-free, Eigen only.
//
// Everything is computed in the world frame with Plucker 6-vectors about the world
// origin O: a twist is (omega; v_O), a wrench (moment about O; force). In that frame a
// joint's motion axis S needs no transformation between segments, so the composite-
// rigid-body pass (Featherstone, "Rigid Body Dynamics Algorithms", 2008, sec. 6.2) is
//   Ic_i = I_i + sum over children Ic_c,  M_kj = M_jk = S_j^T (Ic_k S_k)  (j above k).
//
// C^T qd: with C the Christoffel-consistent Coriolis matrix, Mdot - 2 C is skew, so
// C^T qd = Mdot qd - C qd = dT/dq, T = qd^T M qd / 2 (Lagrange). Turning joint k moves
// its distal subtree rigidly about S_k with every joint rate kept, and the change of the
// kinetic energy is (C^T qd)_k = (v_k x S_k)^T H_k = Sdot_k^T H_k, H_k the momentum of
// the subtree distal to joint k, v_k the twist of k's segment: one forward pass for the
// twists, one backward pass summing the momenta (the recursion of the momentum form of
// the RNEA; Echeandia & Wensing, "Numerical methods to compute the Coriolis matrix and
// Christoffel symbols for rigid-body systems", J. Comput. Nonlinear Dyn. 2021).
//
// The joint space is that of the moving segments (mimic joints included, each with its
// own rate = multiplier * leader's rate): the per-joint efforts of inverse dynamics
// obey M q_dd + C qd + g = tau in these coordinates for any prescribed motion. The base
// is taken as fixed (a floating base: as still at its pose).
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <vector>

namespace jle {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// The joint space of a model's moving segments, and its workspace (allocated once).
struct JointSpace {
  explicit JointSpace(const Model<double>& model);

  int size() const { return static_cast<int>(segments.size()); }
  /// Moving segments in increasing index order: joint-space index j is segments[j].
  std::vector<int> segments;
  /// Per segment: its joint-space index, -1 when the joint does not move.
  std::vector<int> index;
  /// Per segment: the nearest moving segment above it (itself excluded), -1 at the root.
  std::vector<int> moving_parent;

  // Results of update(), world frame, about the world origin.
  std::vector<Vector6d> S;   ///< per segment: unit motion axis (zero if not moving)
  std::vector<Vector6d> v;   ///< per segment: twist [rad/s, m/s]
  std::vector<Matrix6d> Ic;  ///< per segment: composite spatial inertia of its subtree
  std::vector<Vector6d> H;   ///< per segment: momentum of its subtree [N m s, N s]
  Eigen::MatrixXd M;         ///< joint-space inertia, size() x size() [kg m^2, kg m, kg]
  Eigen::VectorXd gravity;   ///< g(q): efforts that hold the robot against gravity [N m or N]
  Eigen::VectorXd coriolis_transpose;  ///< C(q, qd)^T qd [N m or N]
  Eigen::VectorXd momentum;            ///< p = M qd [N m s or N s]
};

/// Fills `js` from `data` after forwardKinematics (poses, and data.qd per segment):
/// S, v, Ic, H, M, gravity, coriolis_transpose, momentum. gravity_world [m/s^2]. No
/// allocation.
void updateJointSpace(const Model<double>& model, const Data<double>& data,
                      const Eigen::Vector3d& gravity_world, JointSpace& js);

/// The geometric Jacobian (6 x js.size()) of the point `point_segment` of segment `segment`
/// (segment frame [m]), world frame, rows (linear velocity of the point; angular
/// velocity): J^T (force; moment about the point) is the joint efforts that wrench applied
/// to the robot balances. Needs updateJointSpace first (js.S). No allocation.
void pointJacobian(const Model<double>& model, const Data<double>& data, const JointSpace& js,
                   int segment, const Eigen::Vector3d& point_segment, Eigen::MatrixXd& J);

}  // namespace jle
