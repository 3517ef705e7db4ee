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

/// What the rules allow a joint (segment s's): positions within [low, high], its URDF limits
/// widened by position_margin; a step of at most rate dt + step_margin in dt [s], rate the
/// velocity_factor times its velocity limit. Computed once per coordinate by a front end
/// that checks every message.
struct PlausibleRange {
  double low = 0.0, high = 0.0, rate = 0.0;
};

inline PlausibleRange plausibleRange(const Model<double>& model, const PlausibilityConfig& p,
                                     std::size_t s) {
  return {model.lower_limit[s] - p.position_margin, model.upper_limit[s] + p.position_margin,
          p.velocity_factor * velocityLimit(model, p, s)};
}

/// Whether position q is plausible for a joint of range r.
inline bool plausiblePosition(const PlausibleRange& r, double q) {
  return q >= r.low && q <= r.high;
}

/// Why position q of segment s's joint is not plausible, naming joint, value and bound.
inline std::string positionProblem(const Model<double>& model, const PlausibilityConfig& p,
                                   std::size_t s, double q) {
  char text[256];
  std::snprintf(text, sizeof text,
                "position of joint '%s' is %.6g, beyond its URDF limits [%.6g, %.6g] by more "
                "than plausibility/position_margin %.3g",
                model.joint_name[s].c_str(), q, model.lower_limit[s], model.upper_limit[s],
                p.position_margin);
  return text;
}

/// Whether a step of a joint's position by `step` in dt [s] > 0 is plausible for a joint of
/// range r.
inline bool plausibleStep(const PlausibleRange& r, const PlausibilityConfig& p, double step,
                          double dt) {
  return std::abs(step) <= r.rate * dt + p.step_margin;
}

/// Why that step is not plausible, naming joint, step and limit.
inline std::string stepProblem(const Model<double>& model, const PlausibilityConfig& p,
                               std::size_t s, double step, double dt) {
  char text[256];
  std::snprintf(text, sizeof text,
                "position of joint '%s' moved %.6g in %.6g s, beyond plausibility/"
                "velocity_factor %.3g times its velocity limit %.6g",
                model.joint_name[s].c_str(), std::abs(step), dt, p.velocity_factor,
                velocityLimit(model, p, s));
  return text;
}

/// Whether a measured velocity is beyond what a joint of range r does (velocity_factor
/// times its velocity limit).
inline bool implausibleVelocity(const PlausibleRange& r, double velocity) {
  return std::abs(velocity) > r.rate;
}

/// Whether an effort of segment s's joint is beyond effort_factor times its URDF effort
/// limit (the loads flagged kImplausibleLoad).
inline bool implausibleEffort(const Model<double>& model, const PlausibilityConfig& p,
                              std::size_t s, double effort) {
  return std::abs(effort) > p.effort_factor * model.effort_limit[s];
}

}  // namespace jle
