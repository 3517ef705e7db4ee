// The URDF reader against urdfdom (ROS's own parser, an independent implementation):
// every link's pose at q = 0, mass and inertia must agree on the public models.
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <gtest/gtest.h>
#include <urdf/model.h>

#include <Eigen/Geometry>

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>

namespace {

const std::string kData = JLE_TEST_DATA;

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Eigen::Isometry3d toEigen(const urdf::Pose& p) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() << p.position.x, p.position.y, p.position.z;
  X.linear() =
      Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  return X;
}

class PublicModel : public ::testing::TestWithParam<std::string> {};

TEST_P(PublicModel, AgreesWithUrdfdom) {
  const std::string path = kData + "/urdf/" + GetParam();
  urdf::Model reference;
  ASSERT_TRUE(reference.initString(readFile(path)));
  const jle::Model<double> model = jle::modelFromUrdfFile(path);

  // Masses: the lumped total equals urdfdom's sum over links.
  double total = 0.0;
  for (const auto& kv : reference.links_)
    if (kv.second->inertial) total += kv.second->inertial->mass;
  EXPECT_NEAR(model.totalMass(), total, 1e-12 * total);

  // Every link is a frame, and its pose at q = 0 matches urdfdom's (1e-12 m or rad:
  // a handful of 3x3 products of unit-norm rotations).
  // Pose of every link at q = 0 relative to the root, walked on urdfdom's tree.
  std::map<std::string, Eigen::Isometry3d> poses;
  std::vector<urdf::LinkSharedPtr> links;
  reference.getLinks(links);
  urdf::LinkConstSharedPtr root = reference.getRoot();
  std::function<void(const urdf::LinkConstSharedPtr&, const Eigen::Isometry3d&)> walk =
      [&](const urdf::LinkConstSharedPtr& l, const Eigen::Isometry3d& X) {
        poses[l->name] = X;
        for (const urdf::JointSharedPtr& j : l->child_joints)
          walk(reference.getLink(j->child_link_name),
               X * toEigen(j->parent_to_joint_origin_transform));
      };
  walk(root, Eigen::Isometry3d::Identity());
  ASSERT_EQ(model.frames.size(), links.size());

  jle::Data<double> data(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nq);
  // Mimic offsets would move joints away from urdfdom's q = 0 pose; none of these have one.
  jle::forwardKinematics(model, data, zero, zero, zero, Eigen::Vector3d::Zero().eval());
  for (const jle::Frame<double>& f : model.frames) {
    ASSERT_TRUE(poses.count(f.name)) << f.name;
    const Eigen::Matrix3d R = data.R_world[f.segment] * f.R_segment_frame;
    const Eigen::Vector3d p = data.p_world[f.segment] + data.R_world[f.segment] * f.p_segment_frame;
    EXPECT_LT((R - poses[f.name].linear()).norm(), 1e-12) << f.name;
    EXPECT_LT((p - poses[f.name].translation()).norm(), 1e-12) << f.name;
  }

  // Moving joints: one segment each, with the axis urdfdom reads (normalised) in the
  // child frame.
  int moving = 0;
  for (const auto& kv : reference.joints_) {
    const urdf::JointSharedPtr& j = kv.second;
    if (j->type == urdf::Joint::FIXED) continue;
    ++moving;
    const int s = model.segmentOfJoint(j->name);
    const Eigen::Vector3d axis = Eigen::Vector3d(j->axis.x, j->axis.y, j->axis.z).normalized();
    EXPECT_LT((model.axis[s] - axis).norm(), 1e-15) << j->name;
    EXPECT_EQ(model.link_name[s], j->child_link_name);
    EXPECT_EQ(model.link_name[model.parent[s]] == j->parent_link_name ||
                  model.frames[model.frameIndex(j->parent_link_name)].segment == model.parent[s],
              true)
        << j->name;
  }
  EXPECT_EQ(static_cast<int>(model.moving_segments.size()), moving);
  for (int i = 1; i < model.nsegments(); ++i) EXPECT_LT(model.parent[i], i);
}

INSTANTIATE_TEST_SUITE_P(Models, PublicModel,
                         ::testing::Values("panda.urdf", "ur5_robot.urdf", "kinova.urdf",
                                           "talos_reduced.urdf", "chains/panda_chain.urdf",
                                           "chains/ur5_chain.urdf", "chains/kinova_chain.urdf"));

