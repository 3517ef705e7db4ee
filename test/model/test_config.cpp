// The configuration (config.hpp): its defaults, and validate() accepting the edges of
// every range and refusing what lies beyond, per key family, naming the key. Core only
// (no ROS): the reader's side is test_settings.cpp.
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/settings/config.hpp>
#include <joint_load_estimator/settings/settings_reader.hpp>

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace {

using jle::Settings;

const double kInf = std::numeric_limits<double>::infinity();
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// Valid settings with one wrench input, one sensor input and one force plate, so that
// the checks of list elements run too.
Settings withInputs() {
  Settings s;
  s.wrenches.resize(2);
  s.estimator.wrenches.resize(2);
  s.wrenches[0].topic = s.estimator.wrenches[0].name = "/tool/wrench";
  s.estimator.wrenches[0].link = "tool0";
  s.wrenches[1].topic = s.estimator.wrenches[1].name = "/ft/wrench";
  s.estimator.wrenches[1].sensor_joint = "ft_joint";  // no link: the joint's child link
  s.force_plates.resize(1);
  s.estimator.plates.resize(1);
  s.force_plates[0].topic = "/plate/wrench";
  s.estimator.plates[0].plate.name = "plate";
  s.estimator.plates[0].plate.link = "foot";
  return s;
}

// The message validate() throws for `s`, or "" if it accepts it.
std::string refusal(const Settings& s) {
  try {
    jle::validate(s);
  } catch (const jle::SettingsError& e) {
    return e.what();
  }
  return "";
}

struct Change {
  const char* key;  // the key the message must name
  std::function<void(Settings&)> apply;
};

// Each change on its own: accepted (`ok`) or refused naming its key.
void expectAll(const std::vector<Change>& changes, bool ok) {
  for (const Change& c : changes) {
    Settings s = withInputs();
    c.apply(s);
    const std::string why = refusal(s);
    if (ok)
      EXPECT_EQ(why, "") << c.key;
    else
      EXPECT_NE(why.find(std::string("parameter '") + c.key + "'"), std::string::npos)
          << c.key << ": '" << why << "'";
  }
}

TEST(Config, DefaultsAreTheNodes) {
  // The differentiator the node runs (docs/how_it_works.md "Differentiators"): the constant-jerk
  // Kalman filter, q = 1e4, r = 1e-4 rad; the adaptive filter's keys default to 0.5 to 50 Hz, the
  // noise estimated, a 1 s likelihood. An Estimator built from EstimatorConfig{} runs the same.
  const jle::DifferentiatorConfig d;
  EXPECT_EQ(d.type, jle::DifferentiatorType::kKalman);
  EXPECT_EQ(d.kalman_model, jle::KalmanModel::kConstantJerk);
  EXPECT_EQ(d.process_noise, 0.0);  // the model's: 1e4 for constant jerk
  EXPECT_EQ(jle::processNoise(d), 1e4);
  EXPECT_EQ(d.measurement_noise, 1e-4);
  EXPECT_EQ(d.lag, 0.0);
  EXPECT_EQ(d.max_gap, 0.5);
  EXPECT_EQ(d.min_bandwidth, 0.5);
  EXPECT_EQ(d.max_bandwidth, 50.0);
  EXPECT_EQ(d.noise, 0.0);
  EXPECT_EQ(d.memory, 1.0);
  const Settings s;
  EXPECT_EQ(s.estimator.differentiator.type, jle::DifferentiatorType::kKalman);
  EXPECT_EQ(s.estimator.decimation, 1);
  EXPECT_EQ(s.estimator.gravity_world, Eigen::Vector3d(0.0, 0.0, -9.80665));
  EXPECT_EQ(s.diagnostic_period, 1.0);
  EXPECT_EQ(s.time_jump_threshold, 1.0);
  EXPECT_EQ(s.tf_wait, 0.05);
  EXPECT_EQ(s.stamps.regularize, jle::StampRegularize::kOff);
  EXPECT_EQ(s.stamps.jump_confirm, 3);
  EXPECT_EQ(s.body_mass, 0.0);
  EXPECT_TRUE(s.estimator.joints.empty());
  EXPECT_TRUE(s.wrenches.empty() && s.force_plates.empty());
  // Element defaults: an F/T sensor's load on the robot, zeroed when stale (held only by
  // choice, for max_hold); a plate zeroed when stale, 20 N of contact threshold.
  const jle::WrenchInputConfig w;
  const jle::WrenchTopicSettings wt;
  EXPECT_EQ(w.sign, 1.0);
  EXPECT_EQ(w.timeout, 0.1);
  EXPECT_EQ(w.stale_policy, jle::StalePolicy::kZero);
  EXPECT_EQ(w.max_hold, 1.0);
  EXPECT_EQ(wt.force_threshold, 5.0);
  EXPECT_EQ(wt.moment_threshold, 0.5);
  const jle::PlateInputConfig p;
  EXPECT_EQ(p.stale_policy, jle::StalePolicy::kZero);
  EXPECT_EQ(p.plate.contact_threshold, 20.0);
  EXPECT_NO_THROW(jle::validate(s));
  EXPECT_NO_THROW(jle::validate(withInputs()));

  const jle::Model<double> ur5 =
      jle::modelFromUrdfFile(std::string(JLE_TEST_DATA) + "/urdf/chains/ur5_chain.urdf");
  const jle::Estimator estimator(ur5, jle::EstimatorConfig{});
  EXPECT_EQ(estimator.config().differentiator.type, jle::DifferentiatorType::kKalman);
  EXPECT_EQ(estimator.config().differentiator.kalman_model, jle::KalmanModel::kConstantJerk);
}

TEST(Config, SettingsErrorIsAnInvalidArgument) {
  // The Estimator's callers catch std::invalid_argument: they catch this too.
  Settings s;
  s.estimator.decimation = 0;
  EXPECT_THROW(jle::validate(s), std::invalid_argument);
  EXPECT_EQ(refusal(s), "parameter 'decimation' must be >= 1, it is 0");
  // The Estimator validates its configuration with the same function.
  const jle::Model<double> ur5 =
      jle::modelFromUrdfFile(std::string(JLE_TEST_DATA) + "/urdf/chains/ur5_chain.urdf");
  jle::EstimatorConfig c;
  c.wrenches.resize(1);
  c.wrenches[0].link = "tool0";
  c.wrenches[0].sign = 0.0;
  try {
    jle::Estimator estimator(ur5, c);
    ADD_FAILURE() << "sign 0 was accepted";
  } catch (const jle::SettingsError& e) {
    EXPECT_EQ(std::string(e.what()), "parameter 'wrenches[0]/sign' must be +1 or -1, it is 0");
  }
  // A link the model does not have: the key path as the user wrote it.
  c.wrenches[0].sign = 1.0;
  c.wrenches.push_back(c.wrenches[0]);
  c.wrenches[1].link = "no_such_link";
  try {
    jle::Estimator estimator(ur5, c);
    ADD_FAILURE() << "an unknown link was accepted";
  } catch (const jle::SettingsError& e) {
    EXPECT_EQ(std::string(e.what()),
              "parameter 'wrenches[1]/link': 'no_such_link' is not a link of the model");
  }
}

TEST(Config, TopLevel) {
  expectAll({{"decimation", [](Settings& s) { s.estimator.decimation = 7; }},
             {"body_mass", [](Settings& s) { s.body_mass = -1.0; }},
             {"body_mass", [](Settings& s) { s.body_mass = 70.0; }},
             {"time_jump_threshold", [](Settings& s) { s.time_jump_threshold = 1e-3; }},
             {"stamps/jump_confirm", [](Settings& s) { s.stamps.jump_confirm = 1; }},
             {"diagnostic_period", [](Settings& s) { s.diagnostic_period = 0.01; }},
             {"tf_wait", [](Settings& s) { s.tf_wait = 0.0; }}},
            true);
  expectAll({{"decimation", [](Settings& s) { s.estimator.decimation = 0; }},
             {"gravity", [](Settings& s) { s.estimator.gravity_world.y() = kNaN; }},
             {"body_mass", [](Settings& s) { s.body_mass = -2.0; }},
             {"body_mass", [](Settings& s) { s.body_mass = kInf; }},
             {"time_jump_threshold", [](Settings& s) { s.time_jump_threshold = 0.0; }},
             {"stamps/jump_confirm", [](Settings& s) { s.stamps.jump_confirm = 0; }},
             {"base_residual_threshold", [](Settings& s) { s.base_residual_threshold = -0.1; }},
             {"still_velocity", [](Settings& s) { s.still_velocity = kNaN; }},
             {"diagnostic_period", [](Settings& s) { s.diagnostic_period = 0.0; }},
             {"diagnostic_period", [](Settings& s) { s.diagnostic_period = kInf; }},
             {"tf_wait", [](Settings& s) { s.tf_wait = -0.01; }},
             {"tf_wait", [](Settings& s) { s.tf_wait = kNaN; }},
             {"joint_states_topic", [](Settings& s) { s.joint_states_topic.clear(); }},
             {"robot_description", [](Settings& s) { s.robot_description.clear(); }},
             {"joints[1]",
              [](Settings& s) {
                s.estimator.joints = {"a", "a"};
              }},
             {"keep_fixed_joints[2]",
              [](Settings& s) {
                s.keep_fixed_joints = {"a", "b", "b"};
              }}},
            false);
}

TEST(Config, Differentiator) {
  auto sg = [](Settings& s) {
    s.estimator.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
  };
  auto kalman = [](Settings& s) {
    s.estimator.differentiator.type = jle::DifferentiatorType::kKalman;
  };
  auto adaptive = [](Settings& s) {
    s.estimator.differentiator.type = jle::DifferentiatorType::kAdaptive;
  };
  expectAll(
      {{"differentiator/order",
        [&](Settings& s) {
          sg(s);
          s.estimator.differentiator.order = 5;
        }},
       {"differentiator/window",
        [&](Settings& s) {
          sg(s);
          s.estimator.differentiator.window = 101;
        }},
       {"differentiator/delay",
        [&](Settings& s) {
          sg(s);
          s.estimator.differentiator.delay = 8;
        }},
       // A Kalman filter has no window: its Savitzky-Golay fields are not checked.
       {"differentiator/order", [](Settings& s) { s.estimator.differentiator.order = 9; }},
       // The adaptive filter's own keys: one bandwidth, a known noise.
       {"differentiator/max_bandwidth",
        [](Settings& s) { s.estimator.differentiator.max_bandwidth = 0.5; }},
       {"differentiator/noise", [](Settings& s) { s.estimator.differentiator.noise = 2e-4; }}},
      true);
  expectAll(
      {{"differentiator/order",
        [&](Settings& s) {
          sg(s);
          s.estimator.differentiator.order = 1;
        }},
       {"differentiator/window",
        [&](Settings& s) {
          sg(s);
          s.estimator.differentiator.window = 2;
        }},
       {"differentiator/delay",
        [&](Settings& s) {
          sg(s);
          s.estimator.differentiator.delay = 9;
        }},
       {"differentiator/process_noise",
        [&](Settings& s) {
          kalman(s);
          s.estimator.differentiator.process_noise = -1.0;
        }},
       {"differentiator/measurement_noise",
        [&](Settings& s) {
          kalman(s);
          s.estimator.differentiator.measurement_noise = kInf;
        }},
       {"differentiator/lag",
        [&](Settings& s) {
          kalman(s);
          s.estimator.differentiator.lag = -0.1;
        }},
       {"differentiator/lag",
        [&](Settings& s) {
          sg(s);
          s.estimator.differentiator.lag = 0.1;
        }},
       {"differentiator/max_gap", [](Settings& s) { s.estimator.differentiator.max_gap = -1.0; }},
       {"differentiator/min_bandwidth",
        [&](Settings& s) {
          adaptive(s);
          s.estimator.differentiator.min_bandwidth = 0.0;
        }},
       {"differentiator/max_bandwidth",
        [&](Settings& s) {
          adaptive(s);
          s.estimator.differentiator.max_bandwidth = 0.1;
        }},
       {"differentiator/noise",
        [&](Settings& s) {
          adaptive(s);
          s.estimator.differentiator.noise = -1e-4;
        }},
       {"differentiator/memory",
        [&](Settings& s) {
          adaptive(s);
          s.estimator.differentiator.memory = kNaN;
        }}},
      false);
}

TEST(Config, Wrenches) {
  expectAll(
      {{"wrenches[0]/sign", [](Settings& s) { s.estimator.wrenches[0].sign = -1.0; }},
       {"wrenches[1]/link", [](Settings& s) { s.estimator.wrenches[1].link = "ft_link"; }},
       {"wrenches[0]/force_noise", [](Settings& s) { s.estimator.wrenches[0].force_noise = 0.5; }}},
      true);
  expectAll(
      {{"wrenches[0]/link", [](Settings& s) { s.estimator.wrenches[0].link.clear(); }},
       {"wrenches[0]/sign", [](Settings& s) { s.estimator.wrenches[0].sign = 0.5; }},
       {"wrenches[1]/timeout", [](Settings& s) { s.estimator.wrenches[1].timeout = 0.0; }},
       {"wrenches[0]/force_noise", [](Settings& s) { s.estimator.wrenches[0].force_noise = -1.0; }},
       {"wrenches[1]/moment_noise",
        [](Settings& s) { s.estimator.wrenches[1].moment_noise = kNaN; }},
       {"wrenches[0]/topic", [](Settings& s) { s.wrenches[0].topic.clear(); }},
       {"wrenches[1]/force_threshold", [](Settings& s) { s.wrenches[1].force_threshold = 0.0; }},
       {"wrenches[0]/moment_threshold", [](Settings& s) { s.wrenches[0].moment_threshold = kInf; }},
       // The topics pair with the inputs by index.
       {"wrenches", [](Settings& s) { s.wrenches.pop_back(); }}},
      false);
}

// The topic settings and the estimator's inputs pair by name: each topic's settings carry
// the name of their input or plate (the reader sets them: a wrench input is named by its
// topic); lists in different orders are refused, naming both. Settings made in code without
// the names pair by index, as before.
TEST(Config, TopicsPairWithTheirInputsByName) {
  Settings s = withInputs();
  EXPECT_EQ(refusal(s), "");  // names left empty: paired by index
  s.wrenches[0].name = "/tool/wrench";
  s.wrenches[1].name = "/ft/wrench";
  EXPECT_EQ(refusal(s), "");
  std::swap(s.wrenches[0], s.wrenches[1]);
  EXPECT_EQ(refusal(s),
            "parameter 'wrenches[0]/name' is '/ft/wrench' in the topic's settings, but "
            "'/tool/wrench' in the input's");
  std::swap(s.estimator.wrenches[0], s.estimator.wrenches[1]);
  EXPECT_EQ(refusal(s), "");
  // Two plates, their topics' settings named.
  s.force_plates.push_back(s.force_plates[0]);
  s.estimator.plates.push_back(s.estimator.plates[0]);
  s.estimator.plates[1].plate.name = "right";
  s.force_plates[1].topic = "/plate/right";
  EXPECT_EQ(refusal(s), "");  // names left empty: paired by index
  s.force_plates[0].name = "plate";
  s.force_plates[1].name = "right";
  EXPECT_EQ(refusal(s), "");
  std::swap(s.force_plates[0], s.force_plates[1]);
  EXPECT_EQ(refusal(s),
            "parameter 'force_plates[0]/name' is 'right' in the topic's settings, but 'plate' in "
            "the plate's");
  // Read from YAML, each pair named alike.
  const Settings read =
      jle::parseSettings(jle::parseYaml("wrenches:\n"
                                        "  - {topic: /a, link: tool0}\n"
                                        "  - {topic: /b, link: tool0}\n"
                                        "force_plates:\n"
                                        "  - {name: left, topic: /l, link: left_foot}\n"
                                        "  - {name: right, topic: /r, link: right_foot}\n"));
  ASSERT_EQ(read.wrenches.size(), 2u);
  ASSERT_EQ(read.force_plates.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(read.estimator.wrenches[k].name, read.wrenches[k].topic);
    EXPECT_EQ(read.wrenches[k].name, read.estimator.wrenches[k].name);
    EXPECT_EQ(read.force_plates[k].name, read.estimator.plates[k].plate.name);
  }
  EXPECT_EQ(read.force_plates[1].name, "right");
}

TEST(Config, ForcePlates) {
  expectAll({{"force_plates[0]/contact_threshold",
              [](Settings& s) { s.estimator.plates[0].plate.contact_threshold = 0.0; }},
             {"force_plates[0]/surface_height",
              [](Settings& s) { s.estimator.plates[0].plate.surface_height = -0.04; }},
             {"force_plates[0]/orientation",
              [](Settings& s) {
                s.estimator.plates[0].plate.R_world_plate = Eigen::Vector3d(1, -1, -1).asDiagonal();
              }}},
            true);
  auto second = [](Settings& s) {
    s.force_plates.push_back(s.force_plates[0]);
    s.estimator.plates.push_back(s.estimator.plates[0]);
  };
  expectAll(
      {{"force_plates[0]/name", [](Settings& s) { s.estimator.plates[0].plate.name.clear(); }},
       {"force_plates[1]/name", second},
       {"force_plates[0]/topic", [](Settings& s) { s.force_plates[0].topic.clear(); }},
       {"force_plates[0]/link", [](Settings& s) { s.estimator.plates[0].plate.link.clear(); }},
       {"force_plates[0]/timeout", [](Settings& s) { s.estimator.plates[0].timeout = -0.1; }},
       {"force_plates[0]/contact_threshold",
        [](Settings& s) { s.estimator.plates[0].plate.contact_threshold = -1.0; }},
       {"force_plates[0]/surface_height",
        [](Settings& s) { s.estimator.plates[0].plate.surface_height = kNaN; }},
       {"force_plates[0]/position",
        [](Settings& s) { s.estimator.plates[0].plate.p_world_plate.x() = kInf; }},
       {"force_plates[0]/orientation",  // a reflection
        [](Settings& s) {
          s.estimator.plates[0].plate.R_world_plate = Eigen::Vector3d(1, 1, -1).asDiagonal();
        }},
       {"force_plates[0]/orientation",  // scaled
        [](Settings& s) { s.estimator.plates[0].plate.R_world_plate *= 2.0; }},
       {"force_plates", [](Settings& s) { s.force_plates.clear(); }}},
      false);
}

TEST(Config, Uncertainty) {
  expectAll({{"uncertainty/period", [](Settings& s) { s.estimator.uncertainty.period = 0.0; }},
             {"uncertainty/position_noise",
              [](Settings& s) { s.estimator.uncertainty.position_noise = 1e-4; }}},
            true);
  expectAll(
      {{"uncertainty/position_noise",
        [](Settings& s) { s.estimator.uncertainty.position_noise = -1e-4; }},
       {"uncertainty/mass_fraction",
        [](Settings& s) { s.estimator.uncertainty.mass_fraction = kNaN; }},
       {"uncertainty/com_offset", [](Settings& s) { s.estimator.uncertainty.com_offset = -0.01; }},
       {"uncertainty/inertia_fraction",
        [](Settings& s) { s.estimator.uncertainty.inertia_fraction = kInf; }},
       {"uncertainty/period", [](Settings& s) { s.estimator.uncertainty.period = -0.018; }},
       {"uncertainty/gain_tolerance",
        [](Settings& s) { s.estimator.uncertainty.gain_tolerance = kInf; }}},
      false);
}

TEST(Config, Savings) {
  expectAll(
      {{"savings/static_velocity", [](Settings& s) { s.estimator.savings.static_velocity = 0.01; }},
       {"savings/static_acceleration",
        [](Settings& s) { s.estimator.savings.static_acceleration = 0.5; }}},
      true);
  expectAll({{"savings/static_velocity",
              [](Settings& s) { s.estimator.savings.static_velocity = -0.01; }},
             {"savings/static_acceleration",
              [](Settings& s) { s.estimator.savings.static_acceleration = kNaN; }}},
            false);
}

}  // namespace
