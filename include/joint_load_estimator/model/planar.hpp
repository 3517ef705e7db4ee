// The planar reduction of Federico & Alhasadi (2022), section 6: when a model moves in a
// plane, the per-segment 6x6 system reduces to 3x3 (two force components in the plane,
// one moment about its normal) and the gyroscopic term vanishes. This file detects such
// models, and runs a planar forward pass (one angle, a 2-D origin acceleration per
// segment) and a 3x3 backward pass whose result, mapped back by a constant rotation per
// segment, is the same full 6-D joint wrench as dynamics.hpp (child frame, moment about
// the joint origin).
//
// When the result is exact. Let n be a unit vector in the root frame. If
//   (1) the base is fixed,
//   (2) every revolute joint turns about +n or -n (its axis, in its frame, is parallel to
//       the normal carried down the tree by the constant joint placements),
//   (3) every prismatic joint slides perpendicular to n,
//   (4) gravity is perpendicular to n,
//   (5) n is a principal axis of every segment's inertia about its centre of mass,
//   (6) every applied wrench has its force perpendicular to n and its moment along n,
// then every segment turns about n only (omega, alpha along n, by induction down the
// tree: a rotation about n leaves n unchanged), every point accelerates in the plane
// (alpha x r and omega x (omega x r) are perpendicular to n for any r), so every force
// in the problem lies in the plane and J_G alpha lies along n (5) while omega x J_G omega
// = 0. The joint force then has no component along n: F.n = 0 exactly. The moment about
// the joint origin has a component along n, which the 3x3 system solves, and in-plane
// components which come only from the offsets along n (heights h) of the points where
// the in-plane forces act (centres of mass, child joint origins, load points):
//   M_inplane = n x S,   S = sum_k (h_k - h_joint) F_k,
// a first moment of the forces below the joint. S is accumulated along the backward pass
// for two multiply-adds per segment (and skipped when the model has no offset along n),
// so offsets along n are supported exactly rather than refused: they are common (a
// planar arm whose links are stacked along their axes). With h = 0 everywhere, S = 0
// and the in-plane moment is exactly zero.
//
// Detection tolerance. URDF placements are rounded (an rpy of pi/2 gives cos = 6e-17; a
// generic rpy rebuilds its matrix to ~2e-15), and the normal carried down a tree
// accumulates that rounding joint after joint. The conditions are checked to the
// relative tolerance planarTolerance() = 1e-13: |axis x n_i| (revolute), |axis . n_i|
// (prismatic), |g . n| / |g|, |J n_i x n_i| / |J|. A model accepted at tolerance d
// is an exactly planar model whose joint axes, gravity and inertias are moved by at
// most d each; the planar result is exact for that model and differs from the 6x6
// result of the given one by at most about d times the load scale per joint on the
// path to the root (first order): within 1e-12 relative for trees up to 10 joints deep
// even if every joint sat at the tolerance, and far deeper for rounding-level
// deviations (test_planar measures the difference on random trees up to 38 joints).
// Applied wrenches are checked per sample to the same tolerance (relative to their own
// magnitude); a sample with an out-of-plane wrench takes the 6x6 path.
//
// Forced use (a PlanarModel built although detectPlanar refused, and applied wrenches
// added without planarWrenchInPlane): the user asserts planarity; the normal is that
// of the first revolute joint, revolute axes are taken as +-n (sign of axis . n),
// inertia enters as n.J.n, and every out-of-plane component (of prismatic axes,
// gravity, applied wrenches) is dropped. Exact only where detection would agree.
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <cmath>
#include <string>
#include <vector>

