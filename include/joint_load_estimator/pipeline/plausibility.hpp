// Plausibility at the door (Settings::plausibility, docs/node.md "Never silently wrong"): what no
// joint of the model produces. One set of rules for every front end: jle::Pipeline (the
// node, process_bag, Python) drops such a message, joint_loads refuses such a row. ROS-free.
#pragma once

#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace jle {

/// Per coordinate (model.coordinate_names order), the segment of its own joint (the
/// leader of its mimics), whose URDF limits it has.
inline std::vector<int> coordinateSegments(const Model<double>& model) {
  std::vector<int> segment(static_cast<std::size_t>(model.nq), 0);
  for (int s = 1; s < model.nsegments(); ++s) {
    const int c = model.coordinate[static_cast<std::size_t>(s)];
    if (c >= 0 && model.joint_name[static_cast<std::size_t>(s)] ==
                      model.coordinate_names[static_cast<std::size_t>(c)])
      segment[static_cast<std::size_t>(c)] = s;
  }
  return segment;
}

/// The velocity limit of segment s's joint [rad/s or m/s]: the URDF's, else max_velocity.
inline double velocityLimit(const Model<double>& model, const PlausibilityConfig& p,
                            std::size_t s) {
  return std::isfinite(model.velocity_limit[s]) ? model.velocity_limit[s] : p.max_velocity;
}

/// Why position q of segment s's joint is not plausible (beyond its URDF limits by more
/// than position_margin), naming joint, value and bound; empty when it is.
inline std::string implausiblePosition(const Model<double>& model, const PlausibilityConfig& p,
                                       std::size_t s, double q) {
  if (q >= model.lower_limit[s] - p.position_margin &&
      q <= model.upper_limit[s] + p.position_margin)
    return {};
  char text[256];
  std::snprintf(text, sizeof text,
                "position of joint '%s' is %.6g, beyond its URDF limits [%.6g, %.6g] by more "
                "than plausibility/position_margin %.3g",
                model.joint_name[s].c_str(), q, model.lower_limit[s], model.upper_limit[s],
                p.position_margin);
  return text;
}

/// Why a step of segment s's joint's position by `step` in dt [s] > 0 is not plausible
/// (beyond step_margin plus velocity_factor times its velocity limit times dt); empty
/// when it is.
inline std::string implausibleStep(const Model<double>& model, const PlausibilityConfig& p,
                                   std::size_t s, double step, double dt) {
  const double limit = velocityLimit(model, p, s);
  if (std::abs(step) <= p.velocity_factor * limit * dt + p.step_margin) return {};
  char text[256];
  std::snprintf(text, sizeof text,
                "position of joint '%s' moved %.6g in %.6g s, beyond plausibility/"
                "velocity_factor %.3g times its velocity limit %.6g",
                model.joint_name[s].c_str(), std::abs(step), dt, p.velocity_factor, limit);
  return text;
}

/// Whether a measured velocity of segment s's joint is beyond velocity_factor times its
/// velocity limit.
inline bool implausibleVelocity(const Model<double>& model, const PlausibilityConfig& p,
                                std::size_t s, double velocity) {
  return std::abs(velocity) > p.velocity_factor * velocityLimit(model, p, s);
}

/// Whether an effort of segment s's joint is beyond effort_factor times its URDF effort
/// limit (the loads flagged kImplausibleLoad).
inline bool implausibleEffort(const Model<double>& model, const PlausibilityConfig& p,
                              std::size_t s, double effort) {
  return std::abs(effort) > p.effort_factor * model.effort_limit[s];
}

}  // namespace jle
