// Forward pass: every segment's pose, angular velocity and acceleration, origin
// acceleration, from the joint coordinates and the base state.
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/model/trig.hpp>

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

/// Rotation about the unit vector u by the angle whose sine and cosine are s and c
/// (Rodrigues).
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 3> axisRotation(const Eigen::Matrix<Scalar, 3, 1>& u, Scalar s, Scalar c) {
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

/// Rotation by angle q [rad] about the unit vector u (Rodrigues; sin and cos by sinCos).
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 3> axisRotation(const Eigen::Matrix<Scalar, 3, 1>& u, Scalar q) {
  Scalar s, c;
  sinCos(q, s, c);
  return axisRotation(u, s, c);
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

// The per-segment steps are forced inline (JLE_ALWAYS_INLINE, trig.hpp): the loops over
// segments are the whole of the algorithms, and a call per segment costs more than its
// bookkeeping saves.

// The algorithms read the flags Model::analyze() derives; a model built by hand must call it.
template <typename Scalar>
void checkAnalyzed(const Model<Scalar>& model) {
  const std::size_t n = static_cast<std::size_t>(model.nsegments());
  if (model.axis_index.size() != n || model.opens_parent.size() != n ||
      model.has_children.size() != n || model.has_inertia.size() != n ||
      model.gyroscopic.size() != n)
    throw std::invalid_argument("the model was not analyzed: call Model::analyze() once built");
}

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

// forwardRoot for BaseState's defaults (identity pose, at rest): the same values
// without the products by the identity.
template <typename Scalar>
void forwardRootAtRest(Data<Scalar>& data, const Eigen::Matrix<Scalar, 3, 1>& gravity_world) {
  data.R_world[0].setIdentity();
  data.p_world[0].setZero();
  data.omega[0].setZero();
  data.alpha[0].setZero();
  data.acc[0] = -gravity_world;
  data.f_ext[0].setZero();
  data.n_ext[0].setZero();
}

// R = R_parent_joint * (rotation by q about axis u): for u = +-e_k (sign = u_k) the
// rotation leaves column k and mixes the other two, 12 products instead of Rodrigues'
// and a 3x3 product's 39. Equal to the general product but for its rounding of
// (1 - cos q) + cos q, which is exactly 1 here.
template <typename Scalar>
JLE_ALWAYS_INLINE void jointRotation(const Model<Scalar>& model, int i, Scalar s, Scalar c,
                                     Eigen::Matrix<Scalar, 3, 3>& R) {
  const Eigen::Matrix<Scalar, 3, 3>& R0 = model.R_parent_joint[i];
  const int k = model.axis_index[i];
  if (k < 0) {
    R.noalias() = R0 * axisRotation(model.axis[i], s, c);
    return;
  }
  s *= model.axis[i][k];
  const int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;  // (k, a, b) cyclic
  // Whole columns, as the products that read R next load them: a column written entry
  // by entry and then read as a packet stalls the load (no store forwarding).
  const Eigen::Matrix<Scalar, 3, 1> ca = R0.col(a), cb = R0.col(b);
  R.col(k) = R0.col(k);
  R.col(a) = ca * c + cb * s;
  R.col(b) = cb * c - ca * s;
}

// The joint's own terms added to omega and alpha (revolute, rate qd, acceleration qdd):
// omega += u qd, alpha += u qdd + omega x u qd, with u's zeros skipped when u = +-e_k.
template <typename Scalar>
JLE_ALWAYS_INLINE void revoluteRates(const Model<Scalar>& model, int i, Scalar qd, Scalar qdd,
                                     Eigen::Matrix<Scalar, 3, 1>& w,
                                     Eigen::Matrix<Scalar, 3, 1>& al) {
  const Eigen::Matrix<Scalar, 3, 1>& u = model.axis[i];
  const int k = model.axis_index[i];
  if (k < 0) {
    w += u * qd;
    al += u * qdd + w.cross(u * qd);
    return;
  }
  const int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
  const Scalar sqd = u[k] * qd;
  w[k] += sqd;
  al[k] += u[k] * qdd;
  al[a] += w[b] * sqd;
  al[b] -= w[a] * sqd;
}

// The joint coordinates of segment i (mimics expanded) into data.q, qd, qdd; kStatic:
// the rates are zero.
template <typename Scalar, bool kStatic>
JLE_ALWAYS_INLINE void segmentCoordinates(const Model<Scalar>& model, Data<Scalar>& data, int i,
                                          const VectorX<Scalar>& q, const VectorX<Scalar>& qd,
                                          const VectorX<Scalar>& qdd) {
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
}

// One segment of the forward pass (its parent done, its coordinates and their sin and
// cos in data), in the segment frames only.
// kStatic: the caller guarantees zero joint velocities and accelerations and a base at
// rest (angular), so every omega and alpha is zero and only the pose and the origin
// acceleration remain.
template <typename Scalar, bool kStatic>
JLE_ALWAYS_INLINE void forwardSegment(const Model<Scalar>& model, Data<Scalar>& data, int i) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  const int p = model.parent[i];
  const Scalar qi = data.q[i], qdi = data.qd[i], qddi = data.qdd[i];

  const JointType type = model.joint_type[i];
  Eigen::Matrix<Scalar, 3, 3>& R = data.R_parent_child[i];
  Vector3& r = data.p_parent_child[i];
  r = model.p_parent_joint[i];
  if (type == JointType::kRevolute)
    jointRotation(model, i, data.sin_q[i], data.cos_q[i], R);
  else
    R = model.R_parent_joint[i];
  if (type == JointType::kPrismatic) r.noalias() += R * (model.axis[i] * qi);

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
    if (type == JointType::kRevolute) {
      revoluteRates(model, i, qdi, qddi, w, data.alpha[i]);
    } else if (type == JointType::kPrismatic) {
      const Vector3& u = model.axis[i];
      data.acc[i] += u * qddi + Scalar(2) * w.cross(u * qdi);
    }
  }
  data.f_ext[i].setZero();
  data.n_ext[i].setZero();
}

