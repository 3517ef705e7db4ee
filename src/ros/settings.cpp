#include <joint_load_estimator/ros/settings.hpp>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace jle {
namespace {

using XmlRpc::XmlRpcValue;

std::string typeName(const XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpcValue::TypeBoolean: return "a boolean";
    case XmlRpcValue::TypeInt: return "an integer";
    case XmlRpcValue::TypeDouble: return "a number";
    case XmlRpcValue::TypeString: return "a string";
    case XmlRpcValue::TypeArray: return "a list";
    case XmlRpcValue::TypeStruct: return "a map";
    default: return "of another type";
  }
}

[[noreturn]] void wrongType(const std::string& key, const XmlRpcValue& v, const char* expected) {
  throw SettingsError("parameter '" + key + "' must be " + expected + ", it is " + typeName(v));
}

// Reads the keys of one struct, remembering which were used so that the rest can be
// reported as unknown.
class Section {
 public:
  Section(const XmlRpcValue& value, std::string prefix) : prefix_(std::move(prefix)) {
    if (value.getType() == XmlRpcValue::TypeInvalid) return;  // absent: all defaults
    if (value.getType() != XmlRpcValue::TypeStruct) wrongType(prefix_, value, "a map");
    value_ = value;
  }
  bool has(const std::string& key) const {
    return value_.getType() == XmlRpcValue::TypeStruct && value_.hasMember(key);
  }
  const XmlRpcValue& get(const std::string& key) {
    used_.insert(key);
    return value_[key];
  }
  std::string name(const std::string& key) const {
    return prefix_.empty() ? key : prefix_ + "/" + key;
  }
  void read(const std::string& key, double& out) {
    if (!has(key)) return;
    const XmlRpcValue& v = get(key);
    if (v.getType() == XmlRpcValue::TypeDouble)
      out = static_cast<double>(const_cast<XmlRpcValue&>(v));
    else if (v.getType() == XmlRpcValue::TypeInt)
      out = static_cast<int>(const_cast<XmlRpcValue&>(v));
    else
      wrongType(name(key), v, "a number");
    if (!std::isfinite(out)) throw SettingsError("parameter '" + name(key) + "' is not finite");
  }
  void read(const std::string& key, int& out) {
    if (!has(key)) return;
    const XmlRpcValue& v = get(key);
    if (v.getType() != XmlRpcValue::TypeInt) wrongType(name(key), v, "an integer");
    out = static_cast<int>(const_cast<XmlRpcValue&>(v));
  }
  void read(const std::string& key, bool& out) {
    if (!has(key)) return;
    const XmlRpcValue& v = get(key);
    if (v.getType() != XmlRpcValue::TypeBoolean) wrongType(name(key), v, "true or false");
    out = static_cast<bool>(const_cast<XmlRpcValue&>(v));
  }
  void read(const std::string& key, std::string& out) {
    if (!has(key)) return;
    const XmlRpcValue& v = get(key);
    if (v.getType() != XmlRpcValue::TypeString) wrongType(name(key), v, "a string");
    out = static_cast<std::string>(const_cast<XmlRpcValue&>(v));
  }
  void read(const std::string& key, std::vector<std::string>& out) {
    if (!has(key)) return;
    const XmlRpcValue& v = get(key);
    if (v.getType() != XmlRpcValue::TypeArray) wrongType(name(key), v, "a list of strings");
    out.clear();
    for (int i = 0; i < v.size(); ++i) {
      const XmlRpcValue& e = v[i];
      if (e.getType() != XmlRpcValue::TypeString)
        wrongType(name(key) + "[" + std::to_string(i) + "]", e, "a string");
      out.push_back(static_cast<std::string>(const_cast<XmlRpcValue&>(e)));
    }
  }
  void finish() const {
    if (value_.getType() != XmlRpcValue::TypeStruct) return;
    for (auto it = value_.begin(); it != value_.end(); ++it)
      if (!used_.count(it->first))
        throw SettingsError("unknown parameter '" + name(it->first) + "'");
  }

 private:
  XmlRpcValue value_;
  std::string prefix_;
  std::set<std::string> used_;
};

