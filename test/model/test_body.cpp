// make_body_urdf and the human lower-body model it writes: the bundled model is what the
// tool writes today; masses, centres of mass and inertias are the table fractions
// (Winter 2009 Table 4.1, Drillis & Contini via Winter Fig. 4.1) times body mass and
// height, worked here; the joint axes turn the segments the anatomical way; the tool
// refuses bad options with the documented exit status; and a body standing still on
// two force plates is in equilibrium with the joint loads worked by hand.
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/force_plate.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/planar.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/tool_test.hpp>

#include <gtest/gtest.h>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Eigen::Matrix3d;
using Eigen::Vector3d;

const std::string kData = JLE_TEST_DATA;
const std::string kBundled = kData + "/urdf/body_75kg_175cm.urdf";
constexpr double kMass = 75.0, kHeight = 1.75;  // the bundled model's
constexpr double kG = 9.80665;
constexpr double kPi = 3.14159265358979323846;

// The tables, typed from the book (not from the tool).
// Winter (2009) Table 4.1: mass / body mass, COM from proximal / length, radius of
// gyration about the COM / length.
constexpr double kThighMass = 0.100, kThighCom = 0.433, kThighGyration = 0.323;
constexpr double kShankMass = 0.0465, kShankCom = 0.433, kShankGyration = 0.302;
constexpr double kFootMass = 0.0145, kFootGyration = 0.475;  // COM at 0.50
constexpr double kHatMass = 0.678, kHatCom = 0.626;
// Drillis & Contini (Winter Fig. 4.1), fractions of height.
constexpr double kThighLength = 0.245, kShankLength = 0.246, kAnkleHeight = 0.039,
                 kFootLength = 0.152, kHatLength = 0.818 - 0.530;
// Hara et al. (2016), Sci. Rep. 6, 37707, on leg length LL (ASIS to medial malleolus)
// alone: each hip joint centre 8 mm + 0.086 LL lateral of the mid-ASIS and 9 mm +
// 0.078 LL below it; LL = hip-to-ankle + that drop (docs/body_model.md A4).
double hipSpacing(double hip_to_ankle) {
  const double leg_length = (hip_to_ankle + 0.009) / (1.0 - 0.078);
  return 2.0 * (0.008 + 0.086 * leg_length);
}

using jle_test::Result;
using jle_test::readFile;

class BodyTool : public jle_test::ToolTest {
 protected:
  BodyTool() : ToolTest("jle_test_body") {}

  Result run(const std::vector<std::string>& args) const {
    return ToolTest::run(JLE_MAKE_BODY_URDF, args);
  }
  // The model the tool writes for `args`; fails the test if the tool fails.
  jle::Model<double> generate(std::vector<std::string> args, bool floating = false) const {
    args.insert(args.end(), {"--output", path("out/body.urdf")});
    const Result r = run(args);
    EXPECT_EQ(r.status, 0) << r.err;
    jle::ModelOptions options;
    options.floating_base = floating;
    return jle::modelFromUrdfFile(path("out/body.urdf"), options);
  }
};

jle::Model<double> bundled(bool floating = false) {
  jle::ModelOptions options;
  options.floating_base = floating;
  return jle::modelFromUrdfFile(kBundled, options);
}

// World position of the origin of URDF link `link` after forwardKinematics.
Vector3d linkWorld(const jle::Model<double>& model, const jle::Data<double>& data,
                   const std::string& link) {
  const jle::Frame<double>& f = model.frames[model.frameIndex(link)];
  return data.p_world[f.segment] + data.R_world[f.segment] * f.p_segment_frame;
}

// Fixed-base kinematics at q = 0 except `joint` = angle_deg.
jle::Data<double> pose(const jle::Model<double>& model, const std::string& joint,
                       double angle_deg) {
  jle::Data<double> data(model);
  jle::VectorX<double> q = jle::VectorX<double>::Zero(model.nq);
  const jle::VectorX<double> zero = jle::VectorX<double>::Zero(model.nq);
  if (!joint.empty()) {
    const int s = model.segmentOfJoint(joint);
    q[model.coordinate[s]] = angle_deg * kPi / 180.0;
  }
  jle::forwardKinematics(model, data, q, zero, zero, Vector3d(0.0, 0.0, -kG));
  return data;
}

// ------------------------------------------------------------------- the file itself

TEST_F(BodyTool, RegeneratesTheBundledModelByteForByte) {
  const Result r = run({"--mass", "75", "--height", "1.75", "--output", path("out/b.urdf")});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string bundled_text = readFile(kBundled);
  ASSERT_FALSE(bundled_text.empty()) << kBundled;
  EXPECT_TRUE(readFile(path("out/b.urdf")) == bundled_text)
      << "test/data/urdf/body_75kg_175cm.urdf is not what make_body_urdf --mass 75 "
         "--height 1.75 writes today: regenerate it (test/data/urdf/SOURCE.md)";
  // Standard output carries the same text.
  EXPECT_TRUE(run({"--mass", "75", "--height", "1.75"}).out == bundled_text);
}

TEST(Body, NamesAndCoordinates) {
  const jle::Model<double> model = bundled();
  EXPECT_EQ(model.link_name[0], "pelvis");
  EXPECT_EQ(model.nq, 10);
  for (const char* side : {"r", "l"}) {
    const std::string s = side;
    for (const char* j :
         {"hip_flexion_", "hip_adduction_", "hip_rotation_", "knee_flexion_", "ankle_flexion_"})
      EXPECT_NO_THROW(model.segmentOfJoint(j + s)) << j << s;
    for (const char* l : {"femur_", "tibia_", "foot_", "heel_", "toe_"})
      EXPECT_NO_THROW(model.frameIndex(l + s)) << l << s;
  }
  EXPECT_TRUE(model.warnings.empty());
}

