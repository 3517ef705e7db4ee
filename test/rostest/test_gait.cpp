// The gait demo's check, on the real node (gait.test, config/gait_demo.yaml): a walking
// trial of the bundled body over two force plates (make_gait_bag) is played through the
// node. The plates were computed so that they explain the motion; the pelvis residual the
// node publishes must therefore stay within what the filters cost, and every joint must
// get its loads.
#include "node_test_common.hpp"

#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <geometry_msgs/WrenchStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using joint_load_estimator::JointLoads;

constexpr double kGravity = 9.80665;

TEST(Gait, ResidualIsFilterErrorAndEveryJointIsLoaded) {
  const std::string urdf = std::string(JLE_TEST_DATA) + "/urdf/body_75kg_175cm.urdf";
  char dir_template[] = "/tmp/jle_gait_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::string bag = std::string(dir_template) + "/gait.bag";
  ASSERT_EQ(jle_test::runSpinning({JLE_MAKE_GAIT_BAG, "--urdf", urdf, "--output", bag}, 60.0), 0);

  jle::ModelOptions options;
  options.floating_base = true;
  const jle::Model<double> model = jle::modelFromUrdfFile(urdf, options);
  const double weight = model.totalMass() * kGravity;
  std::vector<std::string> joints;
  for (int s : model.moving_segments)
    joints.push_back(model.joint_name[static_cast<std::size_t>(s)]);
  ASSERT_EQ(joints.size(), 10u);  // hip x3, knee, ankle per side

  ros::NodeHandle nh;
  std::vector<JointLoads> loads;
  std::vector<geometry_msgs::WrenchStamped> residuals;
  ros::Subscriber loads_sub =
      nh.subscribe<JointLoads>("/joint_load_estimator/joint_loads", 10000,
                               [&loads](const JointLoads::ConstPtr& m) { loads.push_back(*m); });
  ros::Subscriber residual_sub = nh.subscribe<geometry_msgs::WrenchStamped>(
      "/joint_load_estimator/base_residual", 10000,
      [&residuals](const geometry_msgs::WrenchStamped::ConstPtr& m) { residuals.push_back(*m); });
  jle_test::DiagnosticsRecorder& diagnostics = jle_test::diagnostics();
  // The node is up and connected to us (base_residual is published only while heard).
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(30.0);
  while (ros::ok() && (loads_sub.getNumPublishers() == 0 || residual_sub.getNumPublishers() == 0) &&
         ros::WallTime::now() < end) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_EQ(residual_sub.getNumPublishers(), 1u);

  // rosbag play waits until the node listens to every input topic, then plays at the
  // bag's pace, driving /clock.
  ASSERT_EQ(jle_test::runSpinning({"rosbag", "play", "--clock", "--quiet", "--wait-for-subscribers",
                                   bag, "--topics", "/joint_states", "/tf", "/tf_static",
                                   "/force_plate_1/wrench", "/force_plate_2/wrench"},
                                  60.0),
            0);
  // The last messages in flight: until nothing new arrives for 1 s.
  jle_test::spinUntilQuiet([&] { return loads.size() + residuals.size(); });

  // What the node did with them, from its diagnostics once they count every joint state
  // sent (bag order: the poses 2 ms before their joint state; over ROS, tf2's listener
  // thread may deliver one later: the node waits for it, tf_wait).
  const std::string status = "joint_load_estimator: joint loads";
  EXPECT_TRUE(jle_test::waitFor(
      [&] { return diagnostics.latest(status, "joint states received") == 630; }, 10.0));
  const long no_pose = diagnostics.latest(status, "dropped: no base pose");
  std::printf(
      "gait: %ld joint states received, %ld dropped for no base pose, %ld tf waits, %ld "
      "run out\n",
      diagnostics.latest(status, "joint states received"), no_pose,
      diagnostics.latest(status, "tf waits (for a late transform)"),
      diagnostics.latest(status, "tf waits run out"));
  RecordProperty("dropped_no_base_pose", std::to_string(no_pose));

  // 3 strides of 1.05 s at 200 Hz = 630 joint states; decimation 2 gives 315 estimates
  // less the filter's start (10 samples). Messages are not dropped (queues of 10000).
  EXPECT_GE(loads.size(), 290u);
  EXPECT_GE(residuals.size(), 290u);
  for (const JointLoads& m : loads) {
    ASSERT_EQ(m.name, joints);
    ASSERT_EQ(m.effort.size(), joints.size());
    for (std::size_t j = 0; j < joints.size(); ++j)
      ASSERT_TRUE(std::isfinite(m.effort[j])) << m.name[j];
  }
  // The loads are the walking body's: the stance hip carries a peak moment of the order
  // of 1 N m/kg, far from 0 (no plate) and from what a missing plate would leave.
  double peak_hip = 0.0;
  for (const JointLoads& m : loads)
    for (std::size_t j = 0; j < joints.size(); ++j)
      if (joints[j].rfind("hip_flexion", 0) == 0)
        peak_hip = std::max(peak_hip, std::abs(m.effort[j]));
  EXPECT_GT(peak_hip / model.totalMass(), 0.3);

  // The residual. Without the plates it would be the body weight (735 N) and more; with
  // them it is what the filters cost, bounded by:
  // - the contact threshold (20 N): at each foot's loading and unloading the plate's force
  //   ramps from 0 (a quintic smooth step over the 105 ms of double support); below the
  //   threshold (for about 15 ms) the node applies the raw force, unfiltered while the
  //   kinematics are filtered (a mismatch of at most the 20 N);
  // - the truncation error of the centred cubic Savitzky-Golay fit over 11 samples at
  //   200 Hz (h = 5 ms): its second derivative misses 2.08 h^2 x'''' (the least-squares
  //   quadratic coefficient of t^4 over k = -5..5 is 25 h^2), i.e. 5.2e-5 s^2 x''''; the
  //   swing leg (its angles on smooth curves joined to the stance with their angle,
  //   velocity and acceleration: in single support, where it and the pelvis are what
  //   the fit can miss, tools/gait_demo.sh measured 5.4 N at most for both: 5 N), the
  //   heel rocker (24 deg in 105 ms: 1.3e6 rad/s^4, 6.7 m/s^2 on the 1.1 kg foot 0.1 m
  //   from the ankle: 7 N), the pelvis (50.9 kg; its horizontal path is solved for the
  //   centre of pressure: |x''''| <= 6.3e3 m/s^4, measured on the exact accelerations of
  //   make_gait_bag --csv) 0.33 m/s^2: 17 N; each plate signal, a sum of those
  //   accelerations, is filtered alike and contributes errors of the same size.
  //   Together up to about 29 N (5 + 7 + 17);
  // so 40 N (5.4 % of body weight). The moment about the pelvis origin: the same forces
  // at the feet, up to 1 m below the pelvis: 40 N m.
  double max_force = 0.0, max_moment = 0.0;
  for (const geometry_msgs::WrenchStamped& r : residuals) {
    const auto& f = r.wrench.force;
    const auto& m = r.wrench.torque;
    max_force = std::max(max_force, std::sqrt(f.x * f.x + f.y * f.y + f.z * f.z));
    max_moment = std::max(max_moment, std::sqrt(m.x * m.x + m.y * m.y + m.z * m.z));
  }
  RecordProperty("max_residual_force_N", std::to_string(max_force));
  RecordProperty("max_residual_moment_Nm", std::to_string(max_moment));
  std::printf("gait: %zu loads, max residual %.2f N (%.2f %% of body weight), %.2f N m\n",
              loads.size(), max_force, 100.0 * max_force / weight, max_moment);
  EXPECT_LT(max_force, 40.0);
  EXPECT_LT(max_moment, 40.0);

  std::remove(bag.c_str());
  rmdir(dir_template);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_gait");
  ros::NodeHandle nh;  // keeps the node alive for the test
  return RUN_ALL_TESTS();
}