// Segment i's pose in the world from its parent's.
template <typename Scalar>
JLE_ALWAYS_INLINE void worldPose(const Model<Scalar>& model, Data<Scalar>& data, int i) {
  const int p = model.parent[i];
  data.R_world[i].noalias() = data.R_world[p] * data.R_parent_child[i];
  data.p_world[i] = data.p_world[p];
  data.p_world[i].noalias() += data.R_world[p] * data.p_parent_child[i];
}

// The forward pass's segments, every one after the root.
template <typename Scalar>
void forwardSegments(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                     const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd) {
  const int n = model.nsegments();
  for (int i = 1; i < n; ++i) segmentCoordinates<Scalar, false>(model, data, i, q, qd, qdd);
  sinCosArray(n - 1, data.q.data() + 1, data.sin_q.data() + 1, data.cos_q.data() + 1);
  for (int i = 1; i < n; ++i) forwardSegment<Scalar, false>(model, data, i);
}

}  // namespace detail

/// The forward pass in the segment frames: fills data.q, qd, qdd, R_parent_child,
/// p_parent_child, omega, alpha, acc (segment frames) and the root's world pose, and
/// clears the external wrenches; the other segments' world poses (R_world, p_world) are
/// left as they were: worldPoses() fills them when a world-frame input or output needs
/// them. q, qd, qdd: size model.nq, in the order of model.coordinate_names [rad, rad/s,
/// rad/s^2 or m, m/s, m/s^2]. gravity_world [m/s^2].
template <typename Scalar>
void localKinematics(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                     const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                     const Eigen::Matrix<Scalar, 3, 1>& gravity_world,
                     const BaseState<Scalar>& base) {
  checkCoordinates(model, q, qd, qdd);
  detail::checkAnalyzed(model);
  detail::forwardRoot(data, gravity_world, base);
  detail::forwardSegments(model, data, q, qd, qdd);
}

