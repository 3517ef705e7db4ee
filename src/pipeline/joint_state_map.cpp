#include <joint_load_estimator/pipeline/joint_state_map.hpp>

#include <cmath>
#include <limits>

namespace jle {

JointStateMap::JointStateMap(const Model<double>& model, const std::vector<int>& published_segments,
                             double mimic_tolerance)
    : coordinate_names_(model.coordinate_names),
      q_(static_cast<std::size_t>(model.nq), 0.0),
      qd_(static_cast<std::size_t>(model.nq), std::numeric_limits<double>::quiet_NaN()),
      received_(static_cast<std::size_t>(model.nq), 0),
      fresh_(static_cast<std::size_t>(model.nq), 0),
      effort_(published_segments.size(), std::numeric_limits<double>::quiet_NaN()) {
  mimic_tolerance_ = mimic_tolerance;
  for (int s : model.moving_segments) {
    const std::size_t u = static_cast<std::size_t>(s);
    moving_joint_names_.push_back(model.joint_name[u]);
    const int c = model.coordinate[u];
    moving_coordinate_.push_back(c);
    // A mimic: a moving joint that is not its coordinate's own (named as its leader).
    moving_is_mimic_.push_back(c >= 0 && model.coordinate_names[static_cast<std::size_t>(c)] !=
                                             model.joint_name[u]);
    moving_multiplier_.push_back(model.multiplier[u]);
    moving_offset_.push_back(model.offset[u]);
  }
  for (int s : published_segments)
    published_joint_names_.push_back(model.joint_name[static_cast<std::size_t>(s)]);
}

int JointStateMap::bind(const std::vector<std::string>& names) {
  ++binds_;
  if (bindings_[current_].used >= 0 && bindings_[current_].layout == names) {
    bindings_[current_].used = binds_;  // the common case: the last message's layout
    return bindings_[current_].duplicate;
  }
  for (std::size_t b = 0; b < bindings_.size(); ++b) {
    if (bindings_[b].used < 0 || bindings_[b].layout != names) continue;
    bindings_[b].used = binds_;
    current_ = b;
    return bindings_[b].duplicate;
  }
  current_ = 0;  // a new layout: in the slot used least recently (or never)
  for (std::size_t b = 1; b < bindings_.size(); ++b)
    if (bindings_[b].used < bindings_[current_].used) current_ = b;
  Binding& m = bindings_[current_];
  m.used = binds_;
  m.layout = names;
  const std::size_t n = names.size();
  m.coordinate_of.assign(n, -1);
  m.published_of.assign(n, -1);
  m.known.assign(n, 0);
  m.mimic_of.assign(n, -1);
  m.duplicate = -1;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < i && m.duplicate < 0; ++j)
      if (names[j] == names[i]) m.duplicate = static_cast<int>(i);
    for (std::size_t k = 0; k < coordinate_names_.size(); ++k)
      if (coordinate_names_[k] == names[i]) m.coordinate_of[i] = static_cast<int>(k);
    for (std::size_t j = 0; j < published_joint_names_.size(); ++j)
      if (published_joint_names_[j] == names[i]) m.published_of[i] = static_cast<int>(j);
    for (std::size_t u = 0; u < moving_joint_names_.size(); ++u)
      if (moving_joint_names_[u] == names[i]) {
        m.known[i] = 1;
        if (moving_is_mimic_[u]) m.mimic_of[i] = static_cast<int>(u);
      }
    if (m.coordinate_of[i] >= 0 || m.published_of[i] >= 0) m.known[i] = 1;
  }
  return m.duplicate;
}

int JointStateMap::update(const std::vector<double>& position, const std::vector<double>& velocity,
                          const std::vector<double>& effort) {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  const Binding& m = bindings_[current_];
  int unknown = -1;
  for (std::size_t i = 0; i < m.known.size(); ++i) {
    if (!m.known[i]) {
      if (unknown < 0) unknown = static_cast<int>(i);
      continue;
    }
    const int k = m.coordinate_of[i];
    if (k >= 0) {
      q_[static_cast<std::size_t>(k)] = position[i];
      qd_[static_cast<std::size_t>(k)] =
          !velocity.empty() && std::isfinite(velocity[i]) ? velocity[i] : kNone;
      received_[static_cast<std::size_t>(k)] = 1;
      fresh_[static_cast<std::size_t>(k)] = 1;
    }
    const int j = m.published_of[i];
    if (j >= 0 && !effort.empty())
      effort_[static_cast<std::size_t>(j)] = std::isfinite(effort[i]) ? effort[i] : kNone;
  }
  checkMimics(position);
  return unknown;
}

void JointStateMap::checkMimics(const std::vector<double>& position) {
  // Only against a leader in the same message: one from another publisher may be of
  // another instant.
  mimic_contradiction_ = -1;
  const Binding& b = bindings_[current_];
  for (std::size_t i = 0; i < b.mimic_of.size() && mimic_contradiction_ < 0; ++i) {
    const int m = b.mimic_of[i];
    if (m < 0) continue;
    const std::size_t u = static_cast<std::size_t>(m);
    const int leader = moving_coordinate_[u];
    bool in_message = false;
    for (int c : b.coordinate_of) in_message = in_message || c == leader;
    if (!in_message) continue;
    const double expected =
        moving_multiplier_[u] * q_[static_cast<std::size_t>(leader)] + moving_offset_[u];
    if (std::abs(position[i] - expected) <= mimic_tolerance_) continue;
    mimic_contradiction_ = static_cast<int>(i);
    mimic_expected_ = expected;
  }
}

int JointStateMap::firstMissing() const {
  for (std::size_t k = 0; k < received_.size(); ++k)
    if (!received_[k]) return static_cast<int>(k);
  return -1;
}

}  // namespace jle