namespace jle {

/// Relative tolerance of the planarity checks (see the file comment): 1e-13 in double
/// (64 eps in a coarser type).
template <typename Scalar>
Scalar planarTolerance() {
  using std::max;
  return max(Scalar(1e-13), Scalar(64) * Eigen::NumTraits<Scalar>::epsilon());
}

/// Outcome of detectPlanar().
template <typename Scalar>
struct PlanarCheck {
  bool planar = false;
  /// Unit normal of the plane in the root frame: the axis of the first revolute joint
  /// (zero if the model has none).
  Eigen::Matrix<Scalar, 3, 1> normal = Eigen::Matrix<Scalar, 3, 1>::Zero();
  /// Why the model is not planar (names the joint or link), or "" when it is.
  std::string reason;
};

/// The constant part of the planar problem. Every segment carries a "plane frame" that
/// turns with it: its third axis is n, and world-plane coordinates (the root's plane
/// basis E = [e1 e2 n]) of a vector are Rz(phi_i) times its plane-frame coordinates,
/// phi_i the segment's angle. K[i] maps segment-frame coordinates to plane-frame ones
/// (rows: e1, e2, n of segment i in its own frame); it is constant because rotations
/// about n commute with the placements down the tree.
template <typename Scalar>
struct PlanarModel {
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

  Vector3 normal = Vector3::UnitZ();  ///< n in the root frame
  Matrix3 E = Matrix3::Identity();    ///< root plane basis [e1 e2 n], root frame
  bool offsets = false;               ///< some point lies off the plane of its joint (S needed)
  // Per segment, size nsegments().
  std::vector<Matrix3> K;          ///< segment frame -> plane frame
  std::vector<Scalar> sign;        ///< revolute: axis = sign * n; else 0
  std::vector<Vector2> origin;     ///< joint origin in the parent's plane frame, in-plane part [m]
  std::vector<Scalar> height;      ///< ... and its offset along n [m]
  std::vector<Vector2> slide;      ///< prismatic: unit axis in the plane frame (in-plane)
  std::vector<Vector2> com;        ///< centre of mass in the plane frame, in-plane part [m]
  std::vector<Scalar> com_height;  ///< ... and its offset along n [m]
  std::vector<Scalar> inertia_n;   ///< n . J_G n [kg m^2]
  // Per model frame (Model::frames), size frames.size().
  std::vector<Matrix3> K_frame;       ///< link frame -> plane frame of its segment
  std::vector<Vector2> frame_origin;  ///< link origin in the plane frame, in-plane part [m]
  std::vector<Scalar> frame_height;   ///< ... and its offset along n [m]
};

/// Per-sample workspace of the planar passes (allocated once).
template <typename Scalar>
struct PlanarData {
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  explicit PlanarData(int nsegments = 0) {
    const std::size_t n = static_cast<std::size_t>(nsegments);
    cos_phi.assign(n, Scalar(1));
    sin_phi.assign(n, Scalar(0));
    phi.assign(n, Scalar(0));
    omega.assign(n, Scalar(0));
    alpha.assign(n, Scalar(0));
    r.assign(n, Vector2::Zero());
    acc.assign(n, Vector2::Zero());
    force.assign(n, Vector2::Zero());
    moment.assign(n, Scalar(0));
    first_moment.assign(n, Vector2::Zero());
  }
  // All vectors in world-plane coordinates (E^T of the root frame, first two).
  std::vector<Scalar> cos_phi, sin_phi, phi;  ///< segment angle about n [rad]
  std::vector<Scalar> omega, alpha;           ///< [rad/s, rad/s^2] along n
  std::vector<Vector2> r;                     ///< parent origin -> this origin, in-plane [m]
  std::vector<Vector2> acc;                   ///< origin acceleration minus gravity [m/s^2]
  /// Backward pass: joint force (in-plane), moment along n about the joint origin, and
  /// S = sum of height * force (the in-plane moment is n x S). Before the pass they hold
  /// minus the applied wrenches (planarAddExternalWrench).
  std::vector<Vector2> force;         ///< [N]
  std::vector<Scalar> moment;         ///< [N m]
  std::vector<Vector2> first_moment;  ///< [N m]
};

namespace detail {

// Columns e1, e2 completing the unit n to a right-handed orthonormal basis.
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 3> planeBasis(const Eigen::Matrix<Scalar, 3, 1>& n) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  Eigen::Matrix<Scalar, 3, 3> E;
  Vector3 e1;
  // Exactly the root axes when n is +-z (the usual case): no rounding enters.
  if (n.x() == Scalar(0) && n.y() == Scalar(0)) {
    e1 = Vector3::UnitX();
  } else {
    e1 = (std::abs(n.x()) < std::abs(n.y()) ? Vector3::UnitX() : Vector3::UnitY())
             .cross(n)
             .normalized();
  }
  E.col(0) = e1;
  E.col(1) = n.cross(e1);
  E.col(2) = n;
  return E;
}

}  // namespace detail

