// Frames rigid to a segment: where a URDF frame sits in a link's frame when both ride on
// one segment, and a wrench carried between two such frames.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <string>

namespace jle {

/// Pose of URDF link `frame` in the frame of URDF link `link` when both lie on one
/// segment (rigidly attached: a constant transform from the model): R_link_frame turns
/// F's axes into L's, p_link_frame [m] is F's origin in L. False when `frame` is not a
/// URDF link or moves relative to `link` (then only tf2 knows it); the outputs are then
/// left unchanged. Throws std::invalid_argument if `link` is not a URDF link.
bool rigidFrameInLink(const Model<double>& model, const std::string& link, const std::string& frame,
                      Eigen::Matrix3d& R_link_frame, Eigen::Vector3d& p_link_frame);

/// A wrench (force [N], moment [N m] about the origin of frame F, both in F) expressed
/// in link L's frame with its moment about L's origin, F's pose in L being
/// (R_link_frame, p_link_frame [m]).
inline void wrenchInLink(const Eigen::Matrix3d& R_link_frame, const Eigen::Vector3d& p_link_frame,
                         const Eigen::Vector3d& f_frame, const Eigen::Vector3d& m_frame,
                         Eigen::Vector3d& f_link, Eigen::Vector3d& m_link) {
  f_link = R_link_frame * f_frame;
  m_link = R_link_frame * m_frame + p_link_frame.cross(f_link);
}

/// The inverse of wrenchInLink: a wrench (force [N], moment [N m] about L's origin, both
/// in link L's frame) expressed in frame F with its moment about F's origin, F's pose in
/// L being (R_link_frame, p_link_frame [m]).
inline void wrenchInFrame(const Eigen::Matrix3d& R_link_frame, const Eigen::Vector3d& p_link_frame,
                          const Eigen::Vector3d& f_link, const Eigen::Vector3d& m_link,
                          Eigen::Vector3d& f_frame, Eigen::Vector3d& m_frame) {
  f_frame = R_link_frame.transpose() * f_link;
  m_frame = R_link_frame.transpose() * (m_link - p_link_frame.cross(f_link));
}

}  // namespace jle
