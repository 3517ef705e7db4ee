#include <joint_load_estimator/settings/settings_reader.hpp>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdlib>
#include <initializer_list>
#include <set>
#include <stdexcept>
#include <utility>

namespace jle {

const std::array<Named<DifferentiatorType>, 4> kDifferentiatorTypes = {
    {{"finite_difference", DifferentiatorType::kFiniteDifference},
     {"savitzky_golay", DifferentiatorType::kSavitzkyGolay},
     {"kalman", DifferentiatorType::kKalman},
     {"adaptive", DifferentiatorType::kAdaptive}}};
const std::array<Named<KalmanModel>, 2> kKalmanModels = {
    {{"constant_jerk", KalmanModel::kConstantJerk},
     {"constant_acceleration", KalmanModel::kConstantAcceleration}}};
const std::array<Named<StalePolicy>, 3> kStalePolicies = {
    {{"hold", StalePolicy::kHold}, {"zero", StalePolicy::kZero}, {"stop", StalePolicy::kStop}}};

namespace {

// The other choices' names (the filters' are in the header: ~reconfigure shares them).
const std::array<Named<PlanarMode>, 3> kPlanarModes = {
    {{"auto", PlanarMode::kAuto}, {"on", PlanarMode::kOn}, {"off", PlanarMode::kOff}}};
const std::array<Named<StampRegularize>, 2> kStampRegularize = {
    {{"auto", StampRegularize::kAuto}, {"off", StampRegularize::kOff}}};
const std::array<Named<ExternalMethod>, 2> kExternalMethods = {
    {{"observer", ExternalMethod::kObserver}, {"residual", ExternalMethod::kResidual}}};
const std::array<Named<Precision>, 2> kPrecisions = {
    {{"double", Precision::kDouble}, {"float", Precision::kFloat}}};
const std::array<Named<MeasuredVelocity>, 3> kMeasuredVelocities = {
    {{"auto", MeasuredVelocity::kAuto},
     {"always", MeasuredVelocity::kAlways},
     {"never", MeasuredVelocity::kNever}}};

using Type = ParamValue::Type;

[[noreturn]] void wrongType(const std::string& key, const ParamValue& v, const char* expected) {
  throw SettingsError("parameter '" + key + "' must be " + expected + ", it is " + v.typeName());
}

// The number `v` (an integer or a double) of parameter `key`.
double toNumber(const ParamValue& v, const std::string& key) {
  if (v.type() != Type::kDouble && v.type() != Type::kInt) wrongType(key, v, "a number");
  return v.asDouble();
}

// A scalar of the parameter tree as its C++ type.
void valueOf(const ParamValue& v, int& out) { out = v.asInt(); }
void valueOf(const ParamValue& v, bool& out) { out = v.asBool(); }
void valueOf(const ParamValue& v, std::string& out) { out = v.asString(); }

// Maps the keys of one struct onto settings, remembering which were used so that the
// rest can be reported as unknown. A key that is absent leaves its setting alone (its
// default is in config.hpp).
class Section {
 public:
  Section(const ParamValue& value, std::string prefix) : prefix_(std::move(prefix)) {
    if (value.type() == Type::kNone) return;  // absent: all defaults
    if (value.type() != Type::kMap) wrongType(prefix_, value, "a map");
    value_ = &value;
  }
  bool has(const std::string& key) const { return value_ && value_->has(key); }
  const ParamValue& get(const std::string& key) {
    used_.insert(key);
    return value_->at(key);
  }
  std::string name(const std::string& key) const {
    return prefix_.empty() ? key : prefix_ + "/" + key;
  }
  void read(const std::string& key, double& out) {
    if (has(key)) out = toNumber(get(key), name(key));
  }
  void read(const std::string& key, int& out) { readScalar(key, out, Type::kInt, "an integer"); }
  void read(const std::string& key, bool& out) {
    readScalar(key, out, Type::kBool, "true or false");
  }
  void read(const std::string& key, std::string& out) {
    readScalar(key, out, Type::kString, "a string");
  }
  void read(const std::string& key, std::vector<std::string>& out) {
    if (!has(key)) return;
    const ParamValue& v = get(key);
    if (v.type() != Type::kList) wrongType(name(key), v, "a list of strings");
    out.clear();
    for (std::size_t i = 0; i < v.size(); ++i) {
      const ParamValue& e = v[i];
      if (e.type() != Type::kString)
        wrongType(name(key) + "[" + std::to_string(i) + "]", e, "a string");
      out.push_back(e.asString());
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
    const ParamValue& v = get(key);
    if (v.type() != Type::kList || v.size() != static_cast<std::size_t>(n))
      throw SettingsError("parameter '" + name(key) + "' must be a list of " + std::to_string(n) +
                          " numbers");
    for (int i = 0; i < n; ++i)
      out[i] = toNumber(v[static_cast<std::size_t>(i)], name(key) + "[" + std::to_string(i) + "]");
    return true;
  }
  // One of the names of `options` (a table of settings_reader.hpp), mapped to its value.
  template <typename Enum, std::size_t N>
  void read(const std::string& key, Enum& out, const std::array<Named<Enum>, N>& options) {
    if (!has(key)) return;
    std::string text, names;
    read(key, text);
    for (const Named<Enum>& o : options) {
      if (text == o.name) {
        out = o.value;
        return;
      }
      names += std::string(names.empty() ? "" : ", ") + o.name;
    }
    throw SettingsError("parameter '" + name(key) + "' is '" + text + "'; expected one of " +
                        names);
  }
  // As above, or a boolean: rosparam reads YAML 1.1, where a bare on/off is one; take
  // it as meant (true: `on`, false: `off`).
  template <typename Enum, std::size_t N>
  void read(const std::string& key, Enum& out, const std::array<Named<Enum>, N>& options, Enum on,
            Enum off) {
    if (!has(key) || get(key).type() != Type::kBool) return read(key, out, options);
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
    const ParamValue& list = get(key);
    if (list.type() != Type::kList) wrongType(name(key), list, "a list of maps");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string prefix = name(key) + "[" + std::to_string(i) + "]";
      if (list[i].type() != Type::kMap) wrongType(prefix, list[i], "a map");
      Section s(list[i], prefix);
      each(s);
      s.finish();
    }
  }
  void finish() const {
    if (!value_) return;
    for (std::size_t i = 0; i < value_->size(); ++i)
      if (!used_.count(value_->key(i)))
        throw SettingsError("unknown parameter '" + name(value_->key(i)) + "'");
  }

