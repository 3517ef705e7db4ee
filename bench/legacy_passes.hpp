// The forward and backward passes as they were before the leaner ones (main at
// c185352: a clear-then-add of the applied wrenches, world poses in the forward pass,
// Rodrigues for every axis, the per-segment steps left to the compiler's inlining),
// frozen for the before/after rows of bench/speed_core.cpp. Not used by the package.
#pragma once

#include <joint_load_estimator/data.hpp>
#include <joint_load_estimator/kinematics.hpp>
#include <joint_load_estimator/model.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace jle_legacy {

using jle::BaseState;
using jle::Data;
using jle::JointType;
using jle::Model;
using jle::VectorX;
using jle::checkCoordinates;

/// Rotation by angle q [rad] about the unit vector u (Rodrigues).
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 3> axisRotation(const Eigen::Matrix<Scalar, 3, 1>& u, Scalar q) {
  using std::cos;
  using std::sin;
  const Scalar s = sin(q);
  const Scalar c = cos(q);
  const Scalar t = Scalar(1) - c;
  Eigen::Matrix<Scalar, 3, 3> R;
  R(0, 0) = t * u.x() * u.x() + c;
  R(0, 1) = t * u.x() * u.y() - s * u.z();
  R(0, 2) = t * u.x() * u.z() + s * u.y();
  R(1, 0) = t * u.x() * u.y() + s * u.z();
  R(1, 1) = t * u.y() * u.y() + c;
  R(1, 2) = t * u.y() * u.z() - s * u.x();
  R(2, 0) = t * u.x() * u.z() - s * u.y();
  R(2, 1) = t * u.y() * u.z() + s * u.x();
  R(2, 2) = t * u.z() * u.z() + c;
  return R;
}

namespace detail {

// Root of the forward pass: the base state, gravity as an upward acceleration.
template <typename Scalar>
void forwardRoot(Data<Scalar>& data, const Eigen::Matrix<Scalar, 3, 1>& gravity_world,
                 const BaseState<Scalar>& base) {
  const Eigen::Matrix<Scalar, 3, 3>& R0 = base.R_world_base;
  data.R_world[0] = R0;
  data.p_world[0] = base.p_world_base;
  data.omega[0].noalias() = R0.transpose() * base.omega_world;
  data.alpha[0].noalias() = R0.transpose() * base.alpha_world;
  data.acc[0].noalias() = R0.transpose() * (base.a_world - gravity_world);
  data.f_ext[0].setZero();
  data.n_ext[0].setZero();
}

// One segment of the forward pass (its parent done). kStatic: the caller guarantees
// zero joint velocities and accelerations and a base at rest (angular), so every
// omega and alpha is zero and only the pose and the origin acceleration remain.
template <typename Scalar, bool kStatic>
inline void forwardSegment(const Model<Scalar>& model, Data<Scalar>& data, int i,
                           const VectorX<Scalar>& q, const VectorX<Scalar>& qd,
                           const VectorX<Scalar>& qdd) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  const int p = model.parent[i];
  const int k = model.coordinate[i];
  Scalar qi(0), qdi(0), qddi(0);
  if (k >= 0) {
    qi = model.multiplier[i] * q[k] + model.offset[i];
    if (!kStatic) {
      qdi = model.multiplier[i] * qd[k];
      qddi = model.multiplier[i] * qdd[k];
    }
  }
  data.q[i] = qi;
  data.qd[i] = qdi;
  data.qdd[i] = qddi;

  const Vector3& u = model.axis[i];
  Eigen::Matrix<Scalar, 3, 3>& R = data.R_parent_child[i];
  Vector3& r = data.p_parent_child[i];
  r = model.p_parent_joint[i];
  if (model.joint_type[i] == JointType::kRevolute)
    R.noalias() = model.R_parent_joint[i] * axisRotation(u, qi);
  else
    R = model.R_parent_joint[i];
  if (model.joint_type[i] == JointType::kPrismatic) r.noalias() += R * (u * qi);

  if (kStatic) {
    data.omega[i].setZero();
    data.alpha[i].setZero();
    data.acc[i].noalias() = R.transpose() * data.acc[p];
  } else {
    // Acceleration of this origin as a point of the parent, parent frame.
    const Vector3& w_p = data.omega[p];
    const Vector3 a_point = data.acc[p] + data.alpha[p].cross(r) + w_p.cross(w_p.cross(r));
    Vector3& w = data.omega[i];
    w.noalias() = R.transpose() * w_p;
    data.alpha[i].noalias() = R.transpose() * data.alpha[p];
    data.acc[i].noalias() = R.transpose() * a_point;
    if (model.joint_type[i] == JointType::kRevolute) {
      w += u * qdi;
      data.alpha[i] += u * qddi + w.cross(u * qdi);
    } else if (model.joint_type[i] == JointType::kPrismatic) {
      data.acc[i] += u * qddi + Scalar(2) * w.cross(u * qdi);
    }
  }