/// localKinematics with the base at rest at the world's origin (BaseState's defaults).
template <typename Scalar>
void localKinematics(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                     const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                     const Eigen::Matrix<Scalar, 3, 1>& gravity_world) {
  checkCoordinates(model, q, qd, qdd);
  detail::checkAnalyzed(model);
  detail::forwardRootAtRest(data, gravity_world);
  detail::forwardSegments(model, data, q, qd, qdd);
}

/// localKinematics over `segments` only: indices in increasing order, closed under
/// parents (every listed segment's parent is listed), starting with 0. With `statics`
/// the caller asserts zero joint velocities and accelerations and a base that does
/// not rotate, and the velocity terms are skipped.
template <typename Scalar>
void localKinematics(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                     const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                     const Eigen::Matrix<Scalar, 3, 1>& gravity_world,
                     const BaseState<Scalar>& base, const std::vector<int>& segments,
                     bool statics) {
  checkCoordinates(model, q, qd, qdd);
  detail::checkAnalyzed(model);
  detail::forwardRoot(data, gravity_world, base);
  const int count = static_cast<int>(segments.size()) - 1;
  const auto listed = [&segments](int j) { return segments[j + 1]; };
  if (statics) {
    data.omega[0].setZero();
    data.alpha[0].setZero();
    for (int j = 0; j < count; ++j)
      detail::segmentCoordinates<Scalar, true>(model, data, listed(j), q, qd, qdd);
    sinCosMany(count, listed, data.q.data(), data.sin_q.data(), data.cos_q.data());
    for (int j = 0; j < count; ++j) detail::forwardSegment<Scalar, true>(model, data, listed(j));
  } else {
    for (int j = 0; j < count; ++j)
      detail::segmentCoordinates<Scalar, false>(model, data, listed(j), q, qd, qdd);
    sinCosMany(count, listed, data.q.data(), data.sin_q.data(), data.cos_q.data());
    for (int j = 0; j < count; ++j) detail::forwardSegment<Scalar, false>(model, data, listed(j));
  }
}

/// Every segment's world pose (data.R_world, data.p_world [m]) from the segment-frame
/// poses of localKinematics (the root's is the base pose it was given).
template <typename Scalar>
void worldPoses(const Model<Scalar>& model, Data<Scalar>& data) {
  const int n = model.nsegments();
  for (int i = 1; i < n; ++i) detail::worldPose(model, data, i);
}

/// worldPoses over `segments` only (increasing, closed under parents, starting with 0).
template <typename Scalar>
void worldPoses(const Model<Scalar>& model, Data<Scalar>& data, const std::vector<int>& segments) {
  for (std::size_t j = 1; j < segments.size(); ++j) detail::worldPose(model, data, segments[j]);
}

/// Forward pass: localKinematics and worldPoses, every field of data's kinematics.
template <typename Scalar>
void forwardKinematics(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                       const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                       const Eigen::Matrix<Scalar, 3, 1>& gravity_world,
                       const BaseState<Scalar>& base) {
  localKinematics(model, data, q, qd, qdd, gravity_world, base);
  worldPoses(model, data);
}

/// forwardKinematics with the base at rest at the world's origin (BaseState's defaults).
template <typename Scalar>
void forwardKinematics(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                       const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                       const Eigen::Matrix<Scalar, 3, 1>& gravity_world) {
  localKinematics(model, data, q, qd, qdd, gravity_world);
  worldPoses(model, data);
}

/// The forward pass over `segments` only (see localKinematics), world poses included.
template <typename Scalar>
void forwardKinematics(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                       const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                       const Eigen::Matrix<Scalar, 3, 1>& gravity_world,
                       const BaseState<Scalar>& base, const std::vector<int>& segments,
                       bool statics) {
  localKinematics(model, data, q, qd, qdd, gravity_world, base, segments, statics);
  worldPoses(model, data, segments);
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
