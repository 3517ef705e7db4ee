// How messages become estimator inputs, shared by the node and process_bag so that a
// bag processed offline gives what the node gives online: the model the settings ask
// for, the joints that are published, joint states (partial messages allowed) mapped
// onto the coordinates, and wrenches expressed in a URDF frame rigid to their link.
// ROS-message-free (plain vectors and Eigen), so that it is cheap to test.
#pragma once

#include <joint_load_estimator/model.hpp>
#include <joint_load_estimator/ros/settings.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace jle {

/// The ModelOptions that `settings` ask for: floating_base, and keep_fixed_joints with
/// the joint of every sensor input (estimator.wrenches[k].sensor_joint) added.
ModelOptions modelOptions(const Settings& settings);

/// Fills in the link of every force/torque sensor input (sensor_joint set, link empty)
/// in settings.estimator.wrenches with its joint's child link. Joints the model does not
/// keep are left for the Estimator to refuse by name.
void completeSensorLinks(const Model<double>& model, Settings& settings);

/// Segments whose loads are published: `joints` (URDF names of moving joints, or of
/// fixed joints kept as segments), or every moving segment when it is empty. Throws
/// SettingsError "parameter 'joints': 'NAME' is not a joint of the model".
std::vector<int> publishedSegments(const Model<double>& model,
                                   const std::vector<std::string>& joints);

/// Pose of URDF link `frame` in the frame of URDF link `link` when both lie on one
/// segment (rigidly attached: a constant transform from the model). False when `frame`
/// is not a URDF link or moves relative to `link` (then only tf2 knows it). Throws
/// std::invalid_argument if `link` is not a URDF link.
bool rigidFrameInLink(const Model<double>& model, const std::string& link, const std::string& frame,
                      Eigen::Matrix3d& R_link_frame, Eigen::Vector3d& p_link_frame);

/// A wrench (force [N], moment [N m] about the origin of frame F, both in F) expressed
/// in link L's frame with its moment about L's origin, F's pose in L being
/// (R_link_frame, p_link_frame).
inline void wrenchInLink(const Eigen::Matrix3d& R_link_frame, const Eigen::Vector3d& p_link_frame,
                         const Eigen::Vector3d& f_frame, const Eigen::Vector3d& m_frame,
                         Eigen::Vector3d& f_link, Eigen::Vector3d& m_link) {
  f_link = R_link_frame * f_frame;
  m_link = R_link_frame * m_frame + p_link_frame.cross(f_link);
}

/// The latest position of every coordinate and the latest measured effort of every
/// published joint, from joint-state messages that may each carry a subset of the
/// joints. The name-to-index mapping is cached for the last layout of names seen, so a
/// stream of messages with one layout costs string comparisons and no allocation.
class JointStateMap {
 public:
  /// `published_segments` as publishedSegments() returns them.
  JointStateMap(const Model<double>& model, const std::vector<int>& published_segments);

  /// Takes a message's names and positions (same size, checked by the caller) and its
  /// efforts (empty, or the same size). Mimic joints are ignored (a mimic follows its
  /// leader). Returns the index in `names` of the first joint the model does not have,
  /// or -1 if there is none (the others are still taken).
  int update(const std::vector<std::string>& names, const std::vector<double>& position,
             const std::vector<double>& effort);

  /// The positions, model.coordinate_names order (size nq).
  const std::vector<double>& q() const { return q_; }
  /// Index of the first coordinate with no position received yet, or -1 if none.
  int firstMissing() const;
  /// Latest measured effort per published joint (NaN until one is received).
  const std::vector<double>& effort() const { return effort_; }

 private:
  void bind(const std::vector<std::string>& names);

  std::vector<std::string> coordinate_names_;
  std::vector<std::string> moving_joint_names_;  // every moving joint, mimics included
  std::vector<std::string> published_joint_names_;
  std::vector<double> q_;
  std::vector<char> received_;
  std::vector<double> effort_;
  // Cached binding of the last layout of names: per message index, the coordinate
  // (-1: none: a mimic or unknown), the published joint (-1: none) and whether known.
  std::vector<std::string> layout_;
  std::vector<int> coordinate_of_, published_of_;
  std::vector<char> known_;
};

}  // namespace jle
