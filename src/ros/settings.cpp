#include <joint_load_estimator/ros/settings.hpp>

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <set>
#include <utility>

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

// The number `v` (an integer or a double) of parameter `key`.
double toNumber(const XmlRpcValue& v, const std::string& key) {
  if (v.getType() == XmlRpcValue::TypeDouble)
    return static_cast<double>(const_cast<XmlRpcValue&>(v));
  if (v.getType() == XmlRpcValue::TypeInt) return static_cast<int>(const_cast<XmlRpcValue&>(v));
  wrongType(key, v, "a number");
}

template <typename Enum>
using Choices = std::initializer_list<std::pair<const char*, Enum>>;

const Choices<StalePolicy> kStalePolicies = {
    {"hold", StalePolicy::kHold}, {"zero", StalePolicy::kZero}, {"stop", StalePolicy::kStop}};

// Maps the keys of one struct onto settings, remembering which were used so that the
// rest can be reported as unknown. A key that is absent leaves its setting alone (its
// default is in config.hpp).
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
    if (has(key)) out = toNumber(get(key), name(key));
  }
  void read(const std::string& key, int& out) {
    readScalar(key, out, XmlRpcValue::TypeInt, "an integer");
  }
  void read(const std::string& key, bool& out) {
    readScalar(key, out, XmlRpcValue::TypeBoolean, "true or false");
  }
  void read(const std::string& key, std::string& out) {
    readScalar(key, out, XmlRpcValue::TypeString, "a string");
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
  // Several keys of one type, each onto its field: {{"prune", &savings.prune}, ...}.
  template <typename T>
  void read(std::initializer_list<std::pair<const char*, T*>> keys) {
    for (const auto& k : keys) read(k.first, *k.second);
  }
  // A list of `n` numbers (gravity, a plate's position); false when the key is absent.
  bool read(const std::string& key, double* out, int n) {
    if (!has(key)) return false;
    const XmlRpcValue& v = get(key);
    if (v.getType() != XmlRpcValue::TypeArray || v.size() != n)
      throw SettingsError("parameter '" + name(key) + "' must be a list of " + std::to_string(n) +
                          " numbers");
    for (int i = 0; i < n; ++i) out[i] = toNumber(v[i], name(key) + "[" + std::to_string(i) + "]");
    return true;
  }
  // One of the names of `options`, mapped to its value.
  template <typename Enum>
  void read(const std::string& key, Enum& out, Choices<Enum> options) {
    if (!has(key)) return;
    std::string text, names;
    read(key, text);
    for (const auto& o : options) {
      if (text == o.first) {
        out = o.second;
        return;
      }
      names += std::string(names.empty() ? "" : ", ") + o.first;
    }
    throw SettingsError("parameter '" + name(key) + "' is '" + text + "'; expected one of " +
                        names);
  }
  // As above, or a boolean: rosparam reads YAML 1.1, where a bare on/off is one; take
  // it as meant (true: `on`, false: `off`).
  template <typename Enum>
  void read(const std::string& key, Enum& out, Choices<Enum> options, Enum on, Enum off) {
    if (!has(key) || get(key).getType() != XmlRpcValue::TypeBoolean) return read(key, out, options);
    bool value = false;
    read(key, value);
    out = value ? on : off;
  }
  // The map `key` read by `each(Section&)`, then checked for unknown keys.
  template <typename Each>
  void readMap(const std::string& key, Each each) {
    if (!has(key)) return;
    Section s(get(key), name(key));
    each(s);
    s.finish();
  }
  // The list of maps `key`: each element read by `each(Section&)` ("key[i]/...").
  template <typename Each>
  void readList(const std::string& key, Each each) {
    if (!has(key)) return;
    const XmlRpcValue& list = get(key);
    if (list.getType() != XmlRpcValue::TypeArray) wrongType(name(key), list, "a list of maps");
    for (int i = 0; i < list.size(); ++i) {
      const std::string prefix = name(key) + "[" + std::to_string(i) + "]";
      if (list[i].getType() != XmlRpcValue::TypeStruct) wrongType(prefix, list[i], "a map");
      Section s(list[i], prefix);
      each(s);
      s.finish();
    }
  }
  void finish() const {
    if (value_.getType() != XmlRpcValue::TypeStruct) return;
    for (auto it = value_.begin(); it != value_.end(); ++it)
      if (!used_.count(it->first))
        throw SettingsError("unknown parameter '" + name(it->first) + "'");
  }

 private:
  template <typename T>
  void readScalar(const std::string& key, T& out, XmlRpcValue::Type type, const char* expected) {
    if (!has(key)) return;
    const XmlRpcValue& v = get(key);
    if (v.getType() != type) wrongType(name(key), v, expected);
    out = static_cast<T>(const_cast<XmlRpcValue&>(v));
  }

  XmlRpcValue value_;
  std::string prefix_;
  std::set<std::string> used_;
};

