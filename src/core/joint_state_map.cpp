#include <joint_load_estimator/joint_state_map.hpp>

#include <cmath>
#include <limits>

namespace jle {

JointStateMap::JointStateMap(const Model<double>& model, const std::vector<int>& published_segments)
    : coordinate_names_(model.coordinate_names),
      q_(static_cast<std::size_t>(model.nq), 0.0),
      qd_(static_cast<std::size_t>(model.nq), std::numeric_limits<double>::quiet_NaN()),
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
  duplicate_ = -1;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < i && duplicate_ < 0; ++j)
      if (names[j] == names[i]) duplicate_ = static_cast<int>(i);
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
                          const std::vector<double>& position, const std::vector<double>& velocity,
                          const std::vector<double>& effort) {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
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
      qd_[static_cast<std::size_t>(k)] =
          !velocity.empty() && std::isfinite(velocity[i]) ? velocity[i] : kNone;
      received_[static_cast<std::size_t>(k)] = 1;
    }
    const int j = published_of_[i];
    if (j >= 0 && !effort.empty())
      effort_[static_cast<std::size_t>(j)] = std::isfinite(effort[i]) ? effort[i] : kNone;
  }
  return unknown;
}

int JointStateMap::duplicate(const std::vector<std::string>& names) {
  if (names != layout_) bind(names);
  return duplicate_;
}

int JointStateMap::firstMissing() const {
  for (std::size_t k = 0; k < received_.size(); ++k)
    if (!received_[k]) return static_cast<int>(k);
  return -1;
}

}  // namespace jle