/// Whether the model satisfies conditions (1)-(5) of the file comment over `segments`
/// (increasing, closed under parents; empty: all), gravity_root [m/s^2] in the root
/// frame. Never throws.
template <typename Scalar>
PlanarCheck<Scalar> detectPlanar(const Model<Scalar>& model,
                                 const Eigen::Matrix<Scalar, 3, 1>& gravity_root,
                                 const std::vector<int>& segments = {}) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  PlanarCheck<Scalar> out;
  const Scalar tol = planarTolerance<Scalar>();
  const int n = model.nsegments();
  std::vector<int> all;
  const std::vector<int>* list = &segments;
  if (segments.empty()) {
    for (int i = 0; i < n; ++i) all.push_back(i);
    list = &all;
  }
  // Orientation of each segment in the root frame at q = 0: rotations about n leave n
  // where it is, so n in each frame follows from the placements alone.
  std::vector<Matrix3> R(static_cast<std::size_t>(n), Matrix3::Identity());
  for (int i : *list) {
    if (i > 0) R[i] = R[model.parent[i]] * model.R_parent_joint[i];
    if (model.joint_type[i] == JointType::kRevolute && out.normal.isZero())
      out.normal = R[i] * model.axis[i];
  }
  if (model.floating_base) {
    out.reason = "the base is floating";
    return out;
  }
  if (out.normal.isZero()) {
    out.reason = "no revolute joint defines the plane";
    return out;
  }
  out.normal.normalize();
  const Scalar g = gravity_root.norm();
  if (std::abs(gravity_root.dot(out.normal)) > tol * g) {
    out.reason = "gravity has a component along the plane normal";
    return out;
  }
  for (int i : *list) {
    const Vector3 n_i = R[i].transpose() * out.normal;
    const Vector3& u = model.axis[i];
    if (model.joint_type[i] == JointType::kRevolute && u.cross(n_i).norm() > tol) {
      out.reason = "joint '" + model.joint_name[i] +
                   "' turns about an axis not parallel to the plane normal";
      return out;
    }
    if (model.joint_type[i] == JointType::kPrismatic && std::abs(u.dot(n_i)) > tol) {
      out.reason = "joint '" + model.joint_name[i] + "' slides out of the plane";
      return out;
    }
    const Vector3 Jn = model.inertia_com[i] * n_i;
    // Relative to the whole inertia: the neglected moments scale with |J| omega^2.
    if (Jn.cross(n_i).norm() > tol * model.inertia_com[i].norm()) {
      out.reason = "the plane normal is not a principal axis of the inertia of link '" +
                   model.link_name[i] + "'";
      return out;
    }
  }
  out.planar = true;
  return out;
}