// ------------------------------------------------------------- masses, COMs, inertia

// Masses are table fraction x body mass; the pelvis carries the HAT, 0.678 M, and
// 0.678 + 2 (0.100 + 0.0465 + 0.0145) = 1 (relative 1e-12: a sum of a few doubles).
TEST(Body, MassesAndCentresOfMassAreTheTableFractions) {
  const jle::Model<double> model = bundled();
  EXPECT_NEAR(model.totalMass(), kMass, 1e-12 * kMass);
  const double tol = 1e-12;  // [kg, m] products of two decimals, printed shortest round-trip
  EXPECT_NEAR(model.mass[0], kHatMass * kMass, tol);  // 50.85
  EXPECT_NEAR(model.com[0].z(), kHatCom * kHatLength * kHeight, tol);
  const double lf = kFootLength * kHeight, hf = kAnkleHeight * kHeight;
  for (const char* side : {"r", "l"}) {
    const std::string s = side;
    const int femur = model.segmentOfJoint("hip_rotation_" + s);
    const int tibia = model.segmentOfJoint("knee_flexion_" + s);
    const int foot = model.segmentOfJoint("ankle_flexion_" + s);
    EXPECT_NEAR(model.mass[femur], kThighMass * kMass, tol);  // 7.5 kg
    EXPECT_NEAR(model.mass[tibia], kShankMass * kMass, tol);  // 3.4875 kg
    EXPECT_NEAR(model.mass[foot], kFootMass * kMass, tol);    // 1.0875 kg
    EXPECT_EQ(model.mass[model.segmentOfJoint("hip_flexion_" + s)], 0.0);
    EXPECT_EQ(model.mass[model.segmentOfJoint("hip_adduction_" + s)], 0.0);
    EXPECT_LT((model.com[femur] - Vector3d(0, 0, -kThighCom * kThighLength * kHeight)).norm(), tol);
    EXPECT_LT((model.com[tibia] - Vector3d(0, 0, -kShankCom * kShankLength * kHeight)).norm(), tol);
    // Foot: halfway from the ankle to the head of metatarsal II, on the sole half the
    // foot length ahead of the ankle (docs/body_model.md, A3): (0.25 lf, 0, -hf / 2).
    EXPECT_LT((model.com[foot] - Vector3d(0.25 * lf, 0, -0.5 * hf)).norm(), tol);
  }
}

// Radius of gyration 0.323 L across the thigh; along it 0.323 x 14.9 / 32.9 L (de Leva
// 1996, assumption A2). Every segment's inertia is positive definite and satisfies the
// triangle inequality.
TEST(Body, InertiasFromTheRadiiOfGyration) {
  const jle::Model<double> model = bundled();
  const double lt = kThighLength * kHeight, ls = kShankLength * kHeight;
  const int femur = model.segmentOfJoint("hip_rotation_r");
  const int tibia = model.segmentOfJoint("knee_flexion_r");
  const int foot = model.segmentOfJoint("ankle_flexion_r");
  const double mt = kThighMass * kMass, ms = kShankMass * kMass, mf = kFootMass * kMass;
  const double tol = 1e-14;  // [kg m^2] on values of 0.01 .. 0.15
  const Matrix3d& it = model.inertia_com[femur];
  EXPECT_NEAR(it(0, 0), mt * std::pow(kThighGyration * lt, 2), tol);  // 0.14384
  EXPECT_NEAR(it(1, 1), mt * std::pow(kThighGyration * lt, 2), tol);
  EXPECT_NEAR(it(2, 2), mt * std::pow(kThighGyration * 14.9 / 32.9 * lt, 2), tol);
  EXPECT_NEAR(model.inertia_com[tibia](1, 1), ms * std::pow(kShankGyration * ls, 2), tol);
  EXPECT_NEAR(model.inertia_com[tibia](2, 2), ms * std::pow(kShankGyration * 10.3 / 25.5 * ls, 2),
              tol);
  // Foot: its long axis runs from the ankle to (0.5 lf, 0, -hf); across it (about y)
  // the transverse radius, along it the longitudinal one.
  const Vector3d axis(0.5 * kFootLength * kHeight, 0.0, -kAnkleHeight * kHeight);
  const double lfoot = axis.norm();
  const Vector3d u = axis / lfoot;
  const Matrix3d& iff = model.inertia_com[foot];
  EXPECT_NEAR(iff(1, 1), mf * std::pow(kFootGyration * lfoot, 2), tol);
  EXPECT_NEAR(u.dot(iff * u), mf * std::pow(kFootGyration * 12.4 / 25.7 * lfoot, 2), tol);

  for (int i = 0; i < model.nsegments(); ++i) {
    if (model.mass[i] == 0.0) continue;
    const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(model.inertia_com[i]);
    const Vector3d p = eig.eigenvalues();  // ascending
    EXPECT_GT(p[0], 0.0) << model.link_name[i];
    EXPECT_LE(p[2], p[0] + p[1]) << model.link_name[i];
  }
}

// ------------------------------------------------------------------ geometry, axes

