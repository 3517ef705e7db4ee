// The immutable multibody model: a tree of rigid segments joined by 1-DOF joints.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace jle {

/// Kind of the joint that enters a segment from its parent.
enum class JointType : std::uint8_t {
  kRoot,       ///< segment 0 of a fixed-base model: its pose is given (identity by default)
  kFloating,   ///< segment 0 of a floating-base model: pose, twist, acceleration given
  kFixed,      ///< a fixed joint kept as its own segment (so that its wrench is an output)
  kRevolute,   ///< revolute or continuous: rotation q [rad] about the axis
  kPrismatic,  ///< translation q [m] along the axis
};

/// Whether the joint entering a segment has a coordinate.
inline bool isMoving(JointType type) {
  return type == JointType::kRevolute || type == JointType::kPrismatic;
}

/// A named frame rigidly attached to a segment: every URDF link is one (a link lumped
/// into its parent through fixed joints is a frame of that parent's segment).
template <typename Scalar>
struct Frame {
  std::string name;
  int segment = 0;
  Eigen::Matrix<Scalar, 3, 3> R_segment_frame = Eigen::Matrix<Scalar, 3, 3>::Identity();
  Eigen::Matrix<Scalar, 3, 1> p_segment_frame = Eigen::Matrix<Scalar, 3, 1>::Zero();
};

/// The model, built once (see urdf_reader.hpp) and never changed by the algorithms.
///
/// Segments are numbered depth first from the root in the order the URDF lists its
/// joints, so parent[i] < i for every i > 0 and parent[0] == -1: the forward pass is a
/// loop up the indices, the backward pass a loop down. A segment's frame is the frame
/// of its URDF child link, whose origin is the joint origin.
template <typename Scalar>
struct Model {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

  int nq = 0;  ///< number of independent coordinates (moving joints that are not mimics)
  bool floating_base = false;

  // Per segment, size nsegments().
  std::vector<int> parent;
  std::vector<JointType> joint_type;
  std::vector<std::string> link_name;   ///< URDF link whose frame is the segment frame
  std::vector<std::string> joint_name;  ///< URDF joint entering the segment ("" for the root)
  /// URDF parent link of that joint ("" for the root): the frame WrenchFrame::kParent names.
  std::vector<std::string> parent_link_name;
  std::vector<Matrix3> R_parent_joint;  ///< joint frame at q = 0 in the parent segment frame
  std::vector<Vector3> p_parent_joint;  ///< joint origin in the parent segment frame [m]
  /// Orientation of the joint's URDF parent link in the parent segment frame (identity
  /// unless the parent link was lumped): turns a child-frame wrench into the parent-link frame.
  std::vector<Matrix3> R_parentsegment_parentlink;
  std::vector<Vector3> axis;  ///< unit joint axis in the segment frame (zero if not moving)
  /// q_segment = multiplier * q[coordinate] + offset (a mimic joint follows its leader's
  /// coordinate); coordinate == -1 when the joint does not move.
  std::vector<int> coordinate;
  std::vector<Scalar> multiplier;
  std::vector<Scalar> offset;
  /// The URDF joint's <dynamics damping friction> (0 where absent or not moving): viscous
  /// damping [N m s/rad or N s/m] and Coulomb friction [N m or N], for the optional
  /// friction term of the motor effort (friction.hpp).
  std::vector<Scalar> damping;
  std::vector<Scalar> friction;
  /// The URDF joint's <limit>: position bounds [rad or m] of a revolute or prismatic
  /// joint (-inf, inf where absent: a continuous joint, no <limit>), velocity [rad/s or
  /// m/s] and effort [N m or N] limits (inf where absent or not positive). What a joint
  /// can do: the inputs' plausibility (Pipeline) and the loads' are checked against them.
  std::vector<double> lower_limit, upper_limit, velocity_limit, effort_limit;
  std::vector<Scalar> mass;          ///< lumped mass [kg]
  std::vector<Vector3> com;          ///< lumped centre of mass in the segment frame [m]
  std::vector<Matrix3> inertia_com;  ///< lumped inertia about the com, segment axes [kg m^2]