void readDifferentiator(Section& s, DifferentiatorConfig& c) {
  s.read("type", c.type,
         {{"finite_difference", DifferentiatorType::kFiniteDifference},
          {"savitzky_golay", DifferentiatorType::kSavitzkyGolay},
          {"kalman", DifferentiatorType::kKalman},
          {"adaptive", DifferentiatorType::kAdaptive}});
  s.read("window", c.window);
  s.read("order", c.order);
  if (s.has("delay")) {
    // "centred" (of the window read above) or a number of samples.
    const XmlRpcValue& d = s.get("delay");
    if (d.getType() == XmlRpcValue::TypeString &&
        static_cast<std::string>(const_cast<XmlRpcValue&>(d)) == "centred")
      c.delay = (c.window - 1) / 2;
    else if (d.getType() == XmlRpcValue::TypeInt)
      c.delay = static_cast<int>(const_cast<XmlRpcValue&>(d));
    else
      wrongType(s.name("delay"), d, "an integer or \"centred\"");
  }
  s.read("kalman_model", c.kalman_model,
         {{"constant_acceleration", KalmanModel::kConstantAcceleration},
          {"constant_jerk", KalmanModel::kConstantJerk}});
  s.read("process_noise", c.process_noise);
  s.read("measurement_noise", c.measurement_noise);
  s.read("lag", c.lag);
  s.read("max_gap", c.max_gap);
  s.read("min_bandwidth", c.min_bandwidth);
  s.read("max_bandwidth", c.max_bandwidth);
  s.read("noise", c.noise);
  s.read("memory", c.memory);
}

void readSavings(Section& s, Savings& v) {
  s.read<bool>({{"prune", &v.prune},
                {"massless_chains", &v.massless_chains},
                {"gyroscopic", &v.gyroscopic},
                {"reuse_unchanged", &v.reuse_unchanged},
                {"republish_unchanged", &v.republish_unchanged}});
  s.read<double>(
      {{"static_velocity", &v.static_velocity}, {"static_acceleration", &v.static_acceleration}});
  s.read("planar", v.planar,
         {{"auto", PlanarMode::kAuto}, {"on", PlanarMode::kOn}, {"off", PlanarMode::kOff}},
         PlanarMode::kOn, PlanarMode::kOff);
}

void readStamps(Section& s, StampSettings& v) {
  s.read("regularize", v.regularize,
         {{"auto", StampRegularize::kAuto}, {"off", StampRegularize::kOff}}, StampRegularize::kAuto,
         StampRegularize::kOff);
  s.read("jump_confirm", v.jump_confirm);
}

void readUncertainty(Section& s, UncertaintyConfig& u) {
  s.read<bool>({{"enabled", &u.enabled},
                {"diagonal_only", &u.diagonal_only},
                {"linearize_state", &u.linearize_state}});
  s.read<double>({{"position_noise", &u.position_noise},
                  {"mass_fraction", &u.mass_fraction},
                  {"com_offset", &u.com_offset},
                  {"inertia_fraction", &u.inertia_fraction},
                  {"period", &u.period},
                  {"gain_tolerance", &u.gain_tolerance}});
  if (s.has("decimation"))  // the sample count it replaced
    throw SettingsError("parameter '" + s.name("decimation") + "' is replaced by '" +
                        s.name("period") + "' [s] (docs/uncertainty.md)");
}

void readFriction(Section& s, FrictionConfig& f) {
  s.read("enabled", f.enabled);
  s.read("velocity_scale", f.velocity_scale);
}

void readContact(Section& s, ContactLinkConfig& c) {
  s.read("link", c.link);
  s.read("point", c.point.data(), 3);
  s.read("force_only", c.force_only);
}

void readExternalEffort(Section& s, ExternalEffortConfig& e) {
  s.read("enabled", e.enabled);
  s.read("method", e.method,
         {{"observer", ExternalMethod::kObserver}, {"residual", ExternalMethod::kResidual}});
  s.read<double>({{"observer_cutoff", &e.observer_cutoff},
                  {"effort_noise", &e.effort_noise},
                  {"damping", &e.damping},
                  {"singular_threshold", &e.singular_threshold},
                  {"threshold", &e.threshold},
                  {"noise_multiple", &e.noise_multiple},
                  {"calibration_time", &e.calibration_time},
                  {"settle_time", &e.settle_time},
                  {"link_window", &e.link_window},
                  {"release_fraction", &e.release_fraction}});
  s.readList("contacts", [&](Section& m) { readContact(m, e.contacts.emplace_back()); });
  s.readList("joint_thresholds", [&](Section& m) {
    std::pair<std::string, double>& jt = e.joint_thresholds.emplace_back();
    m.read("joint", jt.first);
    m.read("threshold", jt.second);
    if (jt.first.empty()) throw SettingsError("parameter '" + m.name("joint") + "' is required");
  });
}