 private:
  template <typename T>
  void readScalar(const std::string& key, T& out, Type type, const char* expected) {
    if (!has(key)) return;
    const ParamValue& v = get(key);
    if (v.type() != type) wrongType(name(key), v, expected);
    valueOf(v, out);
  }

  const ParamValue* value_ = nullptr;  // a map, or null: absent
  std::string prefix_;
  std::set<std::string> used_;
};

void readDifferentiator(Section& s, DifferentiatorConfig& c) {
  s.read("type", c.type, kDifferentiatorTypes);
  s.read("window", c.window);
  s.read("order", c.order);
  if (s.has("delay")) {
    // "centred" (of the window read above) or a number of samples.
    const ParamValue& d = s.get("delay");
    if (d.type() == Type::kString && d.asString() == "centred")
      c.delay = (c.window - 1) / 2;
    else if (d.type() == Type::kInt)
      c.delay = d.asInt();
    else
      wrongType(s.name("delay"), d, "an integer or \"centred\"");
  }
  s.read("kalman_model", c.kalman_model, kKalmanModels);
  s.read("process_noise", c.process_noise);
  s.read("measurement_noise", c.measurement_noise);
  s.read("lag", c.lag);
  s.read("auto_bandwidth", c.auto_bandwidth);
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
  s.read("planar", v.planar, kPlanarModes, PlanarMode::kOn, PlanarMode::kOff);
}

void readStamps(Section& s, StampSettings& v) {
  s.read("regularize", v.regularize, kStampRegularize, StampRegularize::kAuto,
         StampRegularize::kOff);
  s.read("jump_confirm", v.jump_confirm);
  s.read("merge_window", v.merge_window);
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
                        s.name("period") + "' [s] (docs/studies/uncertainty.md)");
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
  s.read("method", e.method, kExternalMethods);
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
  s.read("max_hold", input.max_hold);
  s.read("force_noise", input.force_noise);
  s.read("moment_noise", input.moment_noise);
  input.name = w.topic;  // an input is named by its topic in the estimator's messages
  w.name = input.name;   // the pair's key (validate)
}

void readPlate(Section& s, PlateTopicSettings& p, PlateInputConfig& input) {
  ForcePlateConfig& plate = input.plate;
  s.read("name", plate.name);
  p.name = plate.name;  // the pair's key (validate)
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
  s.read("accept_nonphysical_inertia", n.accept_nonphysical_inertia);
  s.read("diagnostic_period", n.diagnostic_period);
  s.read("inline_callbacks", n.inline_callbacks);
  s.read("exit_on_master_restart", n.exit_on_master_restart);
  s.read("decimation", n.estimator.decimation);
  s.read("gravity", n.estimator.gravity_world.data(), 3);
  s.read("precision", n.estimator.precision, kPrecisions);
  s.read("measured_velocity", n.estimator.measured_velocity, kMeasuredVelocities);
  s.read("body_mass", n.body_mass);
  s.read("base_residual_threshold", n.base_residual_threshold);
  s.read("still_velocity", n.still_velocity);
  s.read("bias_file", n.bias_file);
}

ParamValue fromYaml(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      ParamValue out = ParamValue::map();  // an empty map stays a map
      for (const auto& kv : node) out.set(kv.first.as<std::string>(), fromYaml(kv.second));
      return out;
    }
    case YAML::NodeType::Sequence: {
      ParamValue out = ParamValue::list();
      for (std::size_t i = 0; i < node.size(); ++i) out.push(fromYaml(node[i]));
      return out;
    }
    case YAML::NodeType::Scalar: {
      const std::string text = node.Scalar();
      if (node.Tag() == "!") return ParamValue(text);  // quoted: a string
      if (text == "true" || text == "True") return ParamValue(true);
      if (text == "false" || text == "False") return ParamValue(false);
      char* end = nullptr;
      const long i = std::strtol(text.c_str(), &end, 10);
      if (!text.empty() && *end == '\0') return ParamValue(static_cast<int>(i));
      const double d = std::strtod(text.c_str(), &end);
      if (!text.empty() && *end == '\0') return ParamValue(d);
      return ParamValue(text);
    }
    default: return ParamValue();
  }
}

}  // namespace