TEST(Body, StandingGeometryAtZero) {
  const jle::Model<double> model = bundled();
  const jle::Data<double> data = pose(model, "", 0.0);
  const double lt = kThighLength * kHeight, ls = kShankLength * kHeight;
  const double lf = kFootLength * kHeight, hf = kAnkleHeight * kHeight;
  const double w = hipSpacing(lt + ls);
  // For 1.75 m by hand: LL = (0.85925 + 0.009) / 0.922 = 0.94170 m, 2 (0.008 + 0.086 LL).
  EXPECT_NEAR(w, 0.17797, 1e-5);
  const double tol = 1e-14;  // [m] sums of a few lengths under 1 m
  for (const double side : {1.0, -1.0}) {
    const std::string s = side > 0 ? "r" : "l";
    const Vector3d hip(0.0, -side * 0.5 * w, 0.0);
    EXPECT_LT((linkWorld(model, data, "femur_" + s) - hip).norm(), tol);
    EXPECT_LT((linkWorld(model, data, "tibia_" + s) - (hip + Vector3d(0, 0, -lt))).norm(), tol);
    const Vector3d ankle = hip + Vector3d(0, 0, -lt - ls);
    EXPECT_LT((linkWorld(model, data, "foot_" + s) - ankle).norm(), tol);
    EXPECT_LT((linkWorld(model, data, "heel_" + s) - (ankle + Vector3d(-0.25 * lf, 0, -hf))).norm(),
              tol);
    EXPECT_LT((linkWorld(model, data, "toe_" + s) - (ankle + Vector3d(0.75 * lf, 0, -hf))).norm(),
              tol);
    // Soles at 0.530 H below the pelvis origin (the hip height of Fig. 4.1).
    EXPECT_NEAR(linkWorld(model, data, "heel_" + s).z(), -0.530 * kHeight, tol);
  }
}

// +10 deg at one joint, the rest at zero; the displacement worked for a rotation of
// 10 deg about the joint: a point at distance d moves by d sin 10 deg across.
TEST(Body, PositiveAnglesAreTheAnatomicalDirections) {
  const jle::Model<double> model = bundled();
  const double lt = kThighLength * kHeight, ls = kShankLength * kHeight;
  const double lf = kFootLength * kHeight, hf = kAnkleHeight * kHeight;
  const double s10 = std::sin(10.0 * kPi / 180.0), c10 = std::cos(10.0 * kPi / 180.0);
  const double tol = 1e-14;
  const jle::Data<double> rest = pose(model, "", 0.0);
  const auto moved = [&](const std::string& joint, const std::string& link) {
    return Vector3d(linkWorld(model, pose(model, joint, 10.0), link) -
                    linkWorld(model, rest, link));
  };
  for (const double side : {1.0, -1.0}) {
    const std::string s = side > 0 ? "r" : "l";
    // Hip flexion moves the knee forward (+x) on both sides.
    EXPECT_NEAR(moved("hip_flexion_" + s, "tibia_" + s).x(), lt * s10, tol);
    // Adduction moves the knee toward the midline: +y for the right, -y for the left.
    EXPECT_NEAR(moved("hip_adduction_" + s, "tibia_" + s).y(), side * lt * s10, tol);
    // Internal rotation turns the toe (0.75 lf ahead of the hip axis) medially.
    EXPECT_NEAR(moved("hip_rotation_" + s, "toe_" + s).y(), side * 0.75 * lf * s10, tol);
    // Knee flexion moves the ankle back.
    EXPECT_NEAR(moved("knee_flexion_" + s, "foot_" + s).x(), -ls * s10, tol);
    // Dorsiflexion raises the toe: (0.75 lf, -hf) turned by 10 deg toward +z.
    EXPECT_NEAR(moved("ankle_flexion_" + s, "toe_" + s).z(), 0.75 * lf * s10 - hf * c10 + hf, tol);
    EXPECT_GT(moved("ankle_flexion_" + s, "toe_" + s).z(), 0.0);
  }
}

TEST_F(BodyTool, SubtalarJointTurnsTheSoleMedially) {
  const jle::Model<double> model = generate({"--mass", "75", "--height", "1.75", "--subtalar"});
  EXPECT_EQ(model.nq, 12);
  EXPECT_NEAR(model.totalMass(), kMass, 1e-12 * kMass);
  const double hf = kAnkleHeight * kHeight;
  const double s10 = std::sin(10.0 * kPi / 180.0);
  for (const double side : {1.0, -1.0}) {
    const std::string s = side > 0 ? "r" : "l";
    EXPECT_NO_THROW(model.frameIndex("talus_" + s));
    EXPECT_EQ(model.mass[model.segmentOfJoint("ankle_flexion_" + s)], 0.0);  // the talus
    // Inversion: the heel, hf below the ankle axis, swings medially (the sole faces the
    // midline): +y on the right, -y on the left.
    const Vector3d d = linkWorld(model, pose(model, "subtalar_inversion_" + s, 10.0), "heel_" + s) -
                       linkWorld(model, pose(model, "", 0.0), "heel_" + s);
    EXPECT_NEAR(d.y(), side * hf * s10, 1e-14);
  }
}