void readWrench(Section& s, WrenchTopicSettings& w, WrenchInputConfig& input) {
  s.read("topic", w.topic);
  s.read("frame", w.frame);
  s.read("force_threshold", w.force_threshold);
  s.read("moment_threshold", w.moment_threshold);
  s.read("link", input.link);
  s.read("sensor_joint", input.sensor_joint);
  s.read("sign", input.sign);
  s.read("timeout", input.timeout);
  s.read("stale_policy", input.stale_policy, kStalePolicies);
  s.read("force_noise", input.force_noise);
  s.read("moment_noise", input.moment_noise);
  input.name = w.topic;  // an input is named by its topic in the estimator's messages
}

void readPlate(Section& s, PlateTopicSettings& p, PlateInputConfig& input) {
  ForcePlateConfig& plate = input.plate;
  s.read("name", plate.name);
  s.read("topic", p.topic);
  s.read("frame", p.frame);
  s.read("link", plate.link);
  s.read("surface_height", plate.surface_height);
  s.read("contact_threshold", plate.contact_threshold);
  s.read("timeout", input.timeout);
  s.read("stale_policy", input.stale_policy, kStalePolicies);
  if (s.read("position", plate.p_world_plate.data(), 3)) p.pose_configured = true;
  double xyzw[4];
  if (s.read("orientation", xyzw, 4)) {
    const Eigen::Quaterniond o(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
    if (!(o.norm() > 1e-6))  // no rotation to normalise it to
      throw SettingsError("parameter '" + s.name("orientation") +
                          "' must be a quaternion [x, y, z, w] of non-zero norm");
    plate.R_world_plate = o.normalized().toRotationMatrix();
    p.pose_configured = true;
  }
}

// The keys of the top level that are not maps or lists of maps.
void readTopLevel(Section& s, Settings& n) {
  s.read("robot_description", n.robot_description);
  s.read("joint_states_topic", n.joint_states_topic);
  s.read("joints", n.estimator.joints);
  s.read("publish_wrench_topics", n.publish_wrench_topics);
  s.read("floating_base", n.floating_base);
  s.read("world_frame", n.world_frame);
  s.read("base_frame", n.base_frame);
  s.read("tf_wait", n.tf_wait);
  s.read("time_jump_threshold", n.time_jump_threshold);
  s.read("keep_fixed_joints", n.keep_fixed_joints);
  s.read("diagnostic_period", n.diagnostic_period);
  s.read("inline_callbacks", n.inline_callbacks);
  s.read("decimation", n.estimator.decimation);
  s.read("gravity", n.estimator.gravity_world.data(), 3);
  s.read("precision", n.estimator.precision,
         {{"double", Precision::kDouble}, {"float", Precision::kFloat}});
  s.read("measured_velocity", n.estimator.measured_velocity,
         {{"auto", MeasuredVelocity::kAuto},
          {"always", MeasuredVelocity::kAlways},
          {"never", MeasuredVelocity::kNever}});
  s.read("body_mass", n.body_mass);
  s.read("base_residual_threshold", n.base_residual_threshold);
  s.read("still_velocity", n.still_velocity);
  s.read("bias_file", n.bias_file);
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

Settings parseSettings(const XmlRpcValue& params) {
  Settings n;
  Section s(params, "");
  readTopLevel(s, n);
  s.readMap("savings", [&](Section& m) { readSavings(m, n.estimator.savings); });
  s.readMap("stamps", [&](Section& m) { readStamps(m, n.stamps); });
  s.readMap("uncertainty", [&](Section& m) { readUncertainty(m, n.estimator.uncertainty); });
  s.readMap("friction", [&](Section& m) { readFriction(m, n.friction); });
  s.readMap("external_effort", [&](Section& m) { readExternalEffort(m, n.external_effort); });
  s.readMap("differentiator",
            [&](Section& m) { readDifferentiator(m, n.estimator.differentiator); });
  s.readMap("smoothed", [&](Section& m) {
    m.read("enabled", n.smoothed.enabled);
    m.readMap("differentiator",
              [&](Section& d) { readDifferentiator(d, n.smoothed.differentiator); });
  });
  s.readList("wrenches", [&](Section& m) {
    readWrench(m, n.wrenches.emplace_back(), n.estimator.wrenches.emplace_back());
  });
  s.readList("force_plates", [&](Section& m) {
    readPlate(m, n.force_plates.emplace_back(), n.estimator.plates.emplace_back());
  });
  s.finish();
  validate(n);
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
