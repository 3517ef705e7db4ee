// Forward pass: every segment's pose, angular velocity and acceleration, origin
// acceleration, from the joint coordinates and the base state.
#pragma once

#include <joint_load_estimator/data.hpp>
#include <joint_load_estimator/model.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace jle {

template <typename Scalar>
using VectorX = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

/// Motion of the root segment, all in the world frame. For a fixed base only the pose
/// is used (the twist and acceleration are taken as zero by the caller's choice of
/// leaving them zero); for a floating base all of it.
template <typename Scalar>
struct BaseState {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  Matrix3 R_world_base = Matrix3::Identity();
  Vector3 p_world_base = Vector3::Zero();  ///< [m]
  Vector3 v_world = Vector3::Zero();       ///< velocity of the base origin [m/s]
  Vector3 omega_world = Vector3::Zero();   ///< [rad/s]
  Vector3 a_world = Vector3::Zero();       ///< acceleration of the base origin [m/s^2]
  Vector3 alpha_world = Vector3::Zero();   ///< [rad/s^2]

  /// The same state in another scalar type.
  template <typename Other>
  BaseState<Other> cast() const {
    BaseState<Other> out;
    out.R_world_base = R_world_base.template cast<Other>();
    out.p_world_base = p_world_base.template cast<Other>();
    out.v_world = v_world.template cast<Other>();
    out.omega_world = omega_world.template cast<Other>();
    out.a_world = a_world.template cast<Other>();
    out.alpha_world = alpha_world.template cast<Other>();
    return out;
  }
};

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

/// Checks the sizes of the coordinate vectors once, before the loops.
template <typename Scalar>
void checkCoordinates(const Model<Scalar>& model, const VectorX<Scalar>& q,
                      const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd) {
  if (q.size() != model.nq || qd.size() != model.nq || qdd.size() != model.nq)
    throw std::invalid_argument("coordinate vectors have sizes " + std::to_string(q.size()) + ", " +
                                std::to_string(qd.size()) + ", " + std::to_string(qdd.size()) +
                                "; the model has " + std::to_string(model.nq) + " coordinates");
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

/// The forward pass over `segments` only: indices in increasing order, closed under
/// parents (every listed segment's parent is listed), starting with 0. With `statics`
/// the caller asserts zero joint velocities and accelerations and a base that does
/// not rotate, and the velocity terms are skipped.
template <typename Scalar>
void forwardKinematics(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                       const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                       const Eigen::Matrix<Scalar, 3, 1>& gravity_world,
                       const BaseState<Scalar>& base, const std::vector<int>& segments,
                       bool statics) {
  checkCoordinates(model, q, qd, qdd);
  detail::forwardRoot(data, gravity_world, base);
  if (statics) {
    data.omega[0].setZero();
    data.alpha[0].setZero();
    for (std::size_t j = 1; j < segments.size(); ++j)
      detail::forwardSegment<Scalar, true>(model, data, segments[j], q, qd, qdd);
  } else {
    for (std::size_t j = 1; j < segments.size(); ++j)
      detail::forwardSegment<Scalar, false>(model, data, segments[j], q, qd, qdd);
  }
}

/// Angular velocity of segment i in the world frame [rad/s].
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 1> omegaWorld(const Data<Scalar>& data, int i) {
  return data.R_world[i] * data.omega[i];
}

/// Angular acceleration of segment i in the world frame [rad/s^2].
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 1> alphaWorld(const Data<Scalar>& data, int i) {
  return data.R_world[i] * data.alpha[i];
}

/// Centre of mass of segment i in the world frame [m].
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 1> comWorld(const Model<Scalar>& model, const Data<Scalar>& data, int i) {
  return data.p_world[i] + data.R_world[i] * model.com[i];
}

/// Acceleration of the centre of mass of segment i in the world frame [m/s^2]
/// (gravity_world is the one given to forwardKinematics).
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 1> comAccelerationWorld(const Model<Scalar>& model,
                                                 const Data<Scalar>& data, int i,
                                                 const Eigen::Matrix<Scalar, 3, 1>& gravity_world) {
  const Eigen::Matrix<Scalar, 3, 1>& c = model.com[i];
  const Eigen::Matrix<Scalar, 3, 1>& w = data.omega[i];
  const Eigen::Matrix<Scalar, 3, 1> a = data.acc[i] + data.alpha[i].cross(c) + w.cross(w.cross(c));
  return data.R_world[i] * a + gravity_world;
}

}  // namespace jle