// What robot_state_publisher (KDL) makes of the file, so that rviz draws what the
// estimator computes: every joint, and every link's pose at an arbitrary q, agree.
TEST(Body, KdlReadsTheSameTree) {
  const jle::Model<double> model = bundled();
  KDL::Tree tree;
  ASSERT_TRUE(kdl_parser::treeFromFile(kBundled, tree));
  EXPECT_EQ(tree.getNrOfJoints(), 10u);
  EXPECT_EQ(tree.getRootSegment()->first, "pelvis");
  // q: 0.1 k - 0.45 rad for the k-th coordinate (neither side enforces the limits).
  jle::VectorX<double> q(model.nq);
  for (int k = 0; k < model.nq; ++k) q[k] = 0.1 * k - 0.45;
  KDL::JntArray kq(tree.getNrOfJoints());
  for (const auto& entry : tree.getSegments()) {
    const KDL::Joint& joint = entry.second.segment.getJoint();
    if (joint.getType() == KDL::Joint::None) continue;
    const int s = model.segmentOfJoint(joint.getName());
    kq(entry.second.q_nr) = q[model.coordinate[s]];
  }
  jle::Data<double> data(model);
  const jle::VectorX<double> zero = jle::VectorX<double>::Zero(model.nq);
  jle::forwardKinematics(model, data, q, zero, zero, Vector3d(0.0, 0.0, -kG));
  KDL::TreeFkSolverPos_recursive fk(tree);
  for (const jle::Frame<double>& f : model.frames) {
    KDL::Frame pose;
    ASSERT_GE(fk.JntToCart(kq, pose, f.name), 0) << f.name;
    const Vector3d ours = linkWorld(model, data, f.name);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(ours[i], pose.p(i), 1e-14) << f.name << " " << i;  // [m] under 1 m
  }
}

TEST(Body, LoadsAsAFloatingBase) {
  const jle::Model<double> model = bundled(true);
  EXPECT_TRUE(model.floating_base);
  EXPECT_EQ(model.joint_type[0], jle::JointType::kFloating);
  EXPECT_EQ(model.nq, 10);
}

// ------------------------------------------------------------------------- the CLI