template <typename Enum>
Enum choose(const std::string& key, const std::string& value,
            std::initializer_list<std::pair<const char*, Enum>> options) {
  std::string names;
  for (const auto& o : options) {
    if (value == o.first) return o.second;
    names += std::string(names.empty() ? "" : ", ") + o.first;
  }
  throw SettingsError("parameter '" + key + "' is '" + value + "'; expected one of " + names);
}

DifferentiatorConfig parseDifferentiator(const XmlRpcValue& value, const std::string& prefix) {
  DifferentiatorConfig c = nodeDefaultDifferentiator();
  Section s(value, prefix);
  std::string type = "kalman", model = "constant_jerk";
  s.read("type", type);
  c.type = choose<DifferentiatorType>(s.name("type"), type,
                                      {{"finite_difference", DifferentiatorType::kFiniteDifference},
                                       {"savitzky_golay", DifferentiatorType::kSavitzkyGolay},
                                       {"kalman", DifferentiatorType::kKalman}});
  s.read("window", c.window);
  s.read("order", c.order);
  if (s.has("delay")) {
    // "centred" or a number of samples.
    const XmlRpcValue& d = s.get("delay");
    if (d.getType() == XmlRpcValue::TypeString &&
        static_cast<std::string>(const_cast<XmlRpcValue&>(d)) == "centred")
      c.delay = (c.window - 1) / 2;
    else if (d.getType() == XmlRpcValue::TypeInt)
      c.delay = static_cast<int>(const_cast<XmlRpcValue&>(d));
    else
      wrongType(s.name("delay"), d, "an integer or \"centred\"");
  }
  s.read("kalman_model", model);
  c.kalman_model = choose<KalmanModel>(s.name("kalman_model"), model,
                                       {{"constant_acceleration", KalmanModel::kConstantAcceleration},
                                        {"constant_jerk", KalmanModel::kConstantJerk}});
  s.read("process_noise", c.process_noise);
  s.read("measurement_noise", c.measurement_noise);
  s.read("max_gap", c.max_gap);
  s.finish();
  try {
    validate(c);
  } catch (const std::invalid_argument& e) {
    throw SettingsError(std::string("parameter ") + e.what());
  }
  return c;
}

WrenchTopicSettings parseWrench(const XmlRpcValue& value, const std::string& prefix) {
  WrenchTopicSettings w;
  Section s(value, prefix);
  if (value.getType() != XmlRpcValue::TypeStruct) wrongType(prefix, value, "a map");
  if (!s.has("topic")) throw SettingsError("parameter '" + s.name("topic") + "' is required");
  s.read("sensor_joint", w.input.sensor_joint);
  // A sensor's link is its joint's child link (the estimator fills it in).
  if (!s.has("link") && w.input.sensor_joint.empty())
    throw SettingsError("parameter '" + s.name("link") + "' is required");
  s.read("topic", w.topic);
  s.read("link", w.input.link);
  s.read("force_threshold", w.force_threshold);
  s.read("moment_threshold", w.moment_threshold);
  if (!(w.force_threshold > 0.0) || !(w.moment_threshold > 0.0))
    throw SettingsError("parameters '" + s.name("force_threshold") + "' and '" +
                        s.name("moment_threshold") + "' must be positive");
  s.read("frame", w.frame);
  s.read("sign", w.input.sign);
  if (!(w.input.sign == 1.0 || w.input.sign == -1.0))
    throw SettingsError("parameter '" + s.name("sign") + "' must be 1 or -1");
  s.read("timeout", w.input.timeout);
  if (!(w.input.timeout > 0.0))
    throw SettingsError("parameter '" + s.name("timeout") + "' must be positive");
  std::string policy = "hold";
  s.read("stale_policy", policy);
  w.input.stale_policy = choose<StalePolicy>(
      s.name("stale_policy"), policy,
      {{"hold", StalePolicy::kHold}, {"zero", StalePolicy::kZero}, {"stop", StalePolicy::kStop}});
  s.read("force_noise", w.input.force_noise);
  s.read("moment_noise", w.input.moment_noise);
  if (!(w.input.force_noise >= 0.0) || !(w.input.moment_noise >= 0.0))
    throw SettingsError("parameters '" + s.name("force_noise") + "' and '" + s.name("moment_noise") +
                        "' must not be negative");
  s.finish();
  w.input.name = w.topic;
  return w;
}

