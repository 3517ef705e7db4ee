#include <joint_load_estimator/ros/message_inputs.hpp>

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace jle {

ModelOptions modelOptions(const Settings& settings) {
  ModelOptions options;
  options.floating_base = settings.floating_base;
  options.keep_fixed_joints = settings.keep_fixed_joints;
  // A sensor's joint is kept as its own segment: its wrench is what the sensor measures.
  for (const WrenchInputConfig& w : settings.estimator.wrenches) {
    const std::vector<std::string>& kept = options.keep_fixed_joints;
    if (!w.sensor_joint.empty() && std::find(kept.begin(), kept.end(), w.sensor_joint) == kept.end())
      options.keep_fixed_joints.push_back(w.sensor_joint);
  }
  return options;
}

void completeSensorLinks(const Model<double>& model, Settings& settings) {
  for (WrenchInputConfig& input : settings.estimator.wrenches) {
    if (input.sensor_joint.empty() || !input.link.empty()) continue;
    for (int s = 1; s < model.nsegments(); ++s)
      if (model.joint_name[static_cast<std::size_t>(s)] == input.sensor_joint)
        input.link = model.link_name[static_cast<std::size_t>(s)];
  }
}

std::vector<int> publishedSegments(const Model<double>& model,
                                   const std::vector<std::string>& joints) {
  if (joints.empty()) return model.moving_segments;
  std::vector<int> segments;
  for (const std::string& j : joints) {
    int segment = -1;
    for (int s = 1; s < model.nsegments(); ++s)
      if (model.joint_name[static_cast<std::size_t>(s)] == j &&
          (isMoving(model.joint_type[static_cast<std::size_t>(s)]) ||
           model.joint_type[static_cast<std::size_t>(s)] == JointType::kFixed))
        segment = s;
    if (segment < 0)
      throw SettingsError("parameter 'joints': '" + j + "' is not a joint of the model");
    segments.push_back(segment);
  }
  return segments;
}

bool rigidFrameInLink(const Model<double>& model, const std::string& link, const std::string& frame,
                      Eigen::Matrix3d& R_link_frame, Eigen::Vector3d& p_link_frame) {
  const Frame<double>& l = model.frames[static_cast<std::size_t>(model.frameIndex(link))];
  for (const Frame<double>& f : model.frames) {
    if (f.name != frame) continue;
    if (f.segment != l.segment) return false;
    R_link_frame = l.R_segment_frame.transpose() * f.R_segment_frame;
    p_link_frame = l.R_segment_frame.transpose() * (f.p_segment_frame - l.p_segment_frame);
    return true;
  }
  return false;
}

JointStateMap::JointStateMap(const Model<double>& model, const std::vector<int>& published_segments)
    : coordinate_names_(model.coordinate_names),
      q_(static_cast<std::size_t>(model.nq), 0.0),
      received_(static_cast<std::size_t>(model.nq), 0),
      effort_(published_segments.size(), std::numeric_limits<double>::quiet_NaN()) {
  for (int s : model.moving_segments)
    moving_joint_names_.push_back(model.joint_name[static_cast<std::size_t>(s)]);
  for (int s : published_segments)
    published_joint_names_.push_back(model.joint_name[static_cast<std::size_t>(s)]);
}

void JointStateMap::bind(const std::vector<std::string>& names) {
  layout_ = names;
  const std::size_t n = names.size();
  coordinate_of_.assign(n, -1);
  published_of_.assign(n, -1);
  known_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < coordinate_names_.size(); ++k)
      if (coordinate_names_[k] == names[i]) coordinate_of_[i] = static_cast<int>(k);
    for (std::size_t j = 0; j < published_joint_names_.size(); ++j)
      if (published_joint_names_[j] == names[i]) published_of_[i] = static_cast<int>(j);
    for (const std::string& m : moving_joint_names_)
      if (m == names[i]) known_[i] = 1;
    if (coordinate_of_[i] >= 0 || published_of_[i] >= 0) known_[i] = 1;
  }
}

int JointStateMap::update(const std::vector<std::string>& names,
                          const std::vector<double>& position, const std::vector<double>& effort) {
  if (names != layout_) bind(names);
  int unknown = -1;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!known_[i]) {
      if (unknown < 0) unknown = static_cast<int>(i);
      continue;
    }
    const int k = coordinate_of_[i];
    if (k >= 0) {
      q_[static_cast<std::size_t>(k)] = position[i];
      received_[static_cast<std::size_t>(k)] = 1;
    }
    const int j = published_of_[i];
    if (j >= 0 && !effort.empty()) effort_[static_cast<std::size_t>(j)] = effort[i];
  }
  return unknown;
}

int JointStateMap::firstMissing() const {
  for (std::size_t k = 0; k < received_.size(); ++k)
    if (!received_[k]) return static_cast<int>(k);
  return -1;
}

}  // namespace jle