Settings parseSettings(const ParamValue& params) {
  Settings n;
  Section s(params, "");
  readTopLevel(s, n);
  s.readMap("savings", [&](Section& m) { readSavings(m, n.estimator.savings); });
  s.readMap("stamps", [&](Section& m) { readStamps(m, n.stamps); });
  s.readMap("uncertainty", [&](Section& m) { readUncertainty(m, n.estimator.uncertainty); });
  s.readMap("friction", [&](Section& m) { readFriction(m, n.friction); });
  s.readMap("plausibility", [&](Section& m) {
    PlausibilityConfig& p = n.plausibility;
    m.read<double>({{"position_margin", &p.position_margin},
                    {"step_margin", &p.step_margin},
                    {"velocity_factor", &p.velocity_factor},
                    {"max_velocity", &p.max_velocity},
                    {"max_force", &p.max_force},
                    {"max_moment", &p.max_moment},
                    {"effort_factor", &p.effort_factor},
                    {"settle_time", &p.settle_time},
                    {"mimic_tolerance", &p.mimic_tolerance}});
  });
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

const char* ParamValue::typeName() const {
  switch (type_) {
    case Type::kBool: return "a boolean";
    case Type::kInt: return "an integer";
    case Type::kDouble: return "a number";
    case Type::kString: return "a string";
    case Type::kList: return "a list";
    case Type::kMap: return "a map";
    default: return "nothing";
  }
}

void ParamValue::need(Type type) const {
  if (type_ != type)
    throw std::logic_error(std::string("ParamValue: ") + typeName() + " read as another type");
}

bool ParamValue::asBool() const {
  need(Type::kBool);
  return bool_;
}

int ParamValue::asInt() const {
  need(Type::kInt);
  return int_;
}

double ParamValue::asDouble() const {
  if (type_ == Type::kInt) return int_;
  need(Type::kDouble);
  return double_;
}

const std::string& ParamValue::asString() const {
  need(Type::kString);
  return string_;
}

void ParamValue::push(ParamValue value) {
  if (type_ == Type::kNone) type_ = Type::kList;
  need(Type::kList);
  values_.push_back(std::move(value));
}

bool ParamValue::has(const std::string& key) const {
  return type_ == Type::kMap && std::find(keys_.begin(), keys_.end(), key) != keys_.end();
}

const ParamValue& ParamValue::at(const std::string& key) const {
  const auto it = std::find(keys_.begin(), keys_.end(), key);
  if (type_ != Type::kMap || it == keys_.end())
    throw std::out_of_range("ParamValue: no key '" + key + "'");
  return values_[static_cast<std::size_t>(it - keys_.begin())];
}

void ParamValue::set(const std::string& key, ParamValue value) {
  if (type_ == Type::kNone) type_ = Type::kMap;
  need(Type::kMap);
  const auto it = std::find(keys_.begin(), keys_.end(), key);
  if (it != keys_.end()) {
    values_[static_cast<std::size_t>(it - keys_.begin())] = std::move(value);
    return;
  }
  keys_.push_back(key);
  values_.push_back(std::move(value));
}

ParamValue parseYaml(const std::string& text) {
  try {
    return fromYaml(YAML::Load(text));
  } catch (const YAML::Exception& e) {
    throw SettingsError(std::string("YAML: ") + e.what());
  }
}

ParamValue loadYaml(const std::string& path) {
  try {
    return fromYaml(YAML::LoadFile(path));
  } catch (const YAML::Exception& e) {
    throw SettingsError(path + ": " + e.what());
  }
}

}  // namespace jle
