// The parameter reader (settings_reader.hpp; ros/settings.hpp for the parameter server) maps every
// key onto its field of jle::Settings and refuses what validate() refuses, naming the key: per key
// family an ok and a ko YAML (test/config/ok_*.yaml, ko_*.yaml), as ros_controllers'
// joint_state_controller tests do. And the documentation cannot drift: config/default.yaml and the
// defaults stated by the parameter tables of README.md and docs/ parse to Settings{}.
#include <joint_load_estimator/ros/settings.hpp>

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using jle::Settings;

const std::string kConfig = JLE_TEST_CONFIG;

Settings parseFile(const std::string& path) { return jle::parseSettings(jle::loadYaml(path)); }

// Parses YAML text (through a file, as process_bag reads it).
Settings parseText(const std::string& text) {
  const fs::path path =
      fs::temp_directory_path() / ("jle_settings_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(path) << text;
  try {
    Settings s = parseFile(path.string());
    fs::remove(path);
    return s;
  } catch (...) {
    fs::remove(path);
    throw;
  }
}

// The message of the SettingsError that parsing `path` throws ("" if it parses).
std::string refusal(const std::string& path) {
  try {
    parseFile(path);
  } catch (const jle::SettingsError& e) {
    return e.what();
  }
  return "";
}

// Field by field: a field the reader forgets to map, or maps onto another, differs here.
// EXPECT_SAME(f) compares a.f and b.f and names f on a failure.
#define EXPECT_SAME(f) EXPECT_EQ(a.f, b.f) << where << #f

void expectSame(const jle::DifferentiatorConfig& a, const jle::DifferentiatorConfig& b,
                const std::string& where) {
  EXPECT_SAME(type);
  EXPECT_SAME(window);
  EXPECT_SAME(order);
  EXPECT_SAME(delay);
  EXPECT_SAME(kalman_model);
  EXPECT_SAME(process_noise);
  EXPECT_SAME(measurement_noise);
  EXPECT_SAME(lag);
  EXPECT_SAME(auto_bandwidth);
  EXPECT_SAME(max_gap);
  EXPECT_SAME(min_bandwidth);
  EXPECT_SAME(max_bandwidth);
  EXPECT_SAME(noise);
  EXPECT_SAME(memory);
}

void expectSame(const jle::Savings& a, const jle::Savings& b, const std::string& where) {
  EXPECT_SAME(prune);
  EXPECT_SAME(massless_chains);
  EXPECT_SAME(gyroscopic);
  EXPECT_SAME(static_velocity);
  EXPECT_SAME(static_acceleration);
  EXPECT_SAME(reuse_unchanged);
  EXPECT_SAME(republish_unchanged);
  EXPECT_SAME(planar);
}

void expectSame(const jle::UncertaintyConfig& a, const jle::UncertaintyConfig& b,
                const std::string& where) {
  EXPECT_SAME(enabled);
  EXPECT_SAME(diagonal_only);
  EXPECT_SAME(position_noise);
  EXPECT_SAME(mass_fraction);
  EXPECT_SAME(com_offset);
  EXPECT_SAME(inertia_fraction);
  EXPECT_SAME(linearize_state);
  EXPECT_SAME(period);
  EXPECT_SAME(gain_tolerance);
}

void expectSame(const jle::WrenchInputConfig& a, const jle::WrenchInputConfig& b,
                const std::string& where) {
  EXPECT_SAME(name);
  EXPECT_SAME(link);
  EXPECT_SAME(sign);
  EXPECT_SAME(timeout);
  EXPECT_SAME(stale_policy);
  EXPECT_SAME(sensor_joint);
  EXPECT_SAME(force_noise);
  EXPECT_SAME(moment_noise);
}

void expectSame(const jle::PlateInputConfig& a, const jle::PlateInputConfig& b,
                const std::string& where) {
  EXPECT_SAME(plate.name);
  EXPECT_SAME(plate.link);
  EXPECT_SAME(plate.R_world_plate);
  EXPECT_SAME(plate.p_world_plate);
  EXPECT_SAME(plate.surface_height);
  EXPECT_SAME(plate.contact_threshold);
  EXPECT_SAME(timeout);
  EXPECT_SAME(stale_policy);
}

void expectSame(const jle::WrenchTopicSettings& a, const jle::WrenchTopicSettings& b,
                const std::string& where) {
  EXPECT_SAME(topic);
  EXPECT_SAME(frame);
  EXPECT_SAME(force_threshold);
  EXPECT_SAME(moment_threshold);
}

void expectSame(const jle::PlateTopicSettings& a, const jle::PlateTopicSettings& b,
                const std::string& where) {
  EXPECT_SAME(topic);
  EXPECT_SAME(frame);
  EXPECT_SAME(pose_configured);
}

void expectSame(const jle::ContactLinkConfig& a, const jle::ContactLinkConfig& b,
                const std::string& where) {
  EXPECT_SAME(link);
  EXPECT_SAME(point);
  EXPECT_SAME(force_only);
}

// Element by element, "wrenches[k]/" named on a failure.
template <typename T>
void expectSameList(const std::vector<T>& a, const std::vector<T>& b, const std::string& list) {
  ASSERT_EQ(a.size(), b.size()) << list;
  for (std::size_t k = 0; k < a.size(); ++k)
    expectSame(a[k], b[k], list + "[" + std::to_string(k) + "]/");
}

void expectSame(const jle::ExternalEffortConfig& a, const jle::ExternalEffortConfig& b) {
  const std::string where = "external_effort/";
  EXPECT_SAME(enabled);
  EXPECT_SAME(method);
  EXPECT_SAME(observer_cutoff);
  EXPECT_SAME(effort_noise);
  EXPECT_SAME(damping);
  EXPECT_SAME(singular_threshold);
  EXPECT_SAME(threshold);
  EXPECT_SAME(noise_multiple);
  EXPECT_SAME(calibration_time);
  EXPECT_SAME(settle_time);
  EXPECT_SAME(link_window);
  EXPECT_SAME(joint_thresholds);
  EXPECT_SAME(release_fraction);
  expectSameList(a.contacts, b.contacts, "external_effort/contacts");
}

void expectSame(const jle::EstimatorConfig& a, const jle::EstimatorConfig& b) {
  const std::string where;
  expectSame(a.differentiator, b.differentiator, "differentiator/");
  EXPECT_SAME(precision);
  EXPECT_SAME(measured_velocity);
  expectSame(a.savings, b.savings, "savings/");
  EXPECT_SAME(joints);
  EXPECT_SAME(gravity_world);
  expectSameList(a.wrenches, b.wrenches, "wrenches");
  EXPECT_SAME(decimation);
  expectSame(a.uncertainty, b.uncertainty, "uncertainty/");
  expectSameList(a.plates, b.plates, "force_plates");
}

void expectSame(const Settings& a, const Settings& b) {
  const std::string where;
  EXPECT_SAME(robot_description);
  EXPECT_SAME(joint_states_topic);
  EXPECT_SAME(publish_wrench_topics);
  EXPECT_SAME(floating_base);
  EXPECT_SAME(world_frame);
  EXPECT_SAME(base_frame);
  EXPECT_SAME(tf_wait);
  EXPECT_SAME(time_jump_threshold);
  EXPECT_SAME(stamps.regularize);
  EXPECT_SAME(stamps.jump_confirm);
  EXPECT_SAME(stamps.merge_window);
  EXPECT_SAME(keep_fixed_joints);
  EXPECT_SAME(accept_nonphysical_inertia);
  EXPECT_SAME(base_residual_threshold);
  EXPECT_SAME(still_velocity);
  EXPECT_SAME(bias_file);
  EXPECT_SAME(diagnostic_period);
  EXPECT_SAME(inline_callbacks);
  EXPECT_SAME(exit_on_master_restart);
  EXPECT_SAME(body_mass);
  expectSame(a.estimator, b.estimator);
  EXPECT_SAME(smoothed.enabled);
  expectSame(a.smoothed.differentiator, b.smoothed.differentiator, "smoothed/differentiator/");
  expectSame(a.external_effort, b.external_effort);
  expectSameList(a.wrenches, b.wrenches, "wrenches");
  expectSameList(a.force_plates, b.force_plates, "force_plates");
}

#undef EXPECT_SAME

// ---------------------------------------------------------------------------------------
// Per key family: the ok file lands key by key; the ko file is refused, naming the key.

struct Refused {
  const char* file;
  const char* key;     // as the message quotes it
  const char* reason;  // a part of the message after the key
};

const Refused kRefused[] = {
    {"ko_top_level.yaml", "'diagnostic_period'", "must be finite and > 0"},
    {"ko_differentiator.yaml", "'differentiator/order'", "must be 2..5"},
    {"ko_wrenches.yaml", "'wrenches[1]/sign'", "must be +1 or -1"},
    {"ko_force_plates.yaml", "'force_plates[1]/name'", "names another plate too"},
    {"ko_uncertainty.yaml", "'uncertainty/position_noise'", "must be finite and >= 0"},
    {"ko_savings.yaml", "'savings/static_velocity'", "must be finite and >= 0"},
    {"ko_stamps.yaml", "'stamps/jump_confirm'", "must be >= 1"},
    {"ko_external_effort.yaml", "'external_effort/release_fraction'", "must be in (0, 1]"},
    {"ko_smoothed.yaml", "'smoothed/differentiator/lag'", "must be > 0 [s]"},
};

TEST(SettingsReader, EachKoFileIsRefusedWithItsReason) {
  for (const Refused& r : kRefused) {
    const std::string why = refusal(kConfig + "/" + r.file);
    EXPECT_NE(why.find(std::string("parameter ") + r.key), std::string::npos)
        << r.file << ": " << why;
    EXPECT_NE(why.find(r.reason), std::string::npos) << r.file << ": " << why;
  }
}

TEST(SettingsReader, TopLevelKeys) {
  Settings e;
  e.robot_description = "arm_description";
  e.joint_states_topic = "/arm/joint_states";
  e.estimator.joints = {"shoulder_pan_joint", "elbow_joint"};
  e.publish_wrench_topics = false;
  e.estimator.gravity_world = Eigen::Vector3d(0.0, -9.81, 0.5);
  e.estimator.decimation = 3;
  e.time_jump_threshold = 0.5;
  e.keep_fixed_joints = {"wrist_3_link-tool0_fixed_joint"};
  e.accept_nonphysical_inertia = true;
  e.estimator.precision = jle::Precision::kFloat;
  e.estimator.measured_velocity = jle::MeasuredVelocity::kNever;
  e.floating_base = true;
  e.world_frame = "odom";
  e.base_frame = "base_link";
  e.tf_wait = 0.2;
  e.base_residual_threshold = 0.2;
  e.still_velocity = 0.05;
  e.bias_file = "/tmp/ft_bias.yaml";
  e.diagnostic_period = 0.25;
  e.inline_callbacks = true;
  e.exit_on_master_restart = true;
  e.body_mass = -1.0;
  expectSame(parseFile(kConfig + "/ok_top_level.yaml"), e);
}

TEST(SettingsReader, SmoothedKeys) {
  Settings e;
  e.smoothed.enabled = false;
  e.smoothed.differentiator.type = jle::DifferentiatorType::kAdaptive;
  e.smoothed.differentiator.lag = 0.15;
  e.smoothed.differentiator.min_bandwidth = 1.0;
  e.smoothed.differentiator.max_bandwidth = 20.0;
  expectSame(parseFile(kConfig + "/ok_smoothed.yaml"), e);
}

TEST(SettingsReader, DifferentiatorKeys) {
  Settings e;
  jle::DifferentiatorConfig& d = e.estimator.differentiator;
  d.type = jle::DifferentiatorType::kSavitzkyGolay;
  d.window = 11;
  d.order = 3;
  d.delay = 5;  // centred
  d.kalman_model = jle::KalmanModel::kConstantAcceleration;
  d.process_noise = 1e3;
  d.measurement_noise = 1e-3;
  d.max_gap = 0.25;
  d.min_bandwidth = 2.0;
  d.max_bandwidth = 20.0;
  d.noise = 5e-4;
  d.memory = 0.5;
  expectSame(parseFile(kConfig + "/ok_differentiator.yaml"), e);
}

TEST(SettingsReader, WrenchKeys) {
  Settings e;
  e.wrenches.resize(2);
  e.estimator.wrenches.resize(2);
  e.wrenches[0].topic = e.estimator.wrenches[0].name = "/tool/wrench";
  e.estimator.wrenches[0].link = "tool0";
  e.wrenches[0].frame = "tool_sensor";
  e.estimator.wrenches[0].sign = -1.0;
  e.estimator.wrenches[0].timeout = 0.25;
  e.estimator.wrenches[0].stale_policy = jle::StalePolicy::kStop;
  e.estimator.wrenches[0].force_noise = 0.5;
  e.estimator.wrenches[0].moment_noise = 0.05;
  e.wrenches[1].topic = e.estimator.wrenches[1].name = "/ft/wrench";
  e.estimator.wrenches[1].sensor_joint = "ft_joint";  // link: left to the estimator
  e.wrenches[1].force_threshold = 10.0;
  e.wrenches[1].moment_threshold = 1.5;
  e.estimator.wrenches[1].stale_policy = jle::StalePolicy::kZero;
  // keep_fixed_joints stays as written (modelOptions() adds the sensor's joint).
  expectSame(parseFile(kConfig + "/ok_wrenches.yaml"), e);
}

TEST(SettingsReader, ForcePlateKeys) {
  Settings e;
  e.force_plates.resize(2);
  e.estimator.plates.resize(2);
  jle::ForcePlateConfig& left = e.estimator.plates[0].plate;
  left.name = "left";
  e.force_plates[0].topic = "/plates/left";
  e.force_plates[0].frame = "plate_left";
  left.link = "left_foot";
  left.surface_height = 0.04;
  left.contact_threshold = 30.0;
  e.estimator.plates[0].timeout = 0.5;
  e.estimator.plates[0].stale_policy = jle::StalePolicy::kHold;
  left.p_world_plate = Eigen::Vector3d(0.3, 0.2, -0.04);
  // [x, y, z, w] = [1, 0, 0, 0]: pi about x, exact in the quaternion's matrix.
  left.R_world_plate = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  e.force_plates[0].pose_configured = true;
  e.estimator.plates[1].plate.name = "right";
  e.force_plates[1].topic = "/plates/right";
  e.estimator.plates[1].plate.link = "right_foot";
  expectSame(parseFile(kConfig + "/ok_force_plates.yaml"), e);
}

TEST(SettingsReader, UncertaintyKeys) {
  Settings e;
  jle::UncertaintyConfig& u = e.estimator.uncertainty;
  u.enabled = true;
  u.diagonal_only = true;
  u.position_noise = 1e-4;
  u.mass_fraction = 0.05;
  u.com_offset = 0.005;
  u.inertia_fraction = 0.1;
  u.linearize_state = false;
  u.period = 0.0;
  u.gain_tolerance = 0.05;
  expectSame(parseFile(kConfig + "/ok_uncertainty.yaml"), e);
}

TEST(SettingsReader, ExternalEffortKeys) {
  Settings e;
  jle::ExternalEffortConfig& x = e.external_effort;
  x.enabled = true;
  x.method = jle::ExternalMethod::kResidual;
  x.observer_cutoff = 25.0;
  x.effort_noise = 0.05;
  x.damping = 0.02;
  x.singular_threshold = 0.03;
  x.threshold = 1.5;
  x.noise_multiple = 6.0;
  x.calibration_time = 0.5;
  x.settle_time = 0.3;
  x.link_window = 0.05;
  x.release_fraction = 0.25;
  x.joint_thresholds = {{"panda_joint7", 0.4}};
  jle::ContactLinkConfig c;
  c.link = "panda_hand_tcp";
  c.point = Eigen::Vector3d(0.0, 0.0, 0.02);
  c.force_only = true;
  x.contacts.push_back(c);
  c.link = "panda_link5";
  c.point = Eigen::Vector3d::Zero();
  c.force_only = false;
  x.contacts.push_back(c);
  expectSame(parseFile(kConfig + "/ok_external_effort.yaml"), e);
}

TEST(SettingsReader, SavingsKeys) {
  Settings e;
  jle::Savings& v = e.estimator.savings;
  v.prune = v.massless_chains = v.gyroscopic = false;
  v.reuse_unchanged = v.republish_unchanged = false;
  v.static_velocity = 0.01;
  v.static_acceleration = 0.5;
  v.planar = jle::PlanarMode::kOn;
  expectSame(parseFile(kConfig + "/ok_savings.yaml"), e);
  // rosparam reads YAML 1.1, where a bare on/off is a boolean.
  XmlRpc::XmlRpcValue params;
  params["savings"]["planar"] = false;
  EXPECT_EQ(jle::parseSettings(params).estimator.savings.planar, jle::PlanarMode::kOff);
}

TEST(SettingsReader, StampsKeys) {
  Settings e;
  e.stamps.regularize = jle::StampRegularize::kAuto;
  e.stamps.jump_confirm = 5;
  e.stamps.merge_window = 0.002;
  expectSame(parseFile(kConfig + "/ok_stamps.yaml"), e);
  // rosparam reads YAML 1.1, where a bare off is a boolean.
  XmlRpc::XmlRpcValue params;
  params["stamps"]["regularize"] = false;
  EXPECT_EQ(jle::parseSettings(params).stamps.regularize, jle::StampRegularize::kOff);
  params["stamps"]["regularize"] = true;  // a bare on
  EXPECT_EQ(jle::parseSettings(params).stamps.regularize, jle::StampRegularize::kAuto);
}

// What the reader itself refuses (validate() never sees these): a wrong type, an
// unknown key or name, a missing section shape.
TEST(SettingsReader, TypesNamesAndUnknownKeysAreRefusedNamingTheKey) {
  auto expectRefused = [](const std::string& text, const std::string& culprit) {
    try {
      parseText(text);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const jle::SettingsError& e) {
      EXPECT_NE(std::string(e.what()).find(culprit), std::string::npos) << e.what();
    }
  };
  expectRefused("decimation: 1.5", "parameter 'decimation' must be an integer");
  expectRefused("gravity: [0, 0]", "parameter 'gravity' must be a list of 3 numbers");
  expectRefused("gravity: [0, 0, g]", "parameter 'gravity[2]' must be a number");
  expectRefused(
      "measured_velocity: sometimes",
      "parameter 'measured_velocity' is 'sometimes'; expected one of auto, always, never");
  expectRefused("measured_velocity: always\nuncertainty: {enabled: true}",
                "parameter 'measured_velocity' is always, but uncertainty/enabled");
  expectRefused("precision: half",
                "parameter 'precision' is 'half'; expected one of double, float");
  expectRefused("differentiator: {delay: middle}", "'differentiator/delay' must be an integer or");
  expectRefused("savings: {prune: 1}", "parameter 'savings/prune' must be true or false");
  expectRefused("uncertainty: {decimation: 4}", "'uncertainty/decimation' is replaced by");
  expectRefused("wrenches: [{topic: t, link: l, stale_policy: keep}]",
                "'wrenches[0]/stale_policy'");
  expectRefused("wrenches: [{topic: t, lnk: l}]", "unknown parameter 'wrenches[0]/lnk'");
  expectRefused("wrenches: [{topic: t}]", "parameter 'wrenches[0]/link' is required");
  expectRefused("force_plates: [{name: a, topic: t, link: f, orientation: [0, 0, 0, 0]}]",
                "'force_plates[0]/orientation' must be a quaternion");
  expectRefused("savings: [prune]", "parameter 'savings' must be a map");
  expectRefused("stamps: {regularize: always}",
                "parameter 'stamps/regularize' is 'always'; expected one of auto, off");
  expectRefused("diagnostics_period: 1", "unknown parameter 'diagnostics_period'");
  // Issue 14: an empty topic and a joint listed twice are refused at start, key named.
  expectRefused("joint_states_topic: ''", "parameter 'joint_states_topic' is required");
  expectRefused("wrenches: [{topic: '', link: l}]", "parameter 'wrenches[0]/topic' is required");
  expectRefused("joints: [a, b, a]", "parameter 'joints[2]' is 'a', as is 'joints[0]'");
  expectRefused("keep_fixed_joints: [f, f]", "parameter 'keep_fixed_joints[1]' is 'f'");
  expectRefused(
      "external_effort: {method: kalman}",
      "parameter 'external_effort/method' is 'kalman'; expected one of observer, residual");
  expectRefused("external_effort: {contacts: [{point: [0, 0, 0]}]}",
                "parameter 'external_effort/contacts[0]/link' is required");
  expectRefused("external_effort: {joint_thresholds: [{threshold: 1}]}",
                "parameter 'external_effort/joint_thresholds[0]/joint' is required");
}

// ---------------------------------------------------------------------------------------
// The documentation states the defaults of config.hpp.

// One table of names (settings_reader.hpp): every name reads back as its value, the
// reader refuses another naming them all, and ~reconfigure's enumerations
// (cfg/Estimator.cfg, Python: it cannot include the table) list the same names in order.
std::vector<std::string> quotedNamesAfter(const std::string& text, const std::string& from,
                                          const std::string& to) {
  const std::size_t begin = text.find(from), end = text.find(to, begin);
  std::vector<std::string> names;
  if (begin == std::string::npos || end == std::string::npos) return names;
  const std::string part = text.substr(begin, end - begin);
  const std::regex quoted("\"([a-z_]+)\"");
  for (auto it = std::sregex_iterator(part.begin(), part.end(), quoted);
       it != std::sregex_iterator(); ++it)
    names.push_back((*it)[1]);
  return names;
}

TEST(SettingsNames, OneTableForTheReaderAndReconfigure) {
  std::vector<std::string> types, models;
  for (const auto& n : jle::kDifferentiatorTypes) {
    types.push_back(n.name);
    const Settings s = parseText(std::string("differentiator: {type: ") + n.name + "}\n");
    EXPECT_EQ(s.estimator.differentiator.type, n.value) << n.name;
    EXPECT_STREQ(jle::nameOf(jle::kDifferentiatorTypes, n.value), n.name);
  }
  for (const auto& n : jle::kKalmanModels) {
    models.push_back(n.name);
    const Settings s = parseText(std::string("differentiator: {kalman_model: ") + n.name + "}\n");
    EXPECT_EQ(s.estimator.differentiator.kalman_model, n.value) << n.name;
  }
  for (const auto& n : jle::kStalePolicies) {
    const Settings s = parseText(
        std::string("wrenches: [{topic: ft, link: panda_hand, stale_policy: ") + n.name + "}]\n");
    EXPECT_EQ(s.estimator.wrenches.at(0).stale_policy, n.value) << n.name;
  }
  try {
    parseText("differentiator: {type: butterworth}\n");
    ADD_FAILURE() << "an unknown differentiator was accepted";
  } catch (const jle::SettingsError& e) {
    for (const std::string& t : types) EXPECT_NE(std::string(e.what()).find(t), std::string::npos);
  }
  std::ifstream in(JLE_RECONFIGURE_CFG);
  std::stringstream text;
  text << in.rdbuf();
  const std::string cfg = text.str();
  EXPECT_EQ(quotedNamesAfter(cfg, "types = gen.enum(", "\"differentiator/type\")"), types);
  EXPECT_EQ(quotedNamesAfter(cfg, "models = gen.enum(", "\"differentiator/kalman_model\")"),
            models);
}

TEST(SettingsDocs, DefaultYamlIsSettingsDefaults) {
  expectSame(parseFile(JLE_DEFAULT_YAML), Settings{});
  // And parsing nothing is Settings{}: the reader writes no default of its own.
  expectSame(jle::parseSettings(jle::ParamValue()), Settings{});
  expectSame(jle::parseSettings(XmlRpc::XmlRpcValue()), Settings{});
}

// The parameter server's values (XmlRpc) read as the same file's YAML: every type, nested
// maps and lists.
TEST(SettingsReader, ParameterServerValuesAreReadAsTheirYaml) {
  XmlRpc::XmlRpcValue params;
  params["decimation"] = 3;
  params["gravity"][0] = 0.0;
  params["gravity"][1] = 0;
  params["gravity"][2] = -9.5;
  params["joints"][0] = std::string("a");
  params["savings"]["prune"] = false;
  params["differentiator"]["type"] = std::string("kalman");
  params["wrenches"][0]["topic"] = std::string("ft");
  params["wrenches"][0]["link"] = std::string("tool0");
  params["wrenches"][0]["sign"] = -1.0;
  expectSame(
      jle::parseSettings(params),
      jle::parseSettings(jle::parseYaml(
          "decimation: 3\ngravity: [0.0, 0, -9.5]\njoints: [a]\nsavings: {prune: false}\n"
          "differentiator: {type: kalman}\nwrenches: [{topic: ft, link: tool0, sign: -1.0}]")));
  EXPECT_EQ(jle::parseSettings(params).estimator.decimation, 3);
  EXPECT_EQ(jle::parseSettings(params).estimator.wrenches.at(0).sign, -1.0);
  EXPECT_THROW(jle::parseYaml("decimation: [1"), jle::SettingsError);
}

// Every key of the ok files (which together hold every key the reader knows) is in
// config/default.yaml: top-level keys at the top, a map's keys in that map.
TEST(SettingsDocs, DefaultYamlListsEveryKey) {
  const jle::ParamValue defaults = jle::loadYaml(JLE_DEFAULT_YAML);
  for (const char* family : {"top_level", "differentiator", "savings", "uncertainty", "stamps",
                             "external_effort", "smoothed"}) {
    const jle::ParamValue ok = jle::loadYaml(kConfig + "/ok_" + family + ".yaml");
    for (std::size_t i = 0; i < ok.size(); ++i) {
      const std::string& key = ok.key(i);
      ASSERT_TRUE(defaults.has(key)) << key << " is not in config/default.yaml";
      if (ok[i].type() != jle::ParamValue::Type::kMap) continue;
      for (std::size_t j = 0; j < ok[i].size(); ++j)
        EXPECT_TRUE(defaults.at(key).has(ok[i].key(j)))
            << key << "/" << ok[i].key(j) << " is not in config/default.yaml";
    }
  }
}

// The parameter tables of the docs (README.md's "at a glance", docs/node.md's whole one,
// docs/external_loads.md's): each row of one key and one stated default, e.g.
// "| `savings/prune` | `true` | ...", parsed as that key's YAML, is Settings{}. Returns the
// keys of the rows, one "`key`" per line; counts the rows in `checked`.
std::string checkParameterTable(const std::string& path, int& checked) {
  std::ifstream doc(path);
  EXPECT_TRUE(doc.good()) << path;
  const std::regex row(R"(^\| `([a-z_]+)(/([a-z_]+))?(/([a-z_]+))?` \| `([^`]*)`)");
  std::string line, rows;
  checked = 0;
  while (std::getline(doc, line)) {
    std::smatch m;
    if (!std::regex_search(line, m, row)) continue;
    rows += "`" + m[1].str() + (m[2].matched ? m[2].str() : "") + "`\n";
    const std::string value = m[6].str();
    const std::string yaml =
        m[4].matched   ? m[1].str() + ":\n  " + m[3].str() + ":\n    " + m[5].str() + ": " + value
        : m[2].matched ? m[1].str() + ":\n  " + m[3].str() + ": " + value
                       : m[1].str() + ": " + value;
    SCOPED_TRACE(path + " row " + line.substr(0, 60));
    expectSame(parseText(yaml + "\n"), Settings{});
    ++checked;
  }
  return rows;
}

// docs/node.md has a row for every key of default.yaml; README.md's short table and
// docs/external_loads.md's state the same defaults.
TEST(SettingsDocs, ParameterTablesStateTheDefaults) {
  int checked = 0;
  const std::string rows = checkParameterTable(JLE_NODE_DOC, checked);
  EXPECT_GE(checked, 60);  // the rows of one key (66 when written)
  const jle::ParamValue defaults = jle::loadYaml(JLE_DEFAULT_YAML);
  for (std::size_t i = 0; i < defaults.size(); ++i) {
    if (defaults[i].type() == jle::ParamValue::Type::kMap) continue;  // rows per key
    EXPECT_NE(rows.find("`" + defaults.key(i) + "`"), std::string::npos)
        << defaults.key(i) << ": no row in docs/node.md";
  }
  checkParameterTable(JLE_README, checked);
  EXPECT_GE(checked, 20);  // README's "Parameters at a glance" (24 when written)
  checkParameterTable(JLE_EXTERNAL_DOC, checked);
  EXPECT_GE(checked, 12);  // the external_effort/... table (14 when written)
}

}  // namespace