/// The constant planar data for normal n (root frame, unit; detectPlanar's). The
/// conditions are not checked here: out-of-plane components are dropped.
template <typename Scalar>
PlanarModel<Scalar> planarModel(const Model<Scalar>& model,
                                const Eigen::Matrix<Scalar, 3, 1>& normal) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  // A height that is rounding of an in-plane placement (within the tolerance of the
  // point's distance) is zero, so that a flat model skips the first moments S.
  const auto inPlaneOrHeight = [](const Vector3& o) {
    return std::abs(o.z()) <= planarTolerance<Scalar>() * o.norm() ? Scalar(0) : o.z();
  };
  PlanarModel<Scalar> pm;
  pm.normal = normal;
  pm.E = detail::planeBasis(normal);
  const int n = model.nsegments();
  pm.K.resize(static_cast<std::size_t>(n));
  pm.sign.assign(static_cast<std::size_t>(n), Scalar(0));
  pm.origin.assign(static_cast<std::size_t>(n), Vector2::Zero());
  pm.height.assign(static_cast<std::size_t>(n), Scalar(0));
  pm.slide.assign(static_cast<std::size_t>(n), Vector2::Zero());
  pm.com.assign(static_cast<std::size_t>(n), Vector2::Zero());
  pm.com_height.assign(static_cast<std::size_t>(n), Scalar(0));
  pm.inertia_n.assign(static_cast<std::size_t>(n), Scalar(0));
  for (int i = 0; i < n; ++i) {
    if (i == 0) {
      pm.K[0] = pm.E.transpose();
    } else {
      const int p = model.parent[i];
      pm.K[i] = pm.K[p] * model.R_parent_joint[i];
      const Vector3 o = pm.K[p] * model.p_parent_joint[i];
      pm.origin[i] = o.template head<2>();
      pm.height[i] = inPlaneOrHeight(o);
    }
    const Vector3 u = pm.K[i] * model.axis[i];
    if (model.joint_type[i] == JointType::kRevolute)
      pm.sign[i] = u.z() < Scalar(0) ? Scalar(-1) : Scalar(1);
    if (model.joint_type[i] == JointType::kPrismatic) {
      pm.slide[i] = u.template head<2>();
      // A forced model may slide partly along n: keep the in-plane unit direction.
      if (pm.slide[i].norm() > Scalar(0)) pm.slide[i] /= pm.slide[i].norm();
    }
    const Vector3 c = pm.K[i] * model.com[i];
    pm.com[i] = c.template head<2>();
    pm.com_height[i] = inPlaneOrHeight(c);
    const Vector3 n_i = pm.K[i].row(2).transpose();
    pm.inertia_n[i] = n_i.dot(model.inertia_com[i] * n_i);
    if (pm.height[i] != Scalar(0) || pm.com_height[i] != Scalar(0)) pm.offsets = true;
  }
  for (const Frame<Scalar>& f : model.frames) {
    pm.K_frame.push_back(pm.K[f.segment] * f.R_segment_frame);
    const Vector3 o = pm.K[f.segment] * f.p_segment_frame;
    pm.frame_origin.push_back(o.template head<2>());
    pm.frame_height.push_back(inPlaneOrHeight(o));
    if (pm.frame_height.back() != Scalar(0)) pm.offsets = true;
  }
  return pm;
}