  /// Derived by analyze() (which the URDF reader calls): what the backward pass may
  /// skip for each segment without changing its result.
  /// has_inertia[i] == 0: zero mass and inertia, no inertial term to compute.
  std::vector<char> has_inertia;
  /// gyroscopic[i] == 0: omega x J_G omega is identically zero for this segment, because
  /// its angular velocity always lies along a principal axis of J_G (or is zero).
  std::vector<char> gyroscopic;
  /// axis_index[i] == k (0, 1, 2): the joint axis is exactly +-e_k of the segment frame
  /// (axis[i][k] is the sign), so the joint's rotation mixes two columns only; -1 for
  /// any other axis and for a joint that does not move.
  std::vector<signed char> axis_index;
  /// has_children[i]: some segment has i as its parent. opens_parent[i]: i is the
  /// highest-numbered child of its parent, the first of them the backward pass solves,
  /// so it starts the parent's sums (no separate pass clears them).
  std::vector<char> has_children;
  std::vector<char> opens_parent;

  /// Names of the independent coordinates, index = position in q, size nq.
  std::vector<std::string> coordinate_names;
  /// Segments whose joint moves (revolute, continuous, prismatic, mimics included), in
  /// URDF tree order: the joints whose loads are reported.
  std::vector<int> moving_segments;
  /// Every URDF link, as a frame on the segment it was lumped into.
  std::vector<Frame<Scalar>> frames;
  /// What the reader accepted but a user should know (e.g. a slightly unphysical inertia).
  std::vector<std::string> warnings;

  int nsegments() const { return static_cast<int>(parent.size()); }

  /// Index into frames of the URDF link `name`; throws std::invalid_argument if unknown.
  int frameIndex(const std::string& name) const {
    for (int i = 0; i < static_cast<int>(frames.size()); ++i)
      if (frames[i].name == name) return i;
    throw std::invalid_argument("unknown link '" + name + "'");
  }
  /// Index of the segment entered by joint `name`; throws std::invalid_argument if unknown
  /// or if the joint was lumped away (keep it with ModelOptions::keep_fixed_joints).
  int segmentOfJoint(const std::string& name) const {
    for (int i = 1; i < nsegments(); ++i)
      if (joint_name[i] == name) return i;
    throw std::invalid_argument("no segment for joint '" + name +
                                "' (unknown, or a fixed joint that was lumped)");
  }
  /// Total mass [kg].
  Scalar totalMass() const {
    Scalar total(0);
    for (Scalar m : mass) total += m;
    return total;
  }

  /// Fills has_inertia, gyroscopic, axis_index, has_children and opens_parent from the
  /// rest of the model. The direction of a
  /// segment's angular velocity is constant in its frame when the base is fixed and
  /// every joint above it turns about one and the same axis (a planar chain): then the
  /// gyroscopic term vanishes wherever that axis is a principal axis of inertia.
  void analyze() {
    const int n = nsegments();
    has_inertia.assign(static_cast<std::size_t>(n), 1);
    gyroscopic.assign(static_cast<std::size_t>(n), 1);
    // Direction of omega in each segment frame: 0 = always zero, 1 = along dir[i],
    // 2 = varies.
    std::vector<int> kind(static_cast<std::size_t>(n), 2);
    std::vector<Vector3> dir(static_cast<std::size_t>(n), Vector3::Zero());
    const Scalar eps = Scalar(64) * Eigen::NumTraits<Scalar>::epsilon();
    analyzeTopology();
    for (int i = 0; i < n; ++i) {
      has_inertia[i] = mass[i] != Scalar(0) || !inertia_com[i].isZero(Scalar(0));
      if (i == 0) {
        kind[0] = floating_base ? 2 : 0;
      } else {
        const int p = parent[i];
        const bool revolute = joint_type[i] == JointType::kRevolute;
        if (kind[p] == 0) {
          kind[i] = revolute ? 1 : 0;
          dir[i] = axis[i];
        } else if (kind[p] == 1) {
          const Vector3 v = R_parent_joint[i].transpose() * dir[p];  // joint frame
          if (!revolute) {
            kind[i] = 1;
            dir[i] = v;
          } else if (v.cross(axis[i]).norm() <= eps) {
            kind[i] = 1;
            dir[i] = axis[i];
          }
        }
      }
      if (kind[i] == 0) gyroscopic[i] = 0;
      if (kind[i] == 1) {
        const Vector3 Jd = inertia_com[i] * dir[i];
        gyroscopic[i] = Jd.cross(dir[i]).norm() > eps * Jd.norm();  // relative: any scale
      }
    }
  }

