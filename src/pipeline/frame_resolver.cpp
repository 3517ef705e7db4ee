#include <joint_load_estimator/model/frames.hpp>
#include <joint_load_estimator/pipeline/frame_resolver.hpp>

#include <string>

namespace jle {

FrameResolver::FrameResolver(const Model<double>& model, const Settings& settings,
                             FrameSource* frames)
    : model_(model),
      settings_(settings),
      frames_(frames),
      wrenches_(settings.estimator.wrenches.size()),
      plates_(settings.estimator.plates.size()) {}

bool FrameResolver::resolveWrench(int k, const std::string& frame, Stamp stamp,
                                  std::string& problem) {
  WrenchFrame& input = wrenches_.at(ix(k));
  if (input.rigid && frame == input.frame) return true;
  const std::string& link = settings_.estimator.wrenches[ix(k)].link;
  input.frame = frame;
  Eigen::Matrix3d R;
  Eigen::Vector3d p;
  input.rigid = rigidFrameInLink(model_, link, frame, R, p);
  if (input.rigid) {
    input.X_link_frame.linear() = R;
    input.X_link_frame.translation() = p;
    return true;
  }
  std::string error = "no frame source (tf2)";
  if (frames_ && frames_->lookup(link, frame, stamp, input.X_link_frame, error)) return true;
  problem = "wrench '" + settings_.wrenches[ix(k)].topic + "': frame '" + frame +
            "' is neither a URDF link rigid to '" + link + "' nor known to tf2: " + error;
  return false;
}

FrameResolver::PlatePose FrameResolver::resolvePlate(int k, const std::string& frame,
                                                     Eigen::Isometry3d& X_world_plate,
                                                     std::string& problem) {
  PlateFrame& plate = plates_.at(ix(k));
  if (plate.pose_known && frame == plate.frame) return PlatePose::kKnown;
  if (settings_.force_plates[ix(k)].pose_configured) {  // the estimator holds it already
    plate.frame = frame;
    plate.pose_known = true;
    return PlatePose::kKnown;
  }
  // A lab plate is fixed in the world: looked up until found, then kept.
  const std::string& world = model_.floating_base ? settings_.world_frame : model_.link_name[0];
  std::string error = "no frame source (tf2)";
  if (!frames_ || !frames_->lookup(world, frame, 0, X_world_plate, error)) {
    problem = "force plate '" + settings_.estimator.plates[ix(k)].plate.name +
              "': no pose of frame '" + frame + "' in '" + world +
              "' from tf2 (and no position/orientation configured): " + error;
    return PlatePose::kUnknown;
  }
  plate.frame = frame;
  plate.pose_known = true;
  return PlatePose::kFound;
}

bool FrameResolver::basePose(Stamp stamp, Eigen::Isometry3d& X_world_base,
                             std::string& problem) const {
  std::string error = "no frame source (tf2)";
  if (frames_ &&
      frames_->lookup(settings_.world_frame, settings_.base_frame, stamp, X_world_base, error))
    return true;
  problem = "floating base: no pose of '" + settings_.base_frame + "' in '" +
            settings_.world_frame + "' at " + secondsText(stamp) + ": " + error;
  return false;
}

}  // namespace jle
