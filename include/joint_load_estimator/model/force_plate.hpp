// Force plates: what a plate measures, its centre of pressure, and the reaction it
// applies to the foot standing on it (as the estimator and joint_loads apply it). ROS-free.
//
// Conventions (docs/biomechanics.md, "Force plates"):
// - The plate frame's z axis is the outward normal of the contact surface (pointing
//   out of the plate, towards the foot). A plate whose own z axis points down (AMTI,
//   Bertec) is given a plate frame rotated by pi about x in tf2 or in the config.
// - A plate reports the wrench the foot applies TO the plate, expressed in the plate
//   frame, moment about the plate origin (which may lie below the surface:
//   surface_height is the surface's z in the plate frame).
// - The foot receives the opposite wrench (the ground reaction).
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

#include <cmath>
#include <string>

namespace jle {

struct ForcePlateConfig {
  std::string name;  ///< for messages and topics
  std::string link;  ///< URDF link of the foot that stands on the plate (the reaction acts on it)
  /// Pose of the plate frame in the world (a lab-fixed plate).
  Eigen::Matrix3d R_world_plate = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_world_plate = Eigen::Vector3d::Zero();  ///< [m]
  double surface_height = 0.0;  ///< [m] z of the contact surface in the plate frame
  /// [N] below this force pressing into the plate the centre of pressure is not
  /// decoded (a division by a small force: sensor noise would throw it anywhere) and the
  /// reading is not a contact; the reaction still acts on the foot, as the exact wrench
  /// the plate measured (force, and moment about the plate origin carried to the foot),
  /// so heel strike and toe-off have no step (docs/biomechanics.md, "Force plates").
  double contact_threshold = 20.0;
};

/// One plate sample, decoded.
struct PlateReading {
  /// The foot presses into the plate (normal_force > 0, finite): the reaction acts.
  bool loaded = false;
  /// Loaded with normal_force >= contact_threshold: the COP and free moment are decoded.
  bool contact = false;
  /// [N] force pressing into the plate (along -z of the plate frame); positive in contact.
  double normal_force = 0.0;
  /// [m] centre of pressure in the plate frame, on the surface (z = surface_height);
  /// zero without contact.
  Eigen::Vector3d cop_plate = Eigen::Vector3d::Zero();
  /// [N m] free moment of the foot on the plate about the normal through the COP.
  double free_moment = 0.0;
  /// The ground reaction on the foot, plate frame, moment about the plate origin
  /// [N, N m]; zero unless loaded.
  Eigen::Vector3d force_on_foot_plate = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment_on_foot_plate = Eigen::Vector3d::Zero();
};

/// Decodes a plate sample: the wrench the foot applies to the plate (plate frame,
/// moment about the plate origin). Non-finite input, or a force that does not press into
/// the plate, is not loaded; below the contact threshold it is loaded without a COP.
inline PlateReading readForcePlate(const ForcePlateConfig& plate,
                                   const Eigen::Vector3d& force_plate,
                                   const Eigen::Vector3d& moment_plate) {
  PlateReading r;
  if (!force_plate.allFinite() || !moment_plate.allFinite()) return r;
  r.normal_force = -force_plate.z();
  if (!(r.normal_force > 0.0)) return r;
  r.loaded = true;
  r.force_on_foot_plate = -force_plate;
  r.moment_on_foot_plate = -moment_plate;
  if (!(r.normal_force >= plate.contact_threshold)) return r;
  r.contact = true;
  // The point p on the surface z = h about which the foot's moment has no component
  // in the plane: moment_plate = p x F + (0, 0, free_moment).
  const double h = plate.surface_height;
  const double fz = force_plate.z();
  r.cop_plate.x() = (h * force_plate.x() - moment_plate.y()) / fz;
  r.cop_plate.y() = (moment_plate.x() + h * force_plate.y()) / fz;
  r.cop_plate.z() = h;
  r.free_moment =
      moment_plate.z() - (r.cop_plate.x() * force_plate.y() - r.cop_plate.y() * force_plate.x());
  return r;
}

/// The centre of pressure of a reading in the world [m] (the plate origin without contact).
inline Eigen::Vector3d copInWorld(const ForcePlateConfig& plate, const PlateReading& reading) {
  return plate.p_world_plate + plate.R_world_plate * reading.cop_plate;
}

/// The ground reaction of a plate reading in the world frame, moment about the world
/// point `point_world` [m] (e.g. the foot link's origin); zero unless loaded. In contact
/// the moment is carried from the COP, so no large lever arm about a far origin enters;
/// below the threshold (a force of at most contact_threshold) from the plate origin.
inline void plateReactionInWorld(const ForcePlateConfig& plate, const PlateReading& reading,
                                 const Eigen::Vector3d& point_world, Eigen::Vector3d& force_world,
                                 Eigen::Vector3d& moment_world) {
  if (!reading.loaded) {
    force_world.setZero();
    moment_world.setZero();
    return;
  }
  force_world.noalias() = plate.R_world_plate * reading.force_on_foot_plate;
  if (!reading.contact) {
    moment_world = plate.R_world_plate * reading.moment_on_foot_plate +
                   (plate.p_world_plate - point_world).cross(force_world);
    return;
  }
  const Eigen::Vector3d cop_world = copInWorld(plate, reading);
  // On the foot: the reaction force at the COP plus the opposite free moment about the normal.
  const Eigen::Vector3d free_world = plate.R_world_plate.col(2) * (-reading.free_moment);
  moment_world = (cop_world - point_world).cross(force_world) + free_world;
}

/// Applies the ground reaction of `reading` (nothing unless loaded) to the foot standing
/// on `plate`: frame `foot_frame` (an index into model.frames, the frame of plate.link),
/// as a world-frame wrench about its origin. Call after forwardKinematics and before
/// inverseDynamics. The reaction is worked in double whatever Scalar is.
template <typename Scalar>
void applyPlateReaction(const Model<Scalar>& model, Data<Scalar>& data, int foot_frame,
                        const ForcePlateConfig& plate, const PlateReading& reading) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  if (!reading.loaded) return;
  const Frame<Scalar>& foot = model.frames[static_cast<std::size_t>(foot_frame)];
  const int s = foot.segment;
  const Eigen::Vector3d foot_world =
      (data.p_world[s] + data.R_world[s] * foot.p_segment_frame).template cast<double>();
  Eigen::Vector3d force_world, moment_world;
  plateReactionInWorld(plate, reading, foot_world, force_world, moment_world);
  addExternalWrench(model, data, foot_frame, Vector3(force_world.cast<Scalar>()),
                    Vector3(moment_world.cast<Scalar>()), WrenchFrame::kWorld);
}

}  // namespace jle