/// Planar forward pass over `segments` (increasing, closed under parents, starting with
/// 0): angles, angular rates, origin accelerations minus gravity, in world-plane
/// coordinates. q, qd, qdd as for forwardKinematics (size model.nq, checked by the
/// caller); gravity_root [m/s^2] in the root frame (its n component is dropped). Clears
/// the applied wrenches.
template <typename Scalar>
void planarKinematics(const Model<Scalar>& model, const PlanarModel<Scalar>& pm,
                      PlanarData<Scalar>& pd, const VectorX<Scalar>& q, const VectorX<Scalar>& qd,
                      const VectorX<Scalar>& qdd, const Eigen::Matrix<Scalar, 3, 1>& gravity_root,
                      const std::vector<int>& segments) {
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  using std::cos;
  using std::sin;
  pd.phi[0] = Scalar(0);
  pd.cos_phi[0] = Scalar(1);
  pd.sin_phi[0] = Scalar(0);
  pd.omega[0] = pd.alpha[0] = Scalar(0);
  pd.acc[0] = -(pm.E.template leftCols<2>().transpose() * gravity_root);
  pd.force[0].setZero();
  pd.moment[0] = Scalar(0);
  pd.first_moment[0].setZero();
  for (std::size_t j = 1; j < segments.size(); ++j) {
    const int i = segments[j];
    const int p = model.parent[i];
    const int k = model.coordinate[i];
    Scalar qi(0), qdi(0), qddi(0);
    if (k >= 0) {
      qi = model.multiplier[i] * q[k] + model.offset[i];
      qdi = model.multiplier[i] * qd[k];
      qddi = model.multiplier[i] * qdd[k];
    }
    const Scalar c = pd.cos_phi[p], s = pd.sin_phi[p];
    const Scalar w_p = pd.omega[p], al_p = pd.alpha[p];
    // Parent origin -> this origin, world plane.
    Vector2 o = pm.origin[i];
    Vector2& r = pd.r[i];
    r = Vector2(c * o.x() - s * o.y(), s * o.x() + c * o.y());
    // a = a_p + alpha_p n x r - omega_p^2 r (the origin as a point of the parent).
    Vector2& a = pd.acc[i];
    Scalar w = w_p, al = al_p;
    if (model.joint_type[i] == JointType::kRevolute) {
      pd.phi[i] = pd.phi[p] + pm.sign[i] * qi;
      pd.cos_phi[i] = cos(pd.phi[i]);
      pd.sin_phi[i] = sin(pd.phi[i]);
      w += pm.sign[i] * qdi;
      al += pm.sign[i] * qddi;
      a = pd.acc[p] + Vector2(-al_p * r.y(), al_p * r.x()) - (w_p * w_p) * r;
    } else {
      pd.phi[i] = pd.phi[p];
      pd.cos_phi[i] = c;
      pd.sin_phi[i] = s;
      if (model.joint_type[i] == JointType::kPrismatic) {
        const Vector2 d(c * pm.slide[i].x() - s * pm.slide[i].y(),
                        s * pm.slide[i].x() + c * pm.slide[i].y());
        r += qi * d;
        a = pd.acc[p] + Vector2(-al_p * r.y(), al_p * r.x()) - (w_p * w_p) * r;
        // Slide acceleration and Coriolis 2 omega n x (d qd).
        a += qddi * d + (Scalar(2) * w_p * qdi) * Vector2(-d.y(), d.x());
      } else {
        a = pd.acc[p] + Vector2(-al_p * r.y(), al_p * r.x()) - (w_p * w_p) * r;
      }
    }
    pd.omega[i] = w;
    pd.alpha[i] = al;
    pd.force[i].setZero();
    pd.moment[i] = Scalar(0);
    pd.first_moment[i].setZero();
  }
}

/// Whether a wrench applied at the origin of model frame `frame`, given in that link's
/// frame, lies in the plane: force perpendicular to n and moment along n, to the
/// tolerance relative to its own magnitude. A wrench that does not must take the 6x6 path.
template <typename Scalar>
bool planarWrenchInPlane(const PlanarModel<Scalar>& pm, int frame,
                         const Eigen::Matrix<Scalar, 3, 1>& force,
                         const Eigen::Matrix<Scalar, 3, 1>& moment) {
  const Eigen::Matrix<Scalar, 3, 3>& K = pm.K_frame[frame];
  const Scalar tol = planarTolerance<Scalar>();
  const Scalar f_n = K.row(2).dot(force);
  const Eigen::Matrix<Scalar, 2, 1> m_plane = K.template topRows<2>() * moment;
  return std::abs(f_n) <= tol * force.norm() && m_plane.norm() <= tol * moment.norm();
}