// A list of `n` numbers (key e.g. "force_plates[0]/position").
void readNumbers(const XmlRpcValue& v, const std::string& key, int n, double* out) {
  if (v.getType() != XmlRpcValue::TypeArray || v.size() != n)
    throw SettingsError("parameter '" + key + "' must be a list of " + std::to_string(n) +
                        " numbers");
  for (int i = 0; i < n; ++i) {
    const XmlRpcValue& e = v[i];
    if (e.getType() == XmlRpcValue::TypeDouble)
      out[i] = static_cast<double>(const_cast<XmlRpcValue&>(e));
    else if (e.getType() == XmlRpcValue::TypeInt)
      out[i] = static_cast<int>(const_cast<XmlRpcValue&>(e));
    else
      wrongType(key + "[" + std::to_string(i) + "]", e, "a number");
    if (!std::isfinite(out[i])) throw SettingsError("parameter '" + key + "' is not finite");
  }
}

PlateTopicSettings parsePlate(const XmlRpcValue& value, const std::string& prefix) {
  PlateTopicSettings p;
  ForcePlateConfig& plate = p.input.plate;
  Section s(value, prefix);
  if (value.getType() != XmlRpcValue::TypeStruct) wrongType(prefix, value, "a map");
  for (const char* key : {"name", "topic", "link"})
    if (!s.has(key)) throw SettingsError("parameter '" + s.name(key) + "' is required");
  s.read("name", plate.name);
  if (plate.name.empty()) throw SettingsError("parameter '" + s.name("name") + "' is empty");
  s.read("topic", p.topic);
  s.read("frame", p.frame);
  s.read("link", plate.link);
  s.read("surface_height", plate.surface_height);
  s.read("contact_threshold", plate.contact_threshold);
  if (plate.contact_threshold < 0.0)
    throw SettingsError("parameter '" + s.name("contact_threshold") + "' must not be negative");
  s.read("timeout", p.input.timeout);
  if (!(p.input.timeout > 0.0))
    throw SettingsError("parameter '" + s.name("timeout") + "' must be positive");
  std::string policy = "zero";
  s.read("stale_policy", policy);
  p.input.stale_policy = choose<StalePolicy>(
      s.name("stale_policy"), policy,
      {{"hold", StalePolicy::kHold}, {"zero", StalePolicy::kZero}, {"stop", StalePolicy::kStop}});
  if (s.has("position")) {
    readNumbers(s.get("position"), s.name("position"), 3, plate.p_world_plate.data());
    p.pose_configured = true;
  }
  if (s.has("orientation")) {
    double xyzw[4];
    readNumbers(s.get("orientation"), s.name("orientation"), 4, xyzw);
    const Eigen::Quaterniond o(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
    if (!(o.norm() > 1e-6))
      throw SettingsError("parameter '" + s.name("orientation") +
                          "' must be a quaternion [x, y, z, w] of non-zero norm");
    plate.R_world_plate = o.normalized().toRotationMatrix();
    p.pose_configured = true;
  }
  s.finish();
  return p;
}

XmlRpcValue fromYaml(const YAML::Node& node) {
  XmlRpcValue out;
  switch (node.Type()) {
    case YAML::NodeType::Map:
      out = XmlRpcValue();
      for (const auto& kv : node) out[kv.first.as<std::string>()] = fromYaml(kv.second);
      if (node.size() == 0) out.begin();  // an empty map stays a map
      return out;
    case YAML::NodeType::Sequence:
      out.setSize(static_cast<int>(node.size()));
      for (std::size_t i = 0; i < node.size(); ++i) out[static_cast<int>(i)] = fromYaml(node[i]);
      return out;
    case YAML::NodeType::Scalar: {
      const std::string text = node.Scalar();
      if (node.Tag() == "!") return XmlRpcValue(text);  // quoted: a string
      if (text == "true" || text == "True") return XmlRpcValue(true);
      if (text == "false" || text == "False") return XmlRpcValue(false);
      char* end = nullptr;
      const long i = std::strtol(text.c_str(), &end, 10);
      if (!text.empty() && *end == '\0') return XmlRpcValue(static_cast<int>(i));
      const double d = std::strtod(text.c_str(), &end);
      if (!text.empty() && *end == '\0') return XmlRpcValue(d);
      return XmlRpcValue(text);
    }
    default: return out;
  }
}

}  // namespace