TEST_F(BodyTool, RefusesBadOptions) {
  const std::string out = path("out/x.urdf");
  const std::vector<std::vector<std::string>> usage_errors = {
      {"--height", "1.75"},                                         // no mass
      {"--mass", "75"},                                             // no height
      {"--mass", "-75", "--height", "1.75"},                        // out of range
      {"--mass", "75", "--height", "17.5"},                         // centimetres by mistake
      {"--mass", "seventy", "--height", "1.75"},                    // not a number
      {"--mass", "nan", "--height", "1.75"},                        // not finite
      {"--mass", "75", "--height", "1.75", "--thigh-length", "4"},  // 10 x the table's
      {"--mass", "75", "--height", "1.75", "--shank-length", "0"},
      {"--mass", "75", "--height", "1.75", "--knee", "1"},    // unknown option
      {"--mass", "75", "--height", "1.75", "--mass", "80"},   // given twice
      {"--mass", "75", "--height", "1.75", "--name", "a b"},  // not a name
  };
  for (std::vector<std::string> args : usage_errors) {
    args.insert(args.end(), {"--output", out});
    const Result r = run(args);
    EXPECT_EQ(r.status, 2) << args[0] << " " << args[1] << ": " << r.err;
    EXPECT_EQ(r.err.rfind("make_body_urdf: ", 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // A data error: the output cannot be written. Nothing is left behind.
  const Result r = run({"--mass", "75", "--height", "1.75", "--output", path("no/such/dir.urdf")});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(fs::is_empty(path("out")));
  // --help is not an error.
  const Result help = run({"--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("--mass KG"), std::string::npos);
}

TEST_F(BodyTool, MeasuredLengthsOverrideTheTable) {
  const jle::Model<double> model =
      generate({"--mass", "60", "--height", "1.6", "--thigh-length", "0.41", "--shank-length",
                "0.4", "--foot-height", "0.07", "--pelvis-width", "0.18", "--name", "subject_3"});
  const jle::Data<double> data = pose(model, "", 0.0);
  const double tol = 1e-14;
  EXPECT_LT((linkWorld(model, data, "femur_l") - Vector3d(0, 0.09, 0)).norm(), tol);
  EXPECT_LT((linkWorld(model, data, "tibia_l") - Vector3d(0, 0.09, -0.41)).norm(), tol);
  EXPECT_LT((linkWorld(model, data, "foot_l") - Vector3d(0, 0.09, -0.81)).norm(), tol);
  EXPECT_NEAR(linkWorld(model, data, "heel_l").z(), -0.88, tol);
  // The thigh's COM follows the measured length, its mass the body mass.
  const int femur = model.segmentOfJoint("hip_rotation_l");
  EXPECT_NEAR(model.com[femur].z(), -kThighCom * 0.41, 1e-15);
  EXPECT_NEAR(model.mass[femur], kThighMass * 60.0, 1e-13);
  EXPECT_NEAR(model.totalMass(), 60.0, 1e-12 * 60.0);
  EXPECT_NE(readFile(path("out/body.urdf")).find("<robot name=\"subject_3\">"), std::string::npos);
}

// ------------------------------------------------------------------ standing balance

struct Plate {
  jle::ForcePlateConfig config;
  double share;  // of body weight
  Vector3d cop;  // world [m], on the floor z = 0
};

// The body stands still at q = 0 with its soles on the floor z = 0, the pelvis (floating
// base) at the hip height l_thigh + l_shank + h_foot. Each plate reports what the foot
// applies to it: share x W down at the COP, in the plate frame, moment about the plate
// origin; the reaction goes to the foot through force_plate.hpp (applyPlateReaction, as
// the estimator and joint_loads apply it).
struct Standing {
  jle::Model<double> model;
  jle::Data<double> data;
  Standing(const jle::Model<double>& m, double hip_height, const std::vector<Plate>& plates,
           const std::vector<std::string>& feet)
      : model(m), data(m) {
    jle::BaseState<double> base;
    base.p_world_base = Vector3d(0.0, 0.0, hip_height);
    const jle::VectorX<double> zero = jle::VectorX<double>::Zero(model.nq);
    jle::forwardKinematics(model, data, zero, zero, zero, Vector3d(0.0, 0.0, -kG), base);
    const double weight = model.totalMass() * kG;
    for (std::size_t k = 0; k < plates.size(); ++k) {
      const jle::ForcePlateConfig& c = plates[k].config;
      const Vector3d force_plate =
          c.R_world_plate.transpose() * Vector3d(0, 0, -plates[k].share * weight);
      const Vector3d cop_plate = c.R_world_plate.transpose() * (plates[k].cop - c.p_world_plate);
      const jle::PlateReading reading =
          jle::readForcePlate(c, force_plate, cop_plate.cross(force_plate));
      EXPECT_TRUE(reading.contact);
      jle::applyPlateReaction(model, data, model.frameIndex(feet[k]), c, reading);
    }
    jle::inverseDynamics(model, data);
  }
  jle::Wrench<double> world(const std::string& joint) const {
    return jle::jointWrench(model, data, model.segmentOfJoint(joint), jle::WrenchFrame::kWorld);
  }
  double effort(const std::string& joint) const { return data.effort[model.segmentOfJoint(joint)]; }
};

// The loads of one leg standing on a plate carrying P = share x W at the COP (cx, cy)
// (world), the leg's hip joint centre at (0, yh): the ankle, knee and hip are straight
// above each other; only the foot's COM lies off that line, 0.25 lf ahead of it.
// Vertical force on each distal segment from its parent (world z, up positive), from
// the equilibrium of everything below the joint: F + P - (masses below) g = 0:
//   ankle: m_f g - P;  knee: (m_f + m_s) g - P;  hip: (m_f + m_s + m_t) g - P.
// Moment about each joint on the distal part, y component (world): the plate force P
// at lever (cx, ., -z) gives (r x F)_y = -cx P, the foot's weight at lever 0.25 lf gives
// +0.25 lf m_f g, the others none: M_y = cx P - 0.25 lf m_f g at the ankle, knee and
// hip alike. Efforts: ankle and hip flexion turn about -y: -M_y; the knee about +y: M_y.
// x component at the ankle (frontal plane): (r x F)_x = (cy - yh) P, so M_x = -(cy - yh) P.
void expectLegLoads(const Standing& st, const std::string& s, double share, const Vector3d& cop,
                    double yh, double lf, const char* what) {
  const double W = st.model.totalMass() * kG;
  const double P = share * W;
  const double mt = kThighMass * st.model.totalMass(), ms = kShankMass * st.model.totalMass(),
               mf = kFootMass * st.model.totalMass();
  // Sums of a few hundred newtons: 1e-12 W (7e-10 N) is many ulps and far below any
  // physical difference.
  const double ftol = 1e-12 * W;
  SCOPED_TRACE(std::string(what) + ", side " + s);
  EXPECT_NEAR(st.world("ankle_flexion_" + s).force.z(), mf * kG - P, ftol);
  EXPECT_NEAR(st.world("knee_flexion_" + s).force.z(), (mf + ms) * kG - P, ftol);
  EXPECT_NEAR(st.world("hip_rotation_" + s).force.z(), (mf + ms + mt) * kG - P, ftol);
  EXPECT_NEAR(st.world("hip_flexion_" + s).force.z(), (mf + ms + mt) * kG - P, ftol);
  for (const char* j : {"ankle_flexion_", "knee_flexion_", "hip_flexion_"}) {
    EXPECT_NEAR(st.world(j + s).force.x(), 0.0, ftol) << j;
    EXPECT_NEAR(st.world(j + s).force.y(), 0.0, ftol) << j;
  }
  const double my = cop.x() * P - 0.25 * lf * mf * kG;
  const double mtol = 1e-12 * W;  // [N m]: lever arms under 1 m
  EXPECT_NEAR(st.effort("ankle_flexion_" + s), -my, mtol);
  EXPECT_NEAR(st.effort("knee_flexion_" + s), my, mtol);
  EXPECT_NEAR(st.effort("hip_flexion_" + s), -my, mtol);
  EXPECT_NEAR(st.world("ankle_flexion_" + s).moment.x(), -(cop.y() - yh) * P, mtol);
}

// The whole body's COM: every segment's COM is on the vertical through its joints
// except the feet's, 0.25 lf ahead: x_G = 2 m_f (0.25 lf) / M = 2 x 0.0145 x 0.25 lf.
double comX(double lf) { return 2.0 * kFootMass * 0.25 * lf; }

// (a) W/2 on each plate, each COP under its hip at x_G: the moments about the COM cancel.
TEST(Standing, SymmetricStanceBalancesTheBodyWeight) {
  const jle::Model<double> model = bundled(true);
  const double lf = kFootLength * kHeight, w = hipSpacing((kThighLength + kShankLength) * kHeight);
  const double xg = comX(lf);
  Plate right{{}, 0.5, Vector3d(xg, -0.5 * w, 0.0)};
  right.config.p_world_plate = Vector3d(0.2, -0.3, 0.0);
  Plate left{{}, 0.5, Vector3d(xg, 0.5 * w, 0.0)};
  left.config.p_world_plate = Vector3d(0.2, 0.3, -0.035);  // origin below the surface
  left.config.surface_height = 0.035;
  const double hip_height = (kThighLength + kShankLength + kAnkleHeight) * kHeight;
  const Standing st(model, hip_height, {right, left}, {"foot_r", "foot_l"});

  const double W = kMass * kG;
  // The pelvis needs nothing from the world: 1e-10 W, as the issue asks (measured ~1e-14 W).
  EXPECT_LT(st.data.force[0].norm(), 1e-10 * W);
  EXPECT_LT(st.data.moment[0].norm(), 1e-10 * W);
  expectLegLoads(st, "r", 0.5, right.cop, -0.5 * w, lf, "symmetric");
  expectLegLoads(st, "l", 0.5, left.cop, 0.5 * w, lf, "symmetric");
  // Half the weight each, minus the leg: 367.749 - 9.8067 x 12.075 = 249.33 N pushes the
  // pelvis up at each hip (what the femur applies to the pelvis).
  EXPECT_NEAR(-st.world("hip_rotation_r").force.z(), 0.5 * W - 12.075 * kG, 1e-12 * W);
}

// (b) 70 % of the weight on the right plate, 30 % on the left, with hip joint centres
// 0.18 m apart (a measured --pelvis-width, so that both COPs lie under their feet). The
// COPs balance the moments about the COM:
//   x: 0.7 (cx_r - x_G) + 0.3 (cx_l - x_G) = 0 with cx_r = x_G + 0.03, cx_l = x_G - 0.07;
//   y: 0.7 cy_r + 0.3 cy_l = 0 with cy_l = 0.12 (3 cm lateral of the left ankle), so
//      cy_r = -0.3 x 0.12 / 0.7 = -0.0514286 (3.9 cm medial of the right ankle at -0.09).
TEST_F(BodyTool, AsymmetricStanceBalancesTheBodyWeight) {
  const jle::Model<double> model =
      generate({"--mass", "75", "--height", "1.75", "--pelvis-width", "0.18"}, true);
  const double lf = kFootLength * kHeight, xg = comX(lf);
  Plate right{{}, 0.7, Vector3d(xg + 0.03, -0.3 * 0.12 / 0.7, 0.0)};
  right.config.p_world_plate = Vector3d(0.25, -0.25, 0.0);
  Plate left{{}, 0.3, Vector3d(xg - 0.07, 0.12, 0.0)};
  // An AMTI-style plate: its own z down, given to the decoder turned by pi about x and
  // here also turned by 90 deg about the vertical.
  left.config.R_world_plate = Eigen::AngleAxisd(kPi / 2.0, Vector3d::UnitZ()).toRotationMatrix();
  left.config.p_world_plate = Vector3d(0.25, 0.25, -0.04);
  left.config.surface_height = 0.04;
  const double hip_height = (kThighLength + kShankLength + kAnkleHeight) * kHeight;
  const Standing st(model, hip_height, {right, left}, {"foot_r", "foot_l"});

  const double W = kMass * kG;
  EXPECT_LT(st.data.force[0].norm(), 1e-10 * W);
  EXPECT_LT(st.data.moment[0].norm(), 1e-10 * W);
  expectLegLoads(st, "r", 0.7, right.cop, -0.09, lf, "70/30");
  expectLegLoads(st, "l", 0.3, left.cop, 0.09, lf, "70/30");
  // The right ankle: 0.7 W = 514.849 N, 0.0319285 m ahead of the ankle, foot weight
  // 10.665 N at 0.0665 m: effort = 0.25 lf m_f g - cx P = 0.709205 - 16.438360 =
  // -15.729156 N m, a plantar-flexor moment (negative dorsiflexion).
  EXPECT_NEAR(st.effort("ankle_flexion_r"), -15.729156, 1e-6);  // 7 digits worked
}

// ------------------------------------------------------------------ --sagittal, --segments

// A lab's own sagittal-plane parameters (a 2-D study has the mass, the centre of mass
// and the moment of inertia about the transverse axis only), as --segments reads them.
const char* const kSagittalSegments =
    R"(thigh: {mass: 8.0, com: [0, 0, -0.19], inertia: {iyy: 0.15}}
shank: {mass: 3.2, com: [0, 0, -0.18], gyration: 0.12, length: 0.42}
foot: {mass: 1.1, com: [0.06, 0, -0.03], inertia: {iyy: 0.005}, height: 0.07}
hat: {mass: 48.0, com: [0.01, 0, 0.30], inertia: {iyy: 2.1}}
)";
constexpr double kSagittalMass = 48.0 + 2.0 * (8.0 + 3.2 + 1.1);  // kg

// Joints of the sagittal body, and a CSV row of them: q, qd, qdd.
const std::vector<std::string> kSagittalJoints = {
    "pelvis_tx",       "pelvis_tz",     "pelvis_tilt",    "hip_flexion_r",  "knee_flexion_r",
    "ankle_flexion_r", "hip_flexion_l", "knee_flexion_l", "ankle_flexion_l"};

std::string sagittalCsv(const std::vector<std::vector<double>>& rows) {
  std::string text = "t";
  for (const std::string& j : kSagittalJoints) text += "," + j + ".q," + j + ".qd," + j + ".qdd";
  for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"})
    text += std::string(",wrench@foot_r.") + c;
  text += "\n";
  for (const std::vector<double>& row : rows) {
    for (std::size_t i = 0; i < row.size(); ++i) {
      char cell[40];
      std::snprintf(cell, sizeof cell, "%s%.17g", i ? "," : "", row[i]);
      text += cell;
    }
    text += "\n";
  }
  return text;
}

TEST_F(BodyTool, SagittalBodyFromSegmentsIsPlanarWithTheGivenParameters) {
  write("segments.yaml", kSagittalSegments);
  const jle::Model<double> model = generate(
      {"--mass", "75", "--height", "1.75", "--sagittal", "--segments", path("segments.yaml")});
  EXPECT_FALSE(model.floating_base);
  EXPECT_EQ(model.nq, 9);
  EXPECT_NEAR(model.totalMass(), kSagittalMass, 1e-12);
  const auto segment = [&](const char* link) {
    return model.frames[model.frameIndex(link)].segment;
  };
  // The values of the YAML; the out-of-plane moments are iyy / 2 (documented).
  const struct {
    const char* link;
    double mass, iyy;
    Vector3d com;
  } expected[] = {{"femur_r", 8.0, 0.15, Vector3d(0, 0, -0.19)},
                  {"tibia_l", 3.2, 3.2 * 0.12 * 0.12, Vector3d(0, 0, -0.18)},
                  {"foot_r", 1.1, 0.005, Vector3d(0.06, 0, -0.03)},
                  {"pelvis", 48.0, 2.1, Vector3d(0.01, 0, 0.30)}};
  for (const auto& e : expected) {
    const int s = segment(e.link);
    EXPECT_DOUBLE_EQ(model.mass[s], e.mass) << e.link;
    EXPECT_LE((model.com[s] - e.com).norm(), 1e-15) << e.link;
    EXPECT_NEAR(model.inertia_com[s](1, 1), e.iyy, 1e-15) << e.link;
    EXPECT_NEAR(model.inertia_com[s](0, 0), 0.5 * e.iyy, 1e-15) << e.link;
    EXPECT_NEAR(model.inertia_com[s](2, 2), 0.5 * e.iyy, 1e-15) << e.link;
  }
  // The lengths of the YAML: the ankle 0.42 m below the knee, the sole 0.07 m below it.
  EXPECT_LE((model.p_parent_joint[segment("foot_r")] - Vector3d(0, 0, -0.42)).norm(), 1e-15);
  EXPECT_NEAR(model.frames[model.frameIndex("heel_l")].p_segment_frame.z(), -0.07, 1e-15);
  // The planar solver's own detection accepts it, plane normal along y.
  const jle::PlanarCheck<double> check = jle::detectPlanar(model, Vector3d(0, 0, -kG));
  EXPECT_TRUE(check.planar) << check.reason;
  EXPECT_NEAR(std::abs(check.normal.y()), 1.0, 1e-15);
}

// The sagittal body through joint_loads with the planar solver on: standing still its
// pelvis joints carry the weight (pelvis_tz: M g; pelvis_tilt: the weights' moment about
// the pelvis origin, only the feet's COMs lying ahead of it), and moving with a ground
// reaction in the plane the 3x3 solver gives the 6x6 solver's loads.
TEST_F(BodyTool, SagittalBodyGoesThroughJointLoadsWithPlanarOn) {
  write("segments.yaml", kSagittalSegments);
  generate({"--mass", "75", "--height", "1.75", "--sagittal", "--segments", path("segments.yaml")});
  std::vector<std::vector<double>> rows;
  rows.push_back(std::vector<double>(1 + 3 * kSagittalJoints.size() + 6, 0.0));  // still
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int r = 1; r < 6; ++r) {
    std::vector<double> row{0.01 * r};
    // q within every joint's URDF limits widened by 1 rad (joint_loads refuses what no
    // joint reaches: docs/node.md "Never silently wrong"), q-dot and q-ddot within 2.
    for (std::size_t k = 0; k < 3 * kSagittalJoints.size(); ++k)
      row.push_back((k % 3 == 0 ? 0.9 : 2.0) * u(gen));
    // A ground reaction in the plane: force (x, z), moment about y.
    for (double c : {100.0 * u(gen), 0.0, 700.0 + 50.0 * u(gen), 0.0, 10.0 * u(gen), 0.0})
      row.push_back(c);
    rows.push_back(row);
  }
  write("sagittal.csv", sagittalCsv(rows));
  const auto loads = [&](const char* mode) {
    const Result r = ToolTest::run(
        JLE_JOINT_LOADS, {"--urdf", path("out/body.urdf"), "--input", path("sagittal.csv"),
                          "--planar", mode, "--output", path(std::string("out/") + mode)});
    EXPECT_EQ(r.status, 0) << r.err;
    if (std::string(mode) == "on") {
      EXPECT_NE(r.err.find("the 3x3 solver"), std::string::npos) << r.err;
    }
    return jle_test::parseCsv(readFile(path(std::string("out/") + mode)));
  };
  const jle_test::Table on = loads("on"), off = loads("off");
  ASSERT_EQ(on.rows.size(), rows.size());
  EXPECT_NEAR(on.number(0, "pelvis_tz.effort"), kSagittalMass * kG, 1e-10);
  EXPECT_NEAR(on.number(0, "pelvis_tx.effort"), 0.0, 1e-10);
  EXPECT_NEAR(on.number(0, "pelvis_tilt.effort"), -kG * 2.0 * 1.1 * 0.06 - kG * 48.0 * 0.01, 1e-10);
  // Every column of every row: planar = 6x6 within 1e-12 of the row's largest load.
  ASSERT_EQ(on.header, off.header);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    double scale = 1.0;
    for (std::size_t c = 1; c < on.header.size(); ++c)
      scale = std::max(scale, std::abs(off.number(r, off.header[c])));
    for (std::size_t c = 1; c < on.header.size(); ++c)
      EXPECT_NEAR(on.number(r, on.header[c]), off.number(r, off.header[c]), 1e-12 * scale)
          << "row " << r << " " << on.header[c];
  }
}

// A segment given its mass only keeps the table's radii of gyration (Winter Table 4.1's
// k = 0.323 l across the thigh, de Leva's 14.9 / 32.9 of it along), not the table's
// inertia in kg m^2: 9 kg on the 75 kg, 1.75 m body's 0.42875 m thigh gives
// 9 (0.323 x 0.42875)^2 = 0.1726 kg m^2 across (the table's 7.5 kg inertia, 0.1438, is
// 17% low). A length given beside it scales the radii too: a 4 kg shank of 0.40 m has
// 4 (0.302 x 0.40)^2 = 0.05837 kg m^2 across.
TEST_F(BodyTool, MassWithoutInertiaKeepsTheTablesRadiusOfGyration) {
  write("segments.yaml", "thigh: {mass: 9.0}\nshank: {mass: 4.0, length: 0.40}\n");
  const jle::Model<double> model =
      generate({"--mass", "75", "--height", "1.75", "--segments", path("segments.yaml")});
  const auto inertia = [&](const char* link) {
    return model.inertia_com[model.frames[model.frameIndex(link)].segment];
  };
  const double thigh = 0.245 * 1.75, shank = 0.40;  // [m]
  const double thigh_across = 9.0 * std::pow(0.323 * thigh, 2);
  const double thigh_along = 9.0 * std::pow(0.323 * 14.9 / 32.9 * thigh, 2);
  const double shank_across = 4.0 * std::pow(0.302 * shank, 2);
  const double shank_along = 4.0 * std::pow(0.302 * 10.3 / 25.5 * shank, 2);
  EXPECT_NEAR(thigh_across, 0.172606, 1e-6);  // the figure of the issue, by hand
  for (const char* side : {"r", "l"}) {
    const Matrix3d t = inertia((std::string("femur_") + side).c_str());
    const Matrix3d s = inertia((std::string("tibia_") + side).c_str());
    // 1e-15: the tool's products in another order, a few ulps of 0.17 kg m^2.
    EXPECT_NEAR(t(0, 0), thigh_across, 1e-15) << side;
    EXPECT_NEAR(t(1, 1), thigh_across, 1e-15) << side;
    EXPECT_NEAR(t(2, 2), thigh_along, 1e-15) << side;
    EXPECT_NEAR(s(0, 0), shank_across, 1e-15) << side;
    EXPECT_NEAR(s(1, 1), shank_across, 1e-15) << side;
    EXPECT_NEAR(s(2, 2), shank_along, 1e-15) << side;
  }
}

// A URDF that joint_loads would refuse is never written: the tool runs the package's
// model check on what it would write and stops with exit status 1 naming the segment,
// its link and the violation. With --sagittal, {iyy: 0.15, ixy: 0.01} leaves ixx = izz
// = 0, and [[0, 0.01], [0.01, 0.15]] has the principal moment (0.15 - sqrt(0.15^2 + 4 x
// 0.01^2)) / 2 = -6.6e-4 < 0; a 3-D shank {0.1, 0.1, 0.3} breaks the triangle
// inequality (0.1 + 0.1 < 0.3) and so does a foot of radii [0.1, 0.1, 0.3] m.
TEST_F(BodyTool, RefusesSegmentsTheModelCheckRefuses) {
  const auto refused = [&](const std::string& yaml, std::vector<std::string> args,
                           const std::vector<std::string>& parts) {
    write("bad.yaml", yaml);
    args.insert(args.end(), {"--mass", "75", "--height", "1.75", "--segments", path("bad.yaml"),
                             "--output", path("out/x.urdf")});
    const Result r = run(args);
    EXPECT_EQ(r.status, 1) << yaml << r.err;
    for (const std::string& part : parts) EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("out/x.urdf"))) << yaml;
    EXPECT_TRUE(r.out.empty()) << yaml;
  };
  refused("thigh: {inertia: {iyy: 0.15, ixy: 0.01}}\n", {"--sagittal"},
          {"thigh", "link 'femur_r'", "not positive semi-definite"});
  refused("shank: {inertia: {ixx: 0.1, iyy: 0.1, izz: 0.3}}\n", {},
          {"shank", "link 'tibia_r'", "triangle inequality"});
  refused("foot: {gyration: [0.1, 0.1, 0.3]}\n", {}, {"foot", "link 'foot_r'", "triangle"});
  // Standard output too: nothing is printed when the model is refused.
  write("bad.yaml", "hat: {inertia: {ixx: 1, iyy: 1, izz: 3}}\n");
  const Result r = run({"--mass", "75", "--height", "1.75", "--segments", path("bad.yaml")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("hat (link 'pelvis'"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST_F(BodyTool, SegmentsAreCheckedNamingTheKey) {
  const auto refused = [&](const std::string& yaml, std::vector<std::string> extra, int status,
                           const std::string& part) {
    write("bad.yaml", yaml);
    std::vector<std::string> args{
        "--mass",         "75",       "--height",        "1.75", "--segments",
        path("bad.yaml"), "--output", path("out/x.urdf")};
    args.insert(args.end(), extra.begin(), extra.end());
    const Result r = run(args);
    EXPECT_EQ(r.status, status) << yaml << r.err;
    EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("out/x.urdf")));
  };
  // A 3-D body needs all three moments; one radius is the sagittal one.
  refused("thigh: {inertia: {iyy: 0.1}}\n", {}, 1, "thigh.inertia");
  refused("thigh: {gyration: 0.1}\n", {}, 1, "--sagittal");
  refused("thigh: {mass: -2}\n", {}, 1, "thigh.mass");
  refused("elbow: {mass: 2}\n", {}, 1, "elbow");
  refused("thigh: {colour: red}\n", {}, 1, "'colour'");
  refused("thigh: {inertia: {iyy: 1}, gyration: 0.1}\n", {"--sagittal"}, 1, "not both");
  refused("shank: {length: 4}\n", {}, 1, "--shank-length");
  refused("shank: {length: 0.4}\n", {"--shank-length", "0.4"}, 2, "also given by --segments");
  refused("thigh: {mass: 7}\n", {"--sagittal", "--subtalar"}, 2, "exclude");
}

}  // namespace