  /// axis_index, has_children and opens_parent (part of analyze()).
  void analyzeTopology() {
    const int n = nsegments();
    axis_index.assign(static_cast<std::size_t>(n), -1);
    has_children.assign(static_cast<std::size_t>(n), 0);
    opens_parent.assign(static_cast<std::size_t>(n), 0);
    for (int i = n - 1; i > 0; --i) {
      if (!has_children[parent[i]]) opens_parent[i] = 1;
      has_children[parent[i]] = 1;
    }
    for (int i = 0; i < n; ++i) {
      if (!isMoving(joint_type[i])) continue;
      for (int k = 0; k < 3; ++k) {
        const Scalar a = axis[i][(k + 1) % 3], b = axis[i][(k + 2) % 3];
        if (a == Scalar(0) && b == Scalar(0) && std::abs(axis[i][k]) == Scalar(1))
          axis_index[i] = static_cast<signed char>(k);
      }
    }
  }

  /// The same model in another scalar type.
  template <typename Other>
  Model<Other> cast() const {
    Model<Other> out;
    out.nq = nq;
    out.floating_base = floating_base;
    out.parent = parent;
    out.joint_type = joint_type;
    out.link_name = link_name;
    out.joint_name = joint_name;
    out.parent_link_name = parent_link_name;
    out.coordinate = coordinate;
    out.coordinate_names = coordinate_names;
    out.moving_segments = moving_segments;
    out.warnings = warnings;
    out.has_inertia = has_inertia;
    out.gyroscopic = gyroscopic;
    out.axis_index = axis_index;
    out.has_children = has_children;
    out.opens_parent = opens_parent;
    for (int i = 0; i < nsegments(); ++i) {
      out.R_parent_joint.push_back(R_parent_joint[i].template cast<Other>());
      out.p_parent_joint.push_back(p_parent_joint[i].template cast<Other>());
      out.R_parentsegment_parentlink.push_back(
          R_parentsegment_parentlink[i].template cast<Other>());
      out.axis.push_back(axis[i].template cast<Other>());
      out.multiplier.push_back(static_cast<Other>(multiplier[i]));
      out.offset.push_back(static_cast<Other>(offset[i]));
      out.damping.push_back(static_cast<Other>(damping[i]));
      out.friction.push_back(static_cast<Other>(friction[i]));
      out.lower_limit.push_back(lower_limit[i]);
      out.upper_limit.push_back(upper_limit[i]);
      out.velocity_limit.push_back(velocity_limit[i]);
      out.effort_limit.push_back(effort_limit[i]);
      out.mass.push_back(static_cast<Other>(mass[i]));
      out.com.push_back(com[i].template cast<Other>());
      out.inertia_com.push_back(inertia_com[i].template cast<Other>());
    }
    for (const Frame<Scalar>& f : frames) {
      Frame<Other> g;
      g.name = f.name;
      g.segment = f.segment;
      g.R_segment_frame = f.R_segment_frame.template cast<Other>();
      g.p_segment_frame = f.p_segment_frame.template cast<Other>();
      out.frames.push_back(g);
    }
    return out;
  }
};

}  // namespace jle
