// Where the inputs are: a wrench reading's frame in its link, a force plate's pose in the
// world, the floating base's pose in the world. From the URDF where a frame rides on the
// link's segment (a constant transform, computed once), otherwise from a FrameSource (tf2
// in the ROS layer). One part of the message path (pipeline.hpp): the Pipeline asks it
// for every wrench and plate message and for every joint sample of a floating base.
// ROS-free.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/pipeline/timeline.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace jle {

/// Frames the URDF does not hold rigidly (tf2 in the ROS layer: the node's listener, or
/// process_bag's buffer filled from a bag's /tf and /tf_static).
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// Pose of `frame` in `target` at `stamp` (0: the latest known). False with `error`
  /// set when it is not known at that stamp.
  virtual bool lookup(const std::string& target, const std::string& frame, Stamp stamp,
                      Eigen::Isometry3d& X_target_frame, std::string& error) = 0;
};

class FrameResolver {
 public:
  /// `model` and `settings` (its wrench inputs and force plates, world_frame, base_frame)
  /// must outlive the resolver; `frames` may be null (only the URDF's frames are known).
  FrameResolver(const Model<double>& model, const Settings& settings, FrameSource* frames);

  /// Wrench input k's reading in `frame` at `stamp`: its pose in the input's link, then
  /// wrenchPose(k). A URDF frame rigid to the link is computed once and kept while the
  /// frame stays; any other is looked up at every message. False with `problem` naming
  /// the input, the frame and the link.
  bool resolveWrench(int k, const std::string& frame, Stamp stamp, std::string& problem);
  /// The last resolved pose of wrench input k's frame in its link, and that frame (empty
  /// before the first).
  const Eigen::Isometry3d& wrenchPose(int k) const { return wrenches_[ix(k)].X_link_frame; }
  const std::string& wrenchFrame(int k) const { return wrenches_[ix(k)].frame; }

  /// What became of force plate k's pose for a message in `frame`.
  enum class PlatePose : std::uint8_t {
    kKnown,    ///< configured, or found before for this frame: nothing to do
    kFound,    ///< looked up now: X_world_plate is the plate's pose (a lab plate is fixed)
    kUnknown,  ///< not known: `problem` names the plate and the frame
  };
  /// The world is world_frame for a floating base, the URDF's root link for a fixed one.
  PlatePose resolvePlate(int k, const std::string& frame, Eigen::Isometry3d& X_world_plate,
                         std::string& problem);
  /// Force plate k's frame (empty before the first message).
  const std::string& plateFrame(int k) const { return plates_[ix(k)].frame; }

  /// The floating base's pose (base_frame in world_frame) at `stamp`; false with
  /// `problem` set.
  bool basePose(Stamp stamp, Eigen::Isometry3d& X_world_base, std::string& problem) const;

 private:
  struct WrenchFrame {
    std::string frame;   // last resolved frame
    bool rigid = false;  // `frame` is a URDF frame rigid to the link: pose kept
    Eigen::Isometry3d X_link_frame = Eigen::Isometry3d::Identity();
  };
  struct PlateFrame {
    std::string frame;
    bool pose_known = false;
  };
  static std::size_t ix(int k) { return static_cast<std::size_t>(k); }

  const Model<double>& model_;
  const Settings& settings_;
  FrameSource* frames_;
  std::vector<WrenchFrame> wrenches_;
  std::vector<PlateFrame> plates_;
};

}  // namespace jle