TEST(UrdfReader, TreeOrderFollowsTheDocument) {
  // Joints listed b before a: the segments follow the document, not the alphabet
  // (urdfdom keeps joints in a std::map, so its order is alphabetical).
  const std::string xml = R"(<robot name="r">
    <link name="base"/>
    <link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <link name="l2"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <joint name="zz_first" type="revolute"><parent link="base"/><child link="l2"/><axis xyz="0 0 1"/></joint>
    <joint name="aa_second" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
  </robot>)";
  const jle::Model<double> model = jle::modelFromUrdfString(xml);
  ASSERT_EQ(model.coordinate_names.size(), 2u);
  EXPECT_EQ(model.coordinate_names[0], "zz_first");
  EXPECT_EQ(model.coordinate_names[1], "aa_second");
}

TEST(UrdfReader, PandaMimicFollowsItsLeader) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/panda.urdf");
  EXPECT_EQ(model.nq, 8);  // 7 arm joints + 1 finger; finger_joint2 mimics finger_joint1
  const int follower = model.segmentOfJoint("panda_finger_joint2");
  const int leader = model.segmentOfJoint("panda_finger_joint1");
  EXPECT_EQ(model.coordinate[follower], model.coordinate[leader]);
  EXPECT_EQ(model.multiplier[follower], 1.0);
  EXPECT_EQ(model.offset[follower], 0.0);
}

TEST(UrdfReader, TalosLoadsWithItsSlightlyUnphysicalInertiaReported) {
  // Talos' gripper motor inertias violate the triangle inequality by 2.5%: accepted
  // with a warning naming the link; a stricter tolerance refuses the model.
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/talos_reduced.urdf");
  ASSERT_FALSE(model.warnings.empty());
  EXPECT_NE(model.warnings[0].find("gripper_left_motor_single_link"), std::string::npos);
  jle::ModelOptions strict;
  strict.triangle_tolerance = 0.01;
  try {
    jle::modelFromUrdfFile(kData + "/urdf/talos_reduced.urdf", strict);
    FAIL() << "strict tolerance accepted the model";
  } catch (const jle::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("gripper_left_motor_single_link"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("talos_reduced.urdf"), std::string::npos);
  }
}

// identified_pendulum.urdf, an identified parameter set's inertias: link 'arm' (principal moments
// -0.05, 0.02, 0.3) is not positive semi-definite and breaks the triangle inequality, link 'hand'
// (0.01, 0.01, 0.1) breaks it by 80%. Refused by default; accepted with
// accept_nonphysical_inertia, each violation a warning naming the link and what it
// affects; the effort about the joint axis y is then the identified model's closed
// form, where neither ixx nor izz enters: tau = (Iyy_arm + Iyy_hand + 2 x 0.5^2 + 1 x
// 1^2) qdd - (2 x 0.5 + 1 x 1) g cos q = 1.81 qdd - 2 g cos q.
const std::string kIdentifiedPendulum = kData + "/urdf/identified_pendulum.urdf";

TEST(UrdfReader, IdentifiedInertiaIsRefusedByDefaultAndAcceptedWithTheOption) {
  try {
    jle::modelFromUrdfFile(kIdentifiedPendulum);
    FAIL() << "a non-physical inertia was accepted by default";
  } catch (const jle::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("link 'arm': inertia is not positive semi-definite"),
              std::string::npos)
        << e.what();
  }
  jle::ModelOptions options;
  options.accept_nonphysical_inertia = true;
  const jle::Model<double> model = jle::modelFromUrdfFile(kIdentifiedPendulum, options);
  const auto warned = [&](const std::string& link, const std::string& violation) {
    for (const std::string& w : model.warnings)
      if (w.find("link '" + link + "': inertia " + violation) != std::string::npos &&
          w.find("are the identified model's") != std::string::npos &&
          w.find("full 3-D force and moment are not physical") != std::string::npos)
        return true;
    return false;
  };
  EXPECT_TRUE(warned("arm", "is not positive semi-definite"));
  EXPECT_TRUE(warned("arm", "violates the triangle inequality"));
  EXPECT_TRUE(warned("hand", "violates the triangle inequality"));
  EXPECT_EQ(model.warnings.size(), 3u);
  constexpr double g = 9.80665;
  for (const double q : {0.0, 0.7, -2.1}) {
    jle::Data<double> data(model);
    jle::VectorX<double> vq(1), vqd(1), vqdd(1);
    vq << q;
    vqd << 1.3;
    vqdd << -0.4;
    jle::forwardKinematics(model, data, vq, vqd, vqdd, Eigen::Vector3d(0.0, 0.0, -g));
    jle::inverseDynamics(model, data);
    // 1e-12: a few products of O(1) numbers.
    EXPECT_NEAR(data.effort[model.segmentOfJoint("shoulder")], 1.81 * -0.4 - 2.0 * g * std::cos(q),
                1e-12)
        << q;
  }
}

