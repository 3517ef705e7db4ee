#include <joint_load_estimator/settings/config.hpp>

#include <cmath>
#include <set>
#include <sstream>
#include <utility>

namespace jle {
namespace {

[[noreturn]] void fail(const std::string& key, const std::string& what) {
  throw SettingsError("parameter '" + key + "' " + what);
}

std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

void finite(const std::string& key, double v) {
  if (!std::isfinite(v)) fail(key, "must be finite, it is " + number(v));
}

void positive(const std::string& key, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) fail(key, "must be finite and > 0, it is " + number(v));
}

void nonNegative(const std::string& key, double v) {
  if (!(v >= 0.0) || !std::isfinite(v)) fail(key, "must be finite and >= 0, it is " + number(v));
}

void required(const std::string& key, const std::string& v) {
  if (v.empty()) fail(key, "is required");
}

// The key of element k of list `list`: "wrenches[0]/sign".
std::string element(const char* list, std::size_t k, const char* key) {
  return std::string(list) + "[" + std::to_string(k) + "]/" + key;
}

// Each entry of the list `key` once: "parameter 'joints[2]' is 'elbow', as is 'joints[0]'".
void unique(const char* key, const std::vector<std::string>& list) {
  for (std::size_t i = 0; i < list.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (list[i] == list[j])
        fail(std::string(key) + "[" + std::to_string(i) + "]",
             "is '" + list[i] + "', as is '" + key + "[" + std::to_string(j) + "]'");
}

void validateSavings(const Savings& s) {
  nonNegative("savings/static_velocity", s.static_velocity);
  nonNegative("savings/static_acceleration", s.static_acceleration);
}

void validateUncertainty(const UncertaintyConfig& u) {
  const std::pair<const char*, double> values[] = {
      {"uncertainty/position_noise", u.position_noise},
      {"uncertainty/mass_fraction", u.mass_fraction},
      {"uncertainty/com_offset", u.com_offset},
      {"uncertainty/inertia_fraction", u.inertia_fraction},
      {"uncertainty/period", u.period},
      {"uncertainty/gain_tolerance", u.gain_tolerance}};
  for (const auto& kv : values) nonNegative(kv.first, kv.second);
}

void validateWrench(const WrenchInputConfig& w, std::size_t k) {
  // A sensor's link defaults to its joint's child link (the Estimator fills it in).
  if (w.sensor_joint.empty()) required(element("wrenches", k, "link"), w.link);
  if (!(w.sign == 1.0 || w.sign == -1.0))
    fail(element("wrenches", k, "sign"), "must be +1 or -1, it is " + number(w.sign));
  positive(element("wrenches", k, "timeout"), w.timeout);
  nonNegative(element("wrenches", k, "max_hold"), w.max_hold);
  nonNegative(element("wrenches", k, "force_noise"), w.force_noise);
  nonNegative(element("wrenches", k, "moment_noise"), w.moment_noise);
}

void validatePlate(const PlateInputConfig& p, std::size_t k) {
  required(element("force_plates", k, "link"), p.plate.link);
  positive(element("force_plates", k, "timeout"), p.timeout);
  nonNegative(element("force_plates", k, "contact_threshold"), p.plate.contact_threshold);
  finite(element("force_plates", k, "surface_height"), p.plate.surface_height);
  if (!p.plate.p_world_plate.allFinite())
    fail(element("force_plates", k, "position"), "must be finite");
  const Eigen::Matrix3d& R = p.plate.R_world_plate;
  if (!R.allFinite() || !((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-9) ||
      !(R.determinant() > 0.0))
    fail(element("force_plates", k, "orientation"), "must be a rotation");
}

// A topic's settings pair with the input or plate of their `name` (empty: the one at their
// index, for settings made in code), which must be the one at their index.
void pairs(const std::string& key, const std::string& paired, const std::string& name,
           const char* whose) {
  if (!paired.empty() && paired != name)
    fail(key,
         "is '" + paired + "' in the topic's settings, but '" + name + "' in the " + whose + "'s");
}

void validateWrenchTopics(const Settings& s) {
  if (s.wrenches.size() != s.estimator.wrenches.size())
    fail("wrenches", "holds " + std::to_string(s.wrenches.size()) + " topics for " +
                         std::to_string(s.estimator.wrenches.size()) + " inputs");
  for (std::size_t k = 0; k < s.wrenches.size(); ++k) {
    required(element("wrenches", k, "topic"), s.wrenches[k].topic);
    pairs(element("wrenches", k, "name"), s.wrenches[k].name, s.estimator.wrenches[k].name,
          "input");
    positive(element("wrenches", k, "force_threshold"), s.wrenches[k].force_threshold);
    positive(element("wrenches", k, "moment_threshold"), s.wrenches[k].moment_threshold);
  }
}

void validatePlateTopics(const Settings& s) {
  if (s.force_plates.size() != s.estimator.plates.size())
    fail("force_plates", "holds " + std::to_string(s.force_plates.size()) + " topics for " +
                             std::to_string(s.estimator.plates.size()) + " plates");
  std::set<std::string> names;
  for (std::size_t k = 0; k < s.force_plates.size(); ++k) {
    const std::string& name = s.estimator.plates[k].plate.name;
    required(element("force_plates", k, "name"), name);
    if (!names.insert(name).second)
      fail(element("force_plates", k, "name"), "'" + name + "' names another plate too");
    required(element("force_plates", k, "topic"), s.force_plates[k].topic);
    pairs(element("force_plates", k, "name"), s.force_plates[k].name, name, "plate");
  }
}

}  // namespace

// external_effort/... (its model-level checks are in external_effort.cpp).
void validate(const ExternalEffortConfig& c) {
  positive("external_effort/observer_cutoff", c.observer_cutoff);
  nonNegative("external_effort/effort_noise", c.effort_noise);
  nonNegative("external_effort/damping", c.damping);
  positive("external_effort/singular_threshold", c.singular_threshold);
  nonNegative("external_effort/threshold", c.threshold);
  nonNegative("external_effort/noise_multiple", c.noise_multiple);
  positive("external_effort/calibration_time", c.calibration_time);
  nonNegative("external_effort/settle_time", c.settle_time);
  nonNegative("external_effort/link_window", c.link_window);
  if (!(c.release_fraction > 0.0 && c.release_fraction <= 1.0))
    fail("external_effort/release_fraction",
         "must be in (0, 1], it is " + number(c.release_fraction));
  for (std::size_t k = 0; k < c.contacts.size(); ++k) {
    if (c.contacts[k].link.empty())
      fail(element("external_effort/contacts", k, "link"), "is required");
    if (!c.contacts[k].point.allFinite())
      fail(element("external_effort/contacts", k, "point"), "must be finite");
  }
  for (const auto& jt : c.joint_thresholds)
    nonNegative("external_effort/joint_thresholds/" + jt.first, jt.second);
}

void validate(const EstimatorConfig& config) {
  try {
    validate(config.differentiator);
  } catch (const std::invalid_argument& e) {
    throw SettingsError(e.what());  // it names the key already
  }
  if (config.decimation < 1)
    fail("decimation", "must be >= 1, it is " + std::to_string(config.decimation));
  if (!config.gravity_world.allFinite()) fail("gravity", "must be finite");
  unique("joints", config.joints);
  validateSavings(config.savings);
  validateUncertainty(config.uncertainty);
  if (config.measured_velocity == MeasuredVelocity::kAlways && config.uncertainty.enabled)
    fail("measured_velocity",
         "is always, but uncertainty/enabled propagates the positions' noise only: use auto or "
         "never");
  for (std::size_t k = 0; k < config.wrenches.size(); ++k) validateWrench(config.wrenches[k], k);
  for (std::size_t k = 0; k < config.plates.size(); ++k) validatePlate(config.plates[k], k);
}

EstimatorConfig smoothedEstimatorConfig(const Settings& settings) {
  EstimatorConfig config = settings.estimator;
  config.differentiator = settings.smoothed.differentiator;
  return config;
}

namespace {

void validateSmoothed(const SmoothedStreamSettings& s) {
  if (!s.enabled) return;
  const DifferentiatorConfig& d = s.differentiator;
  try {
    validate(d);
  } catch (const std::invalid_argument& e) {
    // "parameter 'differentiator/..." names the key within smoothed/.
    std::string what = e.what();
    const std::string key = "'differentiator/";
    const std::size_t at = what.find(key);
    if (at != std::string::npos) what.insert(at + 1, "smoothed/");
    throw SettingsError(what);
  }
  if (d.type != DifferentiatorType::kKalman && d.type != DifferentiatorType::kAdaptive)
    fail("smoothed/differentiator/type", "must be kalman or adaptive (a smoother)");
  if (!(d.lag > 0.0))
    fail("smoothed/differentiator/lag",
         "must be > 0 [s]: the smoothed stream's delay (smoothed/enabled: false turns it off)");
}

}  // namespace

void validate(const Settings& settings) {
  validate(settings.estimator);
  validateSmoothed(settings.smoothed);
  required("robot_description", settings.robot_description);
  required("joint_states_topic", settings.joint_states_topic);
  unique("keep_fixed_joints", settings.keep_fixed_joints);
  positive("time_jump_threshold", settings.time_jump_threshold);
  if (settings.stamps.jump_confirm < 1)
    fail("stamps/jump_confirm",
         "must be >= 1, it is " + std::to_string(settings.stamps.jump_confirm));
  nonNegative("stamps/merge_window", settings.stamps.merge_window);
  positive("base_residual_threshold", settings.base_residual_threshold);
  positive("still_velocity", settings.still_velocity);
  positive("diagnostic_period", settings.diagnostic_period);
  nonNegative("tf_wait", settings.tf_wait);
  positive("friction/velocity_scale", settings.friction.velocity_scale);
  validate(settings.external_effort);
  const double m = settings.body_mass;
  if (!((m >= 0.0 && std::isfinite(m)) || m == -1.0))
    fail("body_mass",
         "must be a mass > 0 [kg], 0 (off) or -1 (the URDF's total mass), it is " + number(m));
  validateWrenchTopics(settings);
  validatePlateTopics(settings);
  validate(settings.plausibility);
}

void validate(const PlausibilityConfig& p) {
  nonNegative("plausibility/position_margin", p.position_margin);
  nonNegative("plausibility/step_margin", p.step_margin);
  if (!(p.velocity_factor >= 1.0) || !std::isfinite(p.velocity_factor))
    fail("plausibility/velocity_factor",
         "must be finite and >= 1, it is " + number(p.velocity_factor));
  positive("plausibility/max_velocity", p.max_velocity);
  positive("plausibility/max_force", p.max_force);
  positive("plausibility/max_moment", p.max_moment);
  if (!(p.effort_factor >= 1.0) || !std::isfinite(p.effort_factor))
    fail("plausibility/effort_factor", "must be finite and >= 1, it is " + number(p.effort_factor));
  nonNegative("plausibility/settle_time", p.settle_time);
  nonNegative("plausibility/mimic_tolerance", p.mimic_tolerance);
}

}  // namespace jle