/// Adds a wrench applied TO the robot at the origin of model frame `frame`, given in
/// that link's frame (as addExternalWrench with WrenchFrame::kLocal), after
/// planarKinematics. Only its in-plane part enters (check planarWrenchInPlane first
/// where the rest matters).
template <typename Scalar>
void planarAddExternalWrench(const Model<Scalar>& model, const PlanarModel<Scalar>& pm,
                             PlanarData<Scalar>& pd, int frame,
                             const Eigen::Matrix<Scalar, 3, 1>& force,
                             const Eigen::Matrix<Scalar, 3, 1>& moment) {
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  const Eigen::Matrix<Scalar, 3, 3>& K = pm.K_frame[frame];
  const Vector2 f = K.template topRows<2>() * force;  // plane frame of the segment
  const Scalar m_n = K.row(2).dot(moment);
  const int s = model.frames[frame].segment;
  const Scalar c = pd.cos_phi[s], sn = pd.sin_phi[s];
  const Vector2 f_w(c * f.x() - sn * f.y(), sn * f.x() + c * f.y());
  const Vector2& o = pm.frame_origin[frame];
  const Vector2 o_w(c * o.x() - sn * o.y(), sn * o.x() + c * o.y());
  // Stored negated: the backward pass starts from minus the applied loads.
  pd.force[s] -= f_w;
  pd.moment[s] -= m_n + (o_w.x() * f_w.y() - o_w.y() * f_w.x());
  if (pm.offsets) pd.first_moment[s] -= pm.frame_height[frame] * f_w;
}

/// Planar backward pass (the 3x3 solve) over `segments` (increasing, closed under
/// children), then the 6-D joint wrenches into data.force, data.moment (child frame,
/// moment about the joint origin) and data.effort, exactly as inverseDynamics would.
template <typename Scalar>
void planarInverseDynamics(const Model<Scalar>& model, const PlanarModel<Scalar>& pm,
                           PlanarData<Scalar>& pd, Data<Scalar>& data,
                           const std::vector<int>& segments) {
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  for (auto it = segments.rbegin(); it != segments.rend(); ++it) {
    const int i = *it;
    Vector2& f = pd.force[i];
    Scalar& m = pd.moment[i];
    const Scalar c = pd.cos_phi[i], s = pd.sin_phi[i];
    if (model.has_inertia[i]) {
      // F = m a_G - F_0;  M = J_nn alpha - (xi x F)_n - M_0, about the joint origin.
      const Vector2& cc = pm.com[i];
      const Vector2 c_w(c * cc.x() - s * cc.y(), s * cc.x() + c * cc.y());
      const Scalar w = pd.omega[i], al = pd.alpha[i];
      const Vector2 m_a =
          model.mass[i] * (pd.acc[i] + Vector2(-al * c_w.y(), al * c_w.x()) - (w * w) * c_w);
      f += m_a;
      m += pm.inertia_n[i] * al + (c_w.x() * m_a.y() - c_w.y() * m_a.x());
      if (pm.offsets) pd.first_moment[i] += pm.com_height[i] * m_a;
    }
    // Back to the segment frame: plane frame = Rz(-phi) world plane, then K^T.
    const Eigen::Matrix<Scalar, 3, 3>& K = pm.K[i];
    const Scalar fx = c * f.x() + s * f.y(), fy = -s * f.x() + c * f.y();
    data.force[i] = fx * K.row(0).transpose() + fy * K.row(1).transpose();
    data.moment[i] = m * K.row(2).transpose();
    if (pm.offsets) {
      const Vector2& S = pd.first_moment[i];
      const Scalar sx = c * S.x() + s * S.y(), sy = -s * S.x() + c * S.y();
      data.moment[i] += -sy * K.row(0).transpose() + sx * K.row(1).transpose();  // n x S
    }
    switch (model.joint_type[i]) {
      case JointType::kRevolute: data.effort[i] = pm.sign[i] * m; break;
      case JointType::kPrismatic:
        data.effort[i] = pm.slide[i].x() * fx + pm.slide[i].y() * fy;
        break;
      default: data.effort[i] = Scalar(0); break;
    }
    const int p = model.parent[i];
    if (p < 0) continue;
    const Vector2& r = pd.r[i];
    pd.force[p] += f;
    pd.moment[p] += m + (r.x() * f.y() - r.y() * f.x());
    if (pm.offsets) pd.first_moment[p] += pd.first_moment[i] + pm.height[i] * f;
  }
}

}  // namespace jle