  data.R_world[i].noalias() = data.R_world[p] * R;
  data.p_world[i] = data.p_world[p];
  data.p_world[i].noalias() += data.R_world[p] * r;
  data.f_ext[i].setZero();
  data.n_ext[i].setZero();
}

}  // namespace detail

/// Forward pass. q, qd, qdd: size model.nq, in the order of model.coordinate_names
/// [rad, rad/s, rad/s^2 or m, m/s, m/s^2]. gravity_world [m/s^2]. Fills the kinematic
/// fields of data and clears its external wrenches.
template <typename Scalar>
void forwardKinematics(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                       const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                       const Eigen::Matrix<Scalar, 3, 1>& gravity_world,
                       const BaseState<Scalar>& base = BaseState<Scalar>()) {
  checkCoordinates(model, q, qd, qdd);
  detail::forwardRoot(data, gravity_world, base);
  const int n = model.nsegments();
  for (int i = 1; i < n; ++i) detail::forwardSegment<Scalar, false>(model, data, i, q, qd, qdd);
}

namespace detail {

// One segment of the backward pass in two halves: solveSegment adds its own inertial
// terms to what its children and the applied wrenches left in force/moment (and sets
// its effort); passToParent hands the result to its parent.
template <typename Scalar>
inline void solveSegment(const Model<Scalar>& model, Data<Scalar>& data, int i) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  Vector3& f = data.force[i];
  Vector3& m = data.moment[i];
  if (model.has_inertia[i]) {
    const Vector3& c = model.com[i];
    const Vector3& w = data.omega[i];
    const Vector3& al = data.alpha[i];
    const Vector3 m_a_com = model.mass[i] * (data.acc[i] + al.cross(c) + w.cross(w.cross(c)));
    f += m_a_com;
    m.noalias() += model.inertia_com[i] * al;
    m += c.cross(m_a_com);
    if (model.gyroscopic[i]) {
      const Vector3 Jw = model.inertia_com[i] * w;
      m += w.cross(Jw);
    }
  }
  switch (model.joint_type[i]) {
    case JointType::kRevolute: data.effort[i] = model.axis[i].dot(m); break;
    case JointType::kPrismatic: data.effort[i] = model.axis[i].dot(f); break;
    default: data.effort[i] = Scalar(0); break;
  }
}

// The second half of a segment's step: its joint wrench handed to its parent.
template <typename Scalar>
inline void passToParent(const Model<Scalar>& model, Data<Scalar>& data, int i) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  const Vector3& f = data.force[i];
  const Vector3& m = data.moment[i];
  const int p = model.parent[i];
  if (p < 0) return;
  // The child's joint wrench acts on the parent reversed; in the parent's sum it
  // enters with a plus sign (F = m a - F_0 with F_0 holding -F_child).
  const Vector3 f_p = data.R_parent_child[i] * f;
  data.force[p] += f_p;
  data.moment[p].noalias() += data.R_parent_child[i] * m;
  data.moment[p] += data.p_parent_child[i].cross(f_p);
}

template <typename Scalar>
inline void backwardSegment(const Model<Scalar>& model, Data<Scalar>& data, int i) {
  solveSegment(model, data, i);
  passToParent(model, data, i);
}

}  // namespace detail

/// Backward pass over the kinematics in data (forwardKinematics) and the external
/// wrenches added since. For each segment, in its own frame (the paper's equations are
/// frame-independent; in the segment frame J'_G is constant and no world offset enters),
///   F = m (a_G - g) - F_0
///   M = J_G alpha + omega x J_G omega - xi_n x F - M_0,
/// with F_0, M_0 the resultants of the applied wrenches and of the children's joint
/// wrenches (reversed), and xi_n = joint origin - x_G. The moment is accumulated directly
/// about the joint origin, which is the same sum rearranged: no large lever arm cancels.
/// Fills data.force, data.moment (child frame, about the joint origin) and data.effort.
template <typename Scalar>
void inverseDynamics(const Model<Scalar>& model, Data<Scalar>& data) {
  const int n = model.nsegments();
  for (int i = 0; i < n; ++i) {
    data.force[i] = -data.f_ext[i];
    data.moment[i] = -data.n_ext[i];
  }
  for (int i = n - 1; i >= 0; --i) detail::backwardSegment(model, data, i);
}

}  // namespace jle_legacy
