// Backward pass: the per-segment 6x6 inverse dynamics of Federico & Alhasadi (2022),
// solved from the leaves to the root.
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <stdexcept>
#include <string>
#include <vector>

namespace jle {

/// The frame a wrench is expressed in.
enum class WrenchFrame : std::uint8_t {
  kChild,   ///< the joint's child link (segment) frame
  kParent,  ///< the joint's URDF parent link frame
  kWorld,   ///< the world frame
  kLocal,   ///< for an applied wrench: the frame of the link it is applied at
};

/// A force and a moment [N, N m]; which frame and which point is said where it is used.
template <typename Scalar>
struct Wrench {
  Eigen::Matrix<Scalar, 3, 1> force = Eigen::Matrix<Scalar, 3, 1>::Zero();
  Eigen::Matrix<Scalar, 3, 1> moment = Eigen::Matrix<Scalar, 3, 1>::Zero();
};

/// Adds a wrench applied TO the robot at the origin of frame `frame` (an index into
/// model.frames), expressed in that frame (kLocal) or in the world (kWorld). Call after
/// forwardKinematics (which clears the previous ones; localKinematics does too, but a
/// kWorld wrench needs worldPoses() as well) and before inverseDynamics.
template <typename Scalar>
void addExternalWrench(const Model<Scalar>& model, Data<Scalar>& data, int frame,
                       const Eigen::Matrix<Scalar, 3, 1>& force,
                       const Eigen::Matrix<Scalar, 3, 1>& moment, WrenchFrame expressed_in) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  if (frame < 0 || frame >= static_cast<int>(model.frames.size()))
    throw std::invalid_argument("external wrench on frame index " + std::to_string(frame) +
                                ", the model has " + std::to_string(model.frames.size()));
  const Frame<Scalar>& fr = model.frames[frame];
  const int s = fr.segment;
  Vector3 f, n;
  if (expressed_in == WrenchFrame::kLocal) {
    f.noalias() = fr.R_segment_frame * force;
    n.noalias() = fr.R_segment_frame * moment;
  } else if (expressed_in == WrenchFrame::kWorld) {
    f.noalias() = data.R_world[s].transpose() * force;
    n.noalias() = data.R_world[s].transpose() * moment;
  } else {
    throw std::invalid_argument("an external wrench on '" + fr.name +
                                "' must be expressed in its link frame or the world");
  }
  data.f_ext[s] += f;
  data.n_ext[s] += n + fr.p_segment_frame.cross(f);
}

namespace detail {

// One segment of the backward pass in two halves: solveSegment adds its own inertial
// terms to what its children and the applied wrenches left in force/moment (and sets
// its effort); passToParent hands the result to its parent. The sums start from the
// applied wrenches, reversed: at a leaf in solveSegment, elsewhere when the first of
// the children (the highest-numbered, Model::opens_parent) passes its wrench up, so no
// separate pass clears them. The order of the additions is that of a clear-then-add.
template <typename Scalar>
JLE_ALWAYS_INLINE void solveSegment(const Model<Scalar>& model, Data<Scalar>& data, int i) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  Vector3& f = data.force[i];
  Vector3& m = data.moment[i];
  if (!model.has_children[i]) {
    f = -data.f_ext[i];
    m = -data.n_ext[i];
  }
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
  const int k = model.axis_index[i];  // u = +-e_k: the projection is one component
  switch (model.joint_type[i]) {
    case JointType::kRevolute:
      data.effort[i] = k >= 0 ? model.axis[i][k] * m[k] : model.axis[i].dot(m);
      break;
    case JointType::kPrismatic:
      data.effort[i] = k >= 0 ? model.axis[i][k] * f[k] : model.axis[i].dot(f);
      break;
    default: data.effort[i] = Scalar(0); break;
  }
}

// The second half of a segment's step: its joint wrench handed to its parent.
template <typename Scalar>
JLE_ALWAYS_INLINE void passToParent(const Model<Scalar>& model, Data<Scalar>& data, int i) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  const Vector3& f = data.force[i];
  const Vector3& m = data.moment[i];
  const int p = model.parent[i];
  if (p < 0) return;
  // The child's joint wrench acts on the parent reversed; in the parent's sum it
  // enters with a plus sign (F = m a - F_0 with F_0 holding -F_child).
  const Eigen::Matrix<Scalar, 3, 3>& R = data.R_parent_child[i];
  const Vector3 f_p = R * f;
  if (model.opens_parent[i]) {
    data.force[p] = f_p - data.f_ext[p];
    data.moment[p].noalias() = R * m - data.n_ext[p];
  } else {
    data.force[p] += f_p;
    data.moment[p].noalias() += R * m;
  }
  data.moment[p] += data.p_parent_child[i].cross(f_p);
}

