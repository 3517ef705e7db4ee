// Force plates in the settings (force_plates, body_mass: parsed, validated, errors
// naming the key) and in process_bag (the plate pose from the config; effort_per_kg),
// against the hand-worked numbers of test/rostest/test_plates.cpp.
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/settings/settings_reader.hpp>

#include <geometry_msgs/WrenchStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;

const std::string kFoot = std::string(JLE_ROSTEST_DIR) + "/standing_foot.urdf";

jle::ParamValue yaml(const std::string& text, const fs::path& dir) {
  const fs::path p = dir / "settings.yaml";
  std::ofstream(p) << text;
  return jle::loadYaml(p.string());
}

class PlatesOffline : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("jle_plates_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // The settings error of `text`, or "" if it parses.
  std::string error(const std::string& text) {
    try {
      jle::parseSettings(yaml(text, dir_));
    } catch (const jle::SettingsError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

const char* const kPlate = R"(body_mass: 70
force_plates:
  - name: plate1
    topic: /force_plate_1/wrench
    frame: force_plate_1
    link: foot
    surface_height: 0.04
    contact_threshold: 20.0
    timeout: 0.5
    stale_policy: hold
    position: [0.3, 0.2, -0.04]
    orientation: [0, 0, 1, 1]
)";

TEST_F(PlatesOffline, SettingsParsed) {
  const jle::Settings s = jle::parseSettings(yaml(kPlate, dir_));
  ASSERT_EQ(s.force_plates.size(), 1u);
  ASSERT_EQ(s.estimator.plates.size(), 1u);
  const jle::PlateTopicSettings& p = s.force_plates[0];
  const jle::PlateInputConfig& input = s.estimator.plates[0];
  EXPECT_EQ(input.plate.name, "plate1");
  EXPECT_EQ(p.topic, "/force_plate_1/wrench");
  EXPECT_EQ(p.frame, "force_plate_1");
  EXPECT_EQ(input.plate.link, "foot");
  EXPECT_EQ(input.plate.surface_height, 0.04);
  EXPECT_EQ(input.plate.contact_threshold, 20.0);
  EXPECT_EQ(input.timeout, 0.5);
  EXPECT_EQ(input.stale_policy, jle::StalePolicy::kHold);
  EXPECT_TRUE(p.pose_configured);
  EXPECT_EQ(input.plate.p_world_plate, Eigen::Vector3d(0.3, 0.2, -0.04));
  // [0, 0, 1, 1] normalised: 90 degrees about z, x -> y (exact to rounding, 1e-15).
  EXPECT_NEAR(
      (input.plate.R_world_plate * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0,
      1e-15);
  EXPECT_EQ(s.body_mass, 70.0);

  // Defaults: zero policy, 20 N, 0.1 s, no pose (tf2), body_mass 0.
  const jle::Settings d =
      jle::parseSettings(yaml("force_plates: [{name: a, topic: t, link: foot}]", dir_));
  EXPECT_EQ(d.estimator.plates[0].stale_policy, jle::StalePolicy::kZero);
  EXPECT_EQ(d.estimator.plates[0].plate.contact_threshold, 20.0);
  EXPECT_EQ(d.estimator.plates[0].timeout, 0.1);
  EXPECT_FALSE(d.force_plates[0].pose_configured);
  EXPECT_EQ(d.body_mass, 0.0);
  EXPECT_EQ(jle::parseSettings(yaml("body_mass: -1", dir_)).body_mass, -1.0);
}

TEST_F(PlatesOffline, SettingsErrorsNameTheKey) {
  auto expectError = [&](const std::string& text, const std::string& key) {
    const std::string e = error(text);
    EXPECT_NE(e.find(key), std::string::npos) << "'" << e << "' for: " << text;
  };
  expectError("force_plates: [{topic: t, link: foot}]", "'force_plates[0]/name'");
  expectError("force_plates: [{name: a, link: foot}]", "'force_plates[0]/topic'");
  expectError("force_plates: [{name: a, topic: t}]", "'force_plates[0]/link'");
  expectError("force_plates: [{name: a, topic: t, link: foot}, {name: a, topic: u, link: foot}]",
              "'force_plates[1]/name'");
  expectError("force_plates: [{name: a, topic: t, link: foot, sign: -1}]",
              "'force_plates[0]/sign'");
  expectError("force_plates: [{name: a, topic: t, link: foot, contact_threshold: -1}]",
              "'force_plates[0]/contact_threshold'");
  expectError("force_plates: [{name: a, topic: t, link: foot, timeout: 0}]",
              "'force_plates[0]/timeout'");
  expectError("force_plates: [{name: a, topic: t, link: foot, stale_policy: keep}]",
              "'force_plates[0]/stale_policy'");
  expectError("force_plates: [{name: a, topic: t, link: foot, position: [1, 2]}]",
              "'force_plates[0]/position'");
  expectError("force_plates: [{name: a, topic: t, link: foot, orientation: [0, 0, 0, 0]}]",
              "'force_plates[0]/orientation'");
  expectError("force_plates: {name: a}", "'force_plates'");
  expectError("body_mass: -2", "'body_mass'");
  expectError("body_mass: heavy", "'body_mass'");
}

// process_bag over a bag of a foot at rest on the plate (contact, then 15 N below the
// threshold): the hand-worked ankle effort 30.5096675 N m in contact, 2.1896675 N m below
// the threshold (test_plates.cpp: the 15 N reading acts as measured, without a COP), and
// effort_per_kg = effort / 70.
TEST_F(PlatesOffline, ProcessBagAppliesThePlateWithItsConfiguredPose) {
  {
    rosbag::Bag bag(path("in.bag"), rosbag::bagmode::Write);
    for (int k = 0; k < 40; ++k) {
      const ros::Time t(100, 1000000 * k);
      geometry_msgs::WrenchStamped w;
      w.header.stamp = t;
      w.header.frame_id = "force_plate_1";
      const bool contact = k < 20;
      w.wrench.force.x = contact ? 50.0 : 1.0;
      w.wrench.force.y = contact ? -30.0 : 0.0;
      w.wrench.force.z = contact ? -700.0 : -15.0;
      w.wrench.torque.x = contact ? 134.2 : 0.3;
      w.wrench.torque.y = contact ? -103.0 : -0.2;
      w.wrench.torque.z = contact ? 16.0 : 0.0;
      // Recorded 0.1 ms before the joint state of the same stamp (a bag orders equal
      // times by connection, not by writing).
      bag.write("/force_plate_1/wrench", t - ros::Duration(0, 100000), w);
      sensor_msgs::JointState js;
      js.header.stamp = t;
      js.name = {"ankle"};
      js.position = {0.0};
      bag.write("/joint_states", t, js);
    }
  }
  std::ofstream(path("config.yaml"))
      << "differentiator: {type: finite_difference}\nbody_mass: 70\nforce_plates:\n"
         "  - {name: plate1, topic: /force_plate_1/wrench, link: foot, surface_height: 0.04,\n"
         "     timeout: 1.0, position: [0.3, 0.2, -0.04]}\n";
  const std::string command = std::string(JLE_PROCESS_BAG) + " --bag " + path("in.bag") +
                              " --urdf " + kFoot + " --config " + path("config.yaml") +
                              " --output " + path("out.bag") + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  rosbag::Bag out(path("out.bag"), rosbag::bagmode::Read);
  int contact = 0, swing = 0;
  // The immediate stream (the smoothed one, PREFIX/smoothed/joint_loads, is checked by
  // test_process_bag).
  for (const rosbag::MessageInstance& m :
       rosbag::View(out, rosbag::TopicQuery("/joint_load_estimator/joint_loads"))) {
    const auto loads = m.instantiate<joint_load_estimator::JointLoads>();
    ASSERT_TRUE(loads);
    ASSERT_EQ(loads->effort.size(), 1u);
    ASSERT_EQ(loads->effort_per_kg.size(), 1u);
    const double s = (loads->header.stamp - ros::Time(100, 0)).toSec();
    const int k = static_cast<int>(std::lround(s * 1000.0));
    // Constant inputs, q = 0: rounding only, 1e-12 of 30 N m.
    const double expected = k < 20 ? 30.5096675 : 2.1896675;
    EXPECT_NEAR(loads->effort[0], expected, 1e-10) << k;
    EXPECT_NEAR(loads->effort_per_kg[0], loads->effort[0] / 70.0, 1e-15) << k;
    ++(k < 20 ? contact : swing);
  }
  EXPECT_EQ(contact, 18);  // samples 2..19 after the 3-point warm-up
  EXPECT_EQ(swing, 20);

  // Without a configured pose there is no tf2 to ask: refused, naming the plate.
  std::ofstream(path("tf.yaml")) << "force_plates: [{name: plate1, topic: /force_plate_1/wrench, "
                                    "link: foot}]\n";
  const std::string refused = std::string(JLE_PROCESS_BAG) + " --bag " + path("in.bag") +
                              " --urdf " + kFoot + " --config " + path("tf.yaml") + " --csv " +
                              path("o.csv") + " > " + path("log.txt") + " 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(refused.c_str())), 1);
  std::ifstream log(path("log.txt"));
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("'plate1'"), std::string::npos) << text;
  EXPECT_NE(text.find("position/orientation"), std::string::npos) << text;
}

}  // namespace