DifferentiatorConfig nodeDefaultDifferentiator() {
  // On the accuracy study's error-delay Pareto front, closest to the best in every
  // scene (docs/accuracy.md): constant-jerk Kalman, q = 1e4, r = 1e-4 rad.
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kKalman;
  c.kalman_model = KalmanModel::kConstantJerk;
  c.process_noise = 1e4;
  c.measurement_noise = 1e-4;
  return c;
}

NodeSettings parseSettings(const XmlRpcValue& params) {
  NodeSettings n;
  n.estimator.differentiator = nodeDefaultDifferentiator();
  Section s(params, "");
  s.read("robot_description", n.robot_description);
  s.read("joint_states_topic", n.joint_states_topic);
  s.read("joints", n.joints);
  n.estimator.joints = n.joints;
  s.read("publish_wrench_topics", n.publish_wrench_topics);
  s.read("floating_base", n.floating_base);
  s.read("world_frame", n.world_frame);
  s.read("base_frame", n.base_frame);
  s.read("time_jump_threshold", n.time_jump_threshold);
  s.read("keep_fixed_joints", n.keep_fixed_joints);
  // diagnostic_updater reads its own key from the same namespace.
  double diagnostic_period = 1.0;
  s.read("diagnostic_period", diagnostic_period);
  s.read("decimation", n.estimator.decimation);
  if (n.estimator.decimation < 1) throw SettingsError("parameter 'decimation' must be >= 1");
  if (s.has("gravity")) {
    const XmlRpcValue& g = s.get("gravity");
    if (g.getType() != XmlRpcValue::TypeArray || g.size() != 3)
      throw SettingsError("parameter 'gravity' must be a list of 3 numbers");
    for (int i = 0; i < 3; ++i) {
      const XmlRpcValue& e = g[i];
      if (e.getType() == XmlRpcValue::TypeDouble)
        n.estimator.gravity_world[i] = static_cast<double>(const_cast<XmlRpcValue&>(e));
      else if (e.getType() == XmlRpcValue::TypeInt)
        n.estimator.gravity_world[i] = static_cast<int>(const_cast<XmlRpcValue&>(e));
      else
        wrongType("gravity[" + std::to_string(i) + "]", e, "a number");
    }
  }
  std::string precision = "double";
  s.read("precision", precision);
  n.estimator.precision = choose<Precision>("precision", precision,
                                            {{"double", Precision::kDouble}, {"float", Precision::kFloat}});
  if (s.has("savings")) {
    Section sv(s.get("savings"), "savings");
    Savings& v = n.estimator.savings;
    sv.read("prune", v.prune);
    sv.read("massless_chains", v.massless_chains);
    sv.read("gyroscopic", v.gyroscopic);
    sv.read("reuse_unchanged", v.reuse_unchanged);
    sv.read("republish_unchanged", v.republish_unchanged);
    sv.read("static_velocity", v.static_velocity);
    sv.read("static_acceleration", v.static_acceleration);
    // rosparam reads YAML 1.1, where a bare on/off is a boolean: take it as meant.
    if (sv.has("planar") && sv.get("planar").getType() == XmlRpcValue::TypeBoolean) {
      bool planar = false;
      sv.read("planar", planar);
      v.planar = planar ? PlanarMode::kOn : PlanarMode::kOff;
    } else {
      std::string planar = "auto";
      sv.read("planar", planar);
      v.planar = choose<PlanarMode>(sv.name("planar"), planar,
                                    {{"auto", PlanarMode::kAuto}, {"on", PlanarMode::kOn}, {"off", PlanarMode::kOff}});
    }
    if (v.static_velocity < 0.0 || v.static_acceleration < 0.0)
      throw SettingsError("parameters 'savings/static_velocity' and 'savings/static_acceleration' "
                          "must not be negative");
    sv.finish();
  }
  if (s.has("uncertainty")) {
    Section su(s.get("uncertainty"), "uncertainty");
    UncertaintyConfig& u = n.estimator.uncertainty;
    su.read("enabled", u.enabled);
    su.read("diagonal_only", u.diagonal_only);
    su.read("position_noise", u.position_noise);
    su.read("mass_fraction", u.mass_fraction);
    su.read("com_offset", u.com_offset);
    su.read("inertia_fraction", u.inertia_fraction);
    su.read("linearize_state", u.linearize_state);
    su.read("period", u.period);
    su.read("gain_tolerance", u.gain_tolerance);
    if (!(u.gain_tolerance >= 0.0) || !std::isfinite(u.gain_tolerance))
      throw SettingsError("parameter '" + su.name("gain_tolerance") + "' must be finite and >= 0");
    if (!(u.period >= 0.0) || !std::isfinite(u.period))
      throw SettingsError("parameter '" + su.name("period") + "' must be finite and >= 0 [s]");
    if (su.has("decimation"))  // the sample count it replaced
      throw SettingsError("parameter '" + su.name("decimation") + "' is replaced by '" +
                          su.name("period") + "' [s] (docs/uncertainty.md)");
    const std::pair<const char*, double> values[] = {{"position_noise", u.position_noise},
                                                      {"mass_fraction", u.mass_fraction},
                                                      {"com_offset", u.com_offset},
                                                      {"inertia_fraction", u.inertia_fraction}};
    for (const auto& kv : values)
      if (!(kv.second >= 0.0))
        throw SettingsError("parameter '" + su.name(kv.first) + "' must not be negative");
    su.finish();
  }
  if (s.has("differentiator"))
    n.estimator.differentiator = parseDifferentiator(s.get("differentiator"), "differentiator");
  if (s.has("wrenches")) {
    const XmlRpcValue& list = s.get("wrenches");
    if (list.getType() != XmlRpcValue::TypeArray) wrongType("wrenches", list, "a list of maps");
    for (int i = 0; i < list.size(); ++i) {
      n.wrenches.push_back(parseWrench(list[i], "wrenches[" + std::to_string(i) + "]"));
      n.estimator.wrenches.push_back(n.wrenches.back().input);
    }
  }
  if (s.has("force_plates")) {
    const XmlRpcValue& list = s.get("force_plates");
    if (list.getType() != XmlRpcValue::TypeArray) wrongType("force_plates", list, "a list of maps");
    std::set<std::string> names;
    for (int i = 0; i < list.size(); ++i) {
      const std::string key = "force_plates[" + std::to_string(i) + "]";
      n.force_plates.push_back(parsePlate(list[i], key));
      if (!names.insert(n.force_plates.back().input.plate.name).second)
        throw SettingsError("parameter '" + key + "/name': '" +
                            n.force_plates.back().input.plate.name + "' names another plate too");
      n.estimator.plates.push_back(n.force_plates.back().input);
    }
  }
  s.read("body_mass", n.body_mass);
  if (!(n.body_mass >= 0.0 || n.body_mass == -1.0))
    throw SettingsError("parameter 'body_mass' must be a mass > 0 [kg], 0 (off) or -1 (the "
                        "URDF's total mass)");
  if (n.time_jump_threshold <= 0.0)
    throw SettingsError("parameter 'time_jump_threshold' must be positive");
  s.read("base_residual_threshold", n.base_residual_threshold);
  if (!(n.base_residual_threshold > 0.0))
    throw SettingsError("parameter 'base_residual_threshold' must be positive");
  s.read("still_velocity", n.still_velocity);
  if (!(n.still_velocity > 0.0)) throw SettingsError("parameter 'still_velocity' must be positive");
  s.read("bias_file", n.bias_file);
  // A sensor's joint is kept as its own segment: its wrench is what the sensor measures.
  for (const WrenchTopicSettings& w : n.wrenches) {
    const std::string& j = w.input.sensor_joint;
    if (!j.empty() &&
        std::find(n.keep_fixed_joints.begin(), n.keep_fixed_joints.end(), j) == n.keep_fixed_joints.end())
      n.keep_fixed_joints.push_back(j);
  }
  s.finish();
  return n;
}

XmlRpcValue loadYaml(const std::string& path) {
  try {
    return fromYaml(YAML::LoadFile(path));
  } catch (const YAML::Exception& e) {
    throw SettingsError(path + ": " + e.what());
  }
}

}  // namespace jle