template <typename Scalar>
JLE_ALWAYS_INLINE void backwardSegment(const Model<Scalar>& model, Data<Scalar>& data, int i) {
  solveSegment(model, data, i);
  passToParent(model, data, i);
}

}  // namespace detail

/// Backward pass over the kinematics in data (forwardKinematics or localKinematics) and
/// the external wrenches added since. For each segment, in its own frame (the paper's
/// equations are frame-independent; in the segment frame J'_G is constant and no world
/// offset enters),
///   F = m (a_G - g) - F_0
///   M = J_G alpha + omega x J_G omega - xi_n x F - M_0,
/// with F_0, M_0 the resultants of the applied wrenches and of the children's joint
/// wrenches (reversed), and xi_n = joint origin - x_G. The moment is accumulated directly
/// about the joint origin, which is the same sum rearranged: no large lever arm cancels.
/// Fills data.force, data.moment (child frame, about the joint origin) and data.effort;
/// reads no world pose.
template <typename Scalar>
void inverseDynamics(const Model<Scalar>& model, Data<Scalar>& data) {
  detail::checkAnalyzed(model);
  for (int i = model.nsegments() - 1; i >= 0; --i) detail::backwardSegment(model, data, i);
}

/// The backward pass over `segments` only: increasing indices, closed under children
/// (every child of a listed segment is listed). The wrenches of the listed segments
/// are exact; what they hand to unlisted parents is not meaningful.
template <typename Scalar>
void inverseDynamics(const Model<Scalar>& model, Data<Scalar>& data,
                     const std::vector<int>& segments) {
  detail::checkAnalyzed(model);
  for (auto it = segments.rbegin(); it != segments.rend(); ++it)
    detail::backwardSegment(model, data, *it);
}

/// The backward pass over `segments` (as above) with a hook: `at_joint(i)` is called
/// once segment i's joint wrench is solved (data.force[i], data.moment[i], child frame,
/// about the joint origin) and before it is handed to the parent. It may replace that
/// wrench, e.g. by the reading of a force/torque sensor mounted at the joint: the
/// parent and everything proximal then see the replacement, which is the same as
/// applying the difference (computed minus replacement) to segment i at its joint
/// origin. data.effort[i] keeps the computed value. No allocation.
template <typename Scalar, typename AtJoint>
void inverseDynamics(const Model<Scalar>& model, Data<Scalar>& data,
                     const std::vector<int>& segments, AtJoint&& at_joint) {
  detail::checkAnalyzed(model);
  for (auto it = segments.rbegin(); it != segments.rend(); ++it) {
    detail::solveSegment(model, data, *it);
    at_joint(*it);
    detail::passToParent(model, data, *it);
  }
}

/// The joint wrench of segment i (exerted by its parent, moment about the joint
/// origin), expressed in the child, the URDF parent-link or the world frame.
template <typename Scalar>
Wrench<Scalar> jointWrench(const Model<Scalar>& model, const Data<Scalar>& data, int i,
                           WrenchFrame frame) {
  Wrench<Scalar> out;
  switch (frame) {
    case WrenchFrame::kChild:
    case WrenchFrame::kLocal:
      out.force = data.force[i];
      out.moment = data.moment[i];
      break;
    case WrenchFrame::kParent: {
      if (i == 0) {  // the root's "parent" is the world
        out.force = data.R_world[0] * data.force[0];
        out.moment = data.R_world[0] * data.moment[0];
        break;
      }
      const Eigen::Matrix<Scalar, 3, 3> R =
          model.R_parentsegment_parentlink[i].transpose() * data.R_parent_child[i];
      out.force = R * data.force[i];
      out.moment = R * data.moment[i];
      break;
    }
    case WrenchFrame::kWorld:
      out.force = data.R_world[i] * data.force[i];
      out.moment = data.R_world[i] * data.moment[i];
      break;
  }
  return out;
}

/// forwardKinematics + inverseDynamics with no external wrench.
template <typename Scalar>
void rnea(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
          const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
          const Eigen::Matrix<Scalar, 3, 1>& gravity_world) {
  forwardKinematics(model, data, q, qd, qdd, gravity_world);
  inverseDynamics(model, data);
}

}  // namespace jle