TEST(UrdfReader, KeptFixedJointBecomesASegment) {
  jle::ModelOptions options;
  options.keep_fixed_joints = {"panda_hand_joint"};
  const jle::Model<double> lumped = jle::modelFromUrdfFile(kData + "/urdf/panda.urdf");
  const jle::Model<double> kept = jle::modelFromUrdfFile(kData + "/urdf/panda.urdf", options);
  EXPECT_EQ(kept.nsegments(), lumped.nsegments() + 1);
  const int s = kept.segmentOfJoint("panda_hand_joint");
  EXPECT_EQ(kept.joint_type[s], jle::JointType::kFixed);
  EXPECT_NEAR(kept.totalMass(), lumped.totalMass(), 1e-12);
  options.keep_fixed_joints = {"panda_joint1"};
  EXPECT_THROW(jle::modelFromUrdfFile(kData + "/urdf/panda.urdf", options), jle::ModelError);
  options.keep_fixed_joints = {"no_such_joint"};
  EXPECT_THROW(jle::modelFromUrdfFile(kData + "/urdf/panda.urdf", options), jle::ModelError);
}

TEST(UrdfReader, FloatingJointAtTheRootMakesAFloatingBase) {
  const std::string xml = R"(<robot name="r">
    <link name="world"/>
    <link name="body"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <joint name="free" type="floating"><parent link="world"/><child link="body"/></joint>
  </robot>)";
  const jle::Model<double> model = jle::modelFromUrdfString(xml);
  EXPECT_TRUE(model.floating_base);
  EXPECT_EQ(model.nsegments(), 1);
  EXPECT_EQ(model.link_name[0], "body");
  EXPECT_EQ(model.joint_type[0], jle::JointType::kFloating);
}

// A link of mass 0 with a nonzero inertia is taken as given, and said (Model::warnings,
// logged by the node and the tools at load); a massless link without inertia is not.
TEST(UrdfReader, MassZeroWithANonzeroInertiaIsWarned) {
  const std::string xml = R"(<robot name="r">
    <link name="base"/>
    <link name="l1"><inertial><mass value="0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial></link>
    <link name="l2"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
    <link name="l3"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
    <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/></joint>
    <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><axis xyz="0 0 1"/></joint>
  </robot>)";
  const jle::Model<double> model = jle::modelFromUrdfString(xml);
  ASSERT_EQ(model.warnings.size(), 1u);
  EXPECT_NE(model.warnings[0].find("link 'l1': mass 0 with a nonzero inertia (ixx 0.01, iyy "
                                   "0.02, izz 0.03 kg m^2)"),
            std::string::npos)
      << model.warnings[0];
}

// <limit>: the position bounds of a revolute or prismatic joint, none for a continuous
// one (its lower and upper are ignored); velocity and effort where positive.
TEST(UrdfReader, JointLimitsAreRead) {
  const std::string xml = R"(<robot name="r">
    <link name="base"/>
    <link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <link name="l2"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <link name="l3"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <joint name="r" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
      <limit lower="-1.5" upper="2" velocity="3" effort="40"/></joint>
    <joint name="c" type="continuous"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/>
      <limit lower="-1" upper="1" velocity="0" effort="10"/></joint>
    <joint name="n" type="revolute"><parent link="l2"/><child link="l3"/><axis xyz="0 0 1"/></joint>
  </robot>)";
  const jle::Model<double> model = jle::modelFromUrdfString(xml);
  const double inf = std::numeric_limits<double>::infinity();
  const auto s = [&](const char* joint) {
    return static_cast<std::size_t>(model.segmentOfJoint(joint));
  };
  EXPECT_EQ(model.lower_limit[s("r")], -1.5);
  EXPECT_EQ(model.upper_limit[s("r")], 2.0);
  EXPECT_EQ(model.velocity_limit[s("r")], 3.0);
  EXPECT_EQ(model.effort_limit[s("r")], 40.0);
  EXPECT_EQ(model.lower_limit[s("c")], -inf);
  EXPECT_EQ(model.upper_limit[s("c")], inf);
  EXPECT_EQ(model.velocity_limit[s("c")], inf);  // 0: none
  EXPECT_EQ(model.effort_limit[s("c")], 10.0);
  EXPECT_EQ(model.lower_limit[s("n")], -inf);  // no <limit>
  EXPECT_EQ(model.velocity_limit[s("n")], inf);
  EXPECT_EQ(model.effort_limit[s("n")], inf);
}

TEST(UrdfReader, MissingFileNamesThePath) {
  try {
    jle::modelFromUrdfFile("/nonexistent/robot.urdf");
    FAIL();
  } catch (const jle::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/robot.urdf"), std::string::npos);
  }
}

}  // namespace
