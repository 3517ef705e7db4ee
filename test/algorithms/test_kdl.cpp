// Agreement with Orocos KDL, an independent implementation of the same mechanics:
// joint efforts against KDL::TreeIdSolver_RNE and KDL::ChainIdSolver_RNE, all six
// components of a joint wrench through six virtual joints, and forward kinematics
// against KDL::TreeFkSolverPos_recursive.
//
// KDL's conventions, read in its source (treeidsolver_recursive_newton_euler.cpp,
// chainidsolver_recursive_newton_euler.cpp) and checked by the hand case below:
// f[seg] = I a + v x* I v - f_ext[seg], so f_ext is the wrench applied TO the segment by
// the environment, in the segment (URDF child link) frame, about the segment origin;
// the same as jle::addExternalWrench(..., WrenchFrame::kLocal). KDL's effort is
// S . f[seg], S the joint's unit twist in the segment frame: axis . moment (revolute),
// axis . force (prismatic), our data.effort. KDL knows no mimic joints (kdl_parser gives
// them their own coordinate), so the test sets each one from its leader itself.
#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/random_models.hpp>

#include <gtest/gtest.h>
#include <kdl/chain.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <tinyxml2.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Eigen::Vector3d;
using jle::VectorX;

const Vector3d kGravity(0.0, 0.0, -9.80665);  // [m/s^2], world = root frame

// The agreement required of every effort and wrench component: |ours - kdl| <=
// kRelTol * max(|kdl|, 1 N or N m). Both sides sum the same few dozen products of O(1)
// to O(100) numbers in double precision, so they differ by ~1e-14 relative; 1e-9
// leaves five orders of margin and still catches any wrong term (a missing lever arm,
// a transposed rotation), which moves the result by far more. Below 1 N m the bound is
// absolute, 1e-9 N m: a near-zero torque is the cancellation of large terms and is only
// known to their rounding.
constexpr double kRelTol = 1e-9;
// Poses: products of ~10 rotations and translations of O(1) m; rounding ~1e-15.
constexpr double kPoseTol = 1e-12;

std::string urdfPath(const std::string& relative) {
  return std::string(JLE_TEST_DATA) + "/urdf/" + relative;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot open " << path;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

KDL::Vector toKdl(const Vector3d& v) { return KDL::Vector(v.x(), v.y(), v.z()); }

// ---------------------------------------------------------------------------------------
// Reading what KDL ignores or numbers its own way.

/// A URDF <mimic>: q_joint = multiplier * q_leader + offset.
struct Mimic {
  std::string leader;
  double multiplier = 1.0;
  double offset = 0.0;
};

/// The <mimic> of every moving joint, read from the URDF text with tinyxml2 (not
/// through the library under test; KDL drops them).
std::map<std::string, Mimic> urdfMimics(const std::string& xml) {
  std::map<std::string, Mimic> out;
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    ADD_FAILURE() << "malformed URDF";
    return out;
  }
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  for (const tinyxml2::XMLElement* j = robot->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    const std::string type = j->Attribute("type");
    const tinyxml2::XMLElement* m = j->FirstChildElement("mimic");
    if (!m || (type != "revolute" && type != "continuous" && type != "prismatic")) continue;
    Mimic mimic;
    mimic.leader = m->Attribute("joint");
    m->QueryDoubleAttribute("multiplier", &mimic.multiplier);
    m->QueryDoubleAttribute("offset", &mimic.offset);
    out[j->Attribute("name")] = mimic;
  }
  return out;
}

/// A moving joint of a KDL tree: its index into KDL's JntArray and its kind.
struct KdlJoint {
  unsigned int q_nr = 0;
  bool prismatic = false;
};

std::map<std::string, KdlJoint> kdlJoints(const KDL::Tree& tree) {
  std::map<std::string, KdlJoint> out;
  for (const auto& element : tree.getSegments()) {
    const KDL::Joint& joint = GetTreeElementSegment(element.second).getJoint();
    if (joint.getType() == KDL::Joint::Fixed) continue;
    KdlJoint j;
    j.q_nr = GetTreeElementQNr(element.second);
    j.prismatic = joint.getType() == KDL::Joint::TransAxis;
    out[joint.getName()] = j;
  }
  return out;
}

/// Segments (URDF links) of a KDL tree with no child: where the external loads go.
std::vector<std::string> kdlLeaves(const KDL::Tree& tree) {
  std::vector<std::string> out;
  for (const auto& element : tree.getSegments())
    if (GetTreeElementChildren(element.second).empty()) out.push_back(element.first);
  return out;
}

KDL::Tree kdlTree(const std::string& xml) {
  KDL::Tree tree;
  EXPECT_TRUE(kdl_parser::treeFromString(xml, tree)) << "kdl_parser refused the URDF";
  return tree;
}

// ---------------------------------------------------------------------------------------
// Random states and loads.

using jle_test::State;

/// q, qd, qdd uniform in ranges a real arm sees (revolute: +-pi rad, +-3 rad/s,
/// +-10 rad/s^2; prismatic fingers: 0..4 cm, +-0.2 m/s, +-2 m/s^2).
State randomState(const jle::Model<double>& model, jle_test::Random& rng) {
  return jle_test::randomState(model, rng, {M_PI, 3.0, 10.0, 0.02, 0.02, 0.2, 2.0});
}

/// The same state as KDL arrays: each KDL joint takes its coordinate by name, a mimic
/// multiplier * q_leader + offset (qd, qdd: multiplier times the leader's); joints in
/// `held_at_zero` (virtual ones the library's model does not have) stay at 0.
struct KdlState {
  KDL::JntArray q, qd, qdd;
};

KdlState toKdlState(const jle::Model<double>& model, const KDL::Tree& tree,
                    const std::map<std::string, KdlJoint>& kdl_joints,
                    const std::map<std::string, Mimic>& mimics, const State& s,
                    const std::set<std::string>& held_at_zero = {}) {
  const unsigned int n = tree.getNrOfJoints();
  KdlState out{KDL::JntArray(n), KDL::JntArray(n), KDL::JntArray(n)};
  for (const auto& [name, joint] : kdl_joints) {
    if (held_at_zero.count(name)) continue;
    double multiplier = 1.0, offset = 0.0;
    std::string leader = name;
    for (auto m = mimics.find(leader); m != mimics.end(); m = mimics.find(leader)) {
      offset = multiplier * m->second.offset + offset;
      multiplier *= m->second.multiplier;
      leader = m->second.leader;
    }
    const auto it = std::find(model.coordinate_names.begin(), model.coordinate_names.end(), leader);
    if (it == model.coordinate_names.end()) {
      ADD_FAILURE() << "KDL joint '" << name << "' (leader '" << leader
                    << "') is no coordinate of the model";
      continue;
    }
    const int k = static_cast<int>(it - model.coordinate_names.begin());
    out.q(joint.q_nr) = multiplier * s.q[k] + offset;
    out.qd(joint.q_nr) = multiplier * s.qd[k];
    out.qdd(joint.q_nr) = multiplier * s.qdd[k];
  }
  return out;
}

/// A wrench applied to the robot at a link's origin, in that link's frame.
struct Load {
  std::string link;
  Vector3d force, moment;  // [N], [N m]
};

/// Random loads of up to 50 N and 10 N m on every link in `links`.
std::vector<Load> randomLoads(const std::vector<std::string>& links, jle_test::Random& rng) {
  std::vector<Load> out;
  for (const std::string& link : links) {
    Load l;
    l.link = link;
    l.force = 50.0 * rng.vector(1.0);
    l.moment = 10.0 * rng.vector(1.0);
    out.push_back(l);
  }
  return out;
}

KDL::WrenchMap toKdlWrenches(const std::vector<Load>& loads) {
  KDL::WrenchMap out;
  for (const Load& l : loads) out[l.link] = KDL::Wrench(toKdl(l.force), toKdl(l.moment));
  return out;
}

/// The library's forward pass, loads and backward pass for one state.
void solve(const jle::Model<double>& model, jle::Data<double>& data, const State& s,
           const std::vector<Load>& loads) {
  jle::forwardKinematics(model, data, s.q, s.qd, s.qdd, kGravity);
  for (const Load& l : loads)
    jle::addExternalWrench(model, data, model.frameIndex(l.link), l.force, l.moment,
                           jle::WrenchFrame::kLocal);
  jle::inverseDynamics(model, data);
}

// ---------------------------------------------------------------------------------------
// Bookkeeping of the largest disagreement.

/// The largest |ours - kdl| / max(|kdl|, 1) seen, and where.
struct Worst {
  double rel = 0.0;
  std::string where = "(none)";

  void update(double ours, double kdl, int state, const std::string& what) {
    const double rel_here = std::abs(ours - kdl) / std::max(std::abs(kdl), 1.0);
    if (!(rel_here <= rel)) {  // NaN is worst of all
      rel = rel_here;
      std::ostringstream os;
      os.precision(17);
      os << what << " in state " << state << ": ours " << ours << ", KDL " << kdl;
      where = os.str();
    }
  }
};

void report(const std::string& label, const Worst& worst, double tolerance) {
  std::ostringstream os;
  os.precision(3);
  os << std::scientific << worst.rel;
  std::cout << "[ KDL      ] " << label << ": largest relative disagreement " << os.str() << " ("
            << worst.where << ")" << std::endl;
  ::testing::Test::RecordProperty("max_relative_disagreement", os.str());
  EXPECT_LE(worst.rel, tolerance) << label << ": worst case " << worst.where;
}

// ---------------------------------------------------------------------------------------
// KDL's f_ext convention, checked on a case solved by hand before it is relied on.

// A pendulum hinged about z at the base origin; its arm (mass m, com at l along x,
// inertia Izz about the com) carries at x = L a massless tip link turned by +90 deg about
// z. Gravity is -g along y. With the tip-frame load (F, M), the tip x axis is the arm's y
// axis, so the force's component along the arm's y is F_x; its moment about the hinge
// is L F_x, and M_z adds directly. The hinge torque is therefore
//   tau = (Izz + m l^2) qdd + m g l cos q - L F_x - M_z.
// If KDL's f_ext were the wrench the robot applies to the environment, both load terms
// would flip sign; if it were expressed in the world or the arm frame, F_y would appear.
constexpr char kPendulum[] = R"(
<robot name="pendulum">
  <link name="base"/>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <link name="arm">
    <inertial>
      <origin xyz="0.3 0 0"/><mass value="2.0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.05"/>
    </inertial>
  </link>
  <joint name="tip_joint" type="fixed">
    <parent link="arm"/><child link="tip"/><origin xyz="0.7 0 0" rpy="0 0 1.5707963267948966"/>
  </joint>
  <link name="tip"/>
</robot>)";

TEST(KdlConvention, ExternalWrenchIsAppliedToTheRobotInTheLinkFrameAboutItsOrigin) {
  const double m = 2.0, l = 0.3, L = 0.7, izz = 0.05, g = 9.81;
  const double q = 0.4, qd = 1.3, qdd = -0.7;
  const Vector3d force(11.0, -7.0, 5.0), moment(-2.0, 3.0, 1.5);
  const double tau_hand =
      (izz + m * l * l) * qdd + m * g * l * std::cos(q) - L * force.x() - moment.z();

  KDL::Tree tree = kdlTree(kPendulum);
  KDL::TreeIdSolver_RNE solver(tree, KDL::Vector(0.0, -g, 0.0));
  KDL::JntArray kq(1), kqd(1), kqdd(1), tau(1);
  kq(0) = q;
  kqd(0) = qd;
  kqdd(0) = qdd;
  KDL::WrenchMap f_ext;
  f_ext["tip"] = KDL::Wrench(toKdl(force), toKdl(moment));
  ASSERT_GE(solver.CartToJnt(kq, kqd, kqdd, f_ext, tau), 0);
  // Closed form against KDL: O(10) terms of O(1) N m, rounding ~1e-15.
  EXPECT_NEAR(tau(0), tau_hand, 1e-12);

  // The library, with the load given the same way, meets the same closed form.
  const jle::Model<double> model = jle::modelFromUrdfString(kPendulum);
  jle::Data<double> data(model);
  VectorX<double> vq(1), vqd(1), vqdd(1);
  vq << q;
  vqd << qd;
  vqdd << qdd;
  jle::forwardKinematics(model, data, vq, vqd, vqdd, Vector3d(0.0, -g, 0.0));
  jle::addExternalWrench(model, data, model.frameIndex("tip"), force, moment,
                         jle::WrenchFrame::kLocal);
  jle::inverseDynamics(model, data);
  EXPECT_NEAR(data.effort[model.segmentOfJoint("hinge")], tau_hand, 1e-12);
}

// ---------------------------------------------------------------------------------------
// 1. Efforts of whole trees against KDL::TreeIdSolver_RNE.

struct TreeCase {
  const char* name;
  const char* file;  // under test/data/urdf
};

const TreeCase kTrees[] = {
    {"panda", "panda.urdf"},
    {"ur5", "ur5_robot.urdf"},
    {"kinova", "kinova.urdf"},
    {"talos_reduced", "talos_reduced.urdf"},  // fixed at its root link, base_link
};

std::ostream& operator<<(std::ostream& os, const TreeCase& c) { return os << c.file; }

class KdlTree : public ::testing::TestWithParam<TreeCase> {};

/// Efforts of every moving joint of the URDF `xml` against TreeIdSolver_RNE, over `states`
/// random states with gravity and random wrenches on every leaf link; every moving joint
/// (mimics included) compared on its own.
Worst treeEffortDisagreement(const std::string& xml, int states, unsigned int seed) {
  Worst worst;
  const jle::Model<double> model = jle::modelFromUrdfString(xml);
  jle::Data<double> data(model);
  const KDL::Tree tree = kdlTree(xml);
  const std::map<std::string, KdlJoint> kdl_joints = kdlJoints(tree);
  const std::map<std::string, Mimic> mimics = urdfMimics(xml);
  const std::vector<std::string> leaves = kdlLeaves(tree);
  EXPECT_EQ(model.moving_segments.size(), kdl_joints.size())
      << "the model and KDL do not have the same moving joints";
  EXPECT_FALSE(leaves.empty());

  KDL::TreeIdSolver_RNE solver(tree, toKdl(kGravity));
  KDL::JntArray tau(tree.getNrOfJoints());
  jle_test::Random rng(seed);
  for (int n = 0; n < states; ++n) {
    const State s = randomState(model, rng);
    const std::vector<Load> loads = randomLoads(leaves, rng);
    const KdlState k = toKdlState(model, tree, kdl_joints, mimics, s);
    if (solver.CartToJnt(k.q, k.qd, k.qdd, toKdlWrenches(loads), tau) < 0) {
      ADD_FAILURE() << "TreeIdSolver_RNE failed in state " << n;
      return worst;
    }
    solve(model, data, s, loads);
    for (int seg : model.moving_segments) {
      const std::string& joint = model.joint_name[seg];
      worst.update(data.effort[seg], tau(kdl_joints.at(joint).q_nr), n, "effort of " + joint);
    }
  }
  return worst;
}

TEST_P(KdlTree, EffortsAgreeWithTreeIdSolverRne) {
  const std::string xml = readFile(urdfPath(GetParam().file));
  report(std::string(GetParam().name) + " efforts vs TreeIdSolver_RNE",
         treeEffortDisagreement(xml, 1000, 20240611u), kRelTol);
}

// Panda's finger mimic has multiplier 1 and offset 0, which cannot tell a mimic that
// is followed from one that is copied. Here the URDF text is edited to
// multiplier -0.5, offset 0.015 m; KDL's second finger is set from them by the test.
TEST(KdlMimic, ScaledAndOffsetMimicAgreesWithTreeIdSolverRne) {
  tinyxml2::XMLDocument doc;
  const std::string xml = readFile(urdfPath("panda.urdf"));
  ASSERT_EQ(doc.Parse(xml.c_str(), xml.size()), tinyxml2::XML_SUCCESS);
  tinyxml2::XMLElement* mimic = nullptr;
  for (tinyxml2::XMLElement* j = doc.FirstChildElement("robot")->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint"))
    if (std::string(j->Attribute("name")) == "panda_finger_joint2")
      mimic = j->FirstChildElement("mimic");
  ASSERT_NE(mimic, nullptr);
  mimic->SetAttribute("multiplier", -0.5);
  mimic->SetAttribute("offset", 0.015);
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  const std::string edited = printer.CStr();
  ASSERT_EQ(urdfMimics(edited).at("panda_finger_joint2").multiplier, -0.5);
  report("panda (mimic x-0.5 +0.015) efforts vs TreeIdSolver_RNE",
         treeEffortDisagreement(edited, 1000, 31u), kRelTol);
}

// Every URDF link's pose (segment frames and lumped links) against KDL's forward kinematics.
TEST_P(KdlTree, LinkPosesAgreeWithTreeFkSolverPos) {
  const std::string xml = readFile(urdfPath(GetParam().file));
  const jle::Model<double> model = jle::modelFromUrdfString(xml);
  jle::Data<double> data(model);
  const KDL::Tree tree = kdlTree(xml);
  const std::map<std::string, KdlJoint> kdl_joints = kdlJoints(tree);
  const std::map<std::string, Mimic> mimics = urdfMimics(xml);
  KDL::TreeFkSolverPos_recursive fk(tree);
  jle_test::Random rng(7u);
  double worst = 0.0;
  std::string worst_where = "(none)";
  const auto compare = [&](const Eigen::Matrix3d& R, const Vector3d& p, const KDL::Frame& X,
                           const std::string& what, int state) {
    double diff = 0.0;
    for (int r = 0; r < 3; ++r) {
      diff = std::max(diff, std::abs(p[r] - X.p(r)));
      for (int c = 0; c < 3; ++c) diff = std::max(diff, std::abs(R(r, c) - X.M(r, c)));
    }
    if (!(diff <= worst)) {
      worst = diff;
      worst_where = what + " in state " + std::to_string(state);
    }
  };
  for (int n = 0; n < 100; ++n) {
    const State s = randomState(model, rng);
    const KdlState k = toKdlState(model, tree, kdl_joints, mimics, s);
    jle::forwardKinematics(model, data, s.q, s.qd, s.qdd, kGravity);
    KDL::Frame X;
    // The segment frames themselves, as data holds them (the tip's among them)...
    for (int seg : model.moving_segments) {
      ASSERT_GE(fk.JntToCart(k.q, X, model.link_name[seg]), 0) << model.link_name[seg];
      compare(data.R_world[seg], data.p_world[seg], X, "segment " + model.link_name[seg], n);
    }
    // ...and every URDF link, lumped ones included, through its place on its segment.
    for (const jle::Frame<double>& frame : model.frames) {
      ASSERT_GE(fk.JntToCart(k.q, X, frame.name), 0) << frame.name;
      const int i = frame.segment;
      compare(data.R_world[i] * frame.R_segment_frame,
              data.p_world[i] + data.R_world[i] * frame.p_segment_frame, X, "link " + frame.name,
              n);
    }
  }
  std::cout << "[ KDL      ] " << GetParam().name
            << " poses vs TreeFkSolverPos_recursive: largest difference " << worst << " ("
            << worst_where << ")" << std::endl;
  // Largest difference of a rotation-matrix entry or a position coordinate [m].
  EXPECT_LE(worst, kPoseTol) << worst_where;
}

INSTANTIATE_TEST_SUITE_P(Models, KdlTree, ::testing::ValuesIn(kTrees),
                         [](const ::testing::TestParamInfo<TreeCase>& info) {
                           return std::string(info.param.name);
                         });

// ---------------------------------------------------------------------------------------
// 2. Efforts of single chains against KDL::ChainIdSolver_RNE.

struct ChainCase {
  const char* name;
  const char* file;  // under test/data/urdf/chains
  const char* root;
  const char* tip;
};

const ChainCase kChains[] = {
    {"panda", "panda_chain.urdf", "panda_link0", "panda_hand_tcp"},
    {"ur5", "ur5_chain.urdf", "base_link", "tool0"},
    {"kinova", "kinova_chain.urdf", "base", "j2s6s200_end_effector"},
};

std::ostream& operator<<(std::ostream& os, const ChainCase& c) {
  return os << c.file << " " << c.root << " -> " << c.tip;
}

class KdlChain : public ::testing::TestWithParam<ChainCase> {};

// 1000 random states, gravity and a random wrench at the tip.
TEST_P(KdlChain, EffortsAgreeWithChainIdSolverRne) {
  const ChainCase& c = GetParam();
  const std::string xml = readFile(urdfPath(std::string("chains/") + c.file));
  const jle::Model<double> model = jle::modelFromUrdfString(xml);
  jle::Data<double> data(model);
  const KDL::Tree tree = kdlTree(xml);
  KDL::Chain chain;
  ASSERT_TRUE(tree.getChain(c.root, c.tip, chain));
  const unsigned int ns = chain.getNrOfSegments();
  ASSERT_EQ(chain.getSegment(ns - 1).getName(), c.tip);

  // KDL's chain index of each moving joint: its rank along the chain.
  std::map<std::string, KdlJoint> chain_joints;
  for (unsigned int i = 0, j = 0; i < ns; ++i) {
    const KDL::Joint& joint = chain.getSegment(i).getJoint();
    if (joint.getType() == KDL::Joint::Fixed) continue;
    chain_joints[joint.getName()] = KdlJoint{j++, joint.getType() == KDL::Joint::TransAxis};
  }
  ASSERT_EQ(chain_joints.size(), chain.getNrOfJoints());
  ASSERT_EQ(model.moving_segments.size(), chain_joints.size());
  ASSERT_EQ(static_cast<std::size_t>(model.nq), chain_joints.size());

  KDL::ChainIdSolver_RNE solver(chain, toKdl(kGravity));
  KDL::JntArray kq(model.nq), kqd(model.nq), kqdd(model.nq), tau(model.nq);
  jle_test::Random rng(4242u);
  Worst worst;
  for (int n = 0; n < 1000; ++n) {
    const State s = randomState(model, rng);
    const std::vector<Load> loads = randomLoads({c.tip}, rng);
    for (int k = 0; k < model.nq; ++k) {
      const unsigned int j = chain_joints.at(model.coordinate_names[k]).q_nr;
      kq(j) = s.q[k];
      kqd(j) = s.qd[k];
      kqdd(j) = s.qdd[k];
    }
    KDL::Wrenches f_ext(ns, KDL::Wrench::Zero());
    f_ext[ns - 1] = KDL::Wrench(toKdl(loads[0].force), toKdl(loads[0].moment));
    ASSERT_GE(solver.CartToJnt(kq, kqd, kqdd, f_ext, tau), 0);
    solve(model, data, s, loads);
    for (int seg : model.moving_segments) {
      const std::string& joint = model.joint_name[seg];
      worst.update(data.effort[seg], tau(chain_joints.at(joint).q_nr), n, "effort of " + joint);
    }
  }
  report(std::string(c.name) + " chain efforts vs ChainIdSolver_RNE", worst, kRelTol);
}

INSTANTIATE_TEST_SUITE_P(Chains, KdlChain, ::testing::ValuesIn(kChains),
                         [](const ::testing::TestParamInfo<ChainCase>& info) {
                           return std::string(info.param.name);
                         });

// ---------------------------------------------------------------------------------------
// 3. All six components of a joint wrench, measured in KDL by six virtual joints.
//
// Joint J (parent P, child C) is rebuilt as  P --J--> gauge_0 --fx--> gauge_1 --fy-->
// gauge_2 --fz--> gauge_3 --mx--> gauge_4 --my--> gauge_5 --mz--> C: J keeps its origin,
// axis and coordinate; the six are prismatic along x, y, z and revolute about x, y, z,
// with identity origins, held at q = qd = qdd = 0; the gauge links are massless. The
// motion of every body is unchanged, every gauge frame is C's frame, and, the gauge links
// being massless, each gauge joint transmits the wrench that reaches C: KDL's efforts of
// fx, fy, fz are its force components and those of mx, my, mz its moment components
// about C's origin (J's origin), all in C's frame, which is jointWrench(..., kChild).

const char* const kGaugeJoints[6] = {"jle_gauge_fx", "jle_gauge_fy", "jle_gauge_fz",
                                     "jle_gauge_mx", "jle_gauge_my", "jle_gauge_mz"};

std::string withWrenchGauge(const std::string& xml, const std::string& joint_name) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.Parse(xml.c_str(), xml.size()), tinyxml2::XML_SUCCESS);
  tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  tinyxml2::XMLElement* joint = robot->FirstChildElement("joint");
  while (joint && joint_name != joint->Attribute("name"))
    joint = joint->NextSiblingElement("joint");
  if (!joint) {
    ADD_FAILURE() << "no joint '" << joint_name << "'";
    return xml;
  }
  tinyxml2::XMLElement* child = joint->FirstChildElement("child");
  const std::string child_link = child->Attribute("link");
  const auto gauge_link = [](int i) { return "jle_gauge_link_" + std::to_string(i); };
  child->SetAttribute("link", gauge_link(0).c_str());
  static const char* const axes[3] = {"1 0 0", "0 1 0", "0 0 1"};
  for (int i = 0; i < 6; ++i) {
    tinyxml2::XMLElement* link = doc.NewElement("link");
    link->SetAttribute("name", gauge_link(i).c_str());  // no <inertial>: massless
    robot->InsertEndChild(link);
    tinyxml2::XMLElement* g = doc.NewElement("joint");
    g->SetAttribute("name", kGaugeJoints[i]);
    g->SetAttribute("type", i < 3 ? "prismatic" : "revolute");
    tinyxml2::XMLElement* parent = g->InsertNewChildElement("parent");
    parent->SetAttribute("link", gauge_link(i).c_str());
    tinyxml2::XMLElement* c = g->InsertNewChildElement("child");
    c->SetAttribute("link", i < 5 ? gauge_link(i + 1).c_str() : child_link.c_str());
    g->InsertNewChildElement("axis")->SetAttribute("xyz", axes[i % 3]);
    tinyxml2::XMLElement* limit = g->InsertNewChildElement("limit");  // urdfdom wants one
    limit->SetAttribute("lower", -1.0);
    limit->SetAttribute("upper", 1.0);
    limit->SetAttribute("effort", 1.0);
    limit->SetAttribute("velocity", 1.0);
    robot->InsertEndChild(g);
  }
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

struct GaugeCase {
  const char* name;
  const char* file;  // under test/data/urdf
  const char* joint;
};

const GaugeCase kGauges[] = {
    {"panda_joint4", "panda.urdf", "panda_joint4"},
    {"panda_finger_joint2_mimic", "panda.urdf", "panda_finger_joint2"},
    {"ur5_elbow", "ur5_robot.urdf", "elbow_joint"},
    {"ur5_shoulder_pan", "ur5_robot.urdf", "shoulder_pan_joint"},
    {"kinova_joint_2", "kinova.urdf", "j2s6s200_joint_2"},
    {"talos_left_knee", "talos_reduced.urdf", "leg_left_4_joint"},
    {"talos_left_hip_yaw", "talos_reduced.urdf", "leg_left_1_joint"},
    {"talos_right_hip_pitch", "talos_reduced.urdf", "leg_right_3_joint"},
    {"talos_torso_1", "talos_reduced.urdf", "torso_1_joint"},
};

std::ostream& operator<<(std::ostream& os, const GaugeCase& c) {
  return os << c.file << " " << c.joint;
}

class KdlWrenchGauge : public ::testing::TestWithParam<GaugeCase> {};

// 200 random states with gravity and random wrenches on every leaf link.
TEST_P(KdlWrenchGauge, SixComponentsAgreeWithTreeIdSolverRne) {
  const GaugeCase& c = GetParam();
  const std::string xml = readFile(urdfPath(c.file));
  const jle::Model<double> model = jle::modelFromUrdfString(xml);
  jle::Data<double> data(model);
  const int seg = model.segmentOfJoint(c.joint);

  const std::string gauged = withWrenchGauge(xml, c.joint);
  const KDL::Tree tree = kdlTree(gauged);
  const std::map<std::string, KdlJoint> kdl_joints = kdlJoints(tree);
  const std::map<std::string, Mimic> mimics = urdfMimics(gauged);
  // The original leaves: the gauge ends on C, so they are the gauged tree's leaves too.
  const std::vector<std::string> leaves = kdlLeaves(kdlTree(xml));
  ASSERT_EQ(kdlLeaves(tree), leaves);
  ASSERT_EQ(kdl_joints.size(), model.moving_segments.size() + 6);
  const std::set<std::string> gauge(std::begin(kGaugeJoints), std::end(kGaugeJoints));

  KDL::TreeIdSolver_RNE solver(tree, toKdl(kGravity));
  KDL::JntArray tau(tree.getNrOfJoints());
  jle_test::Random rng(99u);
  Worst worst;
  for (int n = 0; n < 200; ++n) {
    const State s = randomState(model, rng);
    const std::vector<Load> loads = randomLoads(leaves, rng);
    const KdlState k = toKdlState(model, tree, kdl_joints, mimics, s, gauge);
    ASSERT_GE(solver.CartToJnt(k.q, k.qd, k.qdd, toKdlWrenches(loads), tau), 0);
    solve(model, data, s, loads);
    const jle::Wrench<double> w = jle::jointWrench(model, data, seg, jle::WrenchFrame::kChild);
    for (int a = 0; a < 3; ++a) {
      worst.update(w.force[a], tau(kdl_joints.at(kGaugeJoints[a]).q_nr), n, kGaugeJoints[a]);
      worst.update(w.moment[a], tau(kdl_joints.at(kGaugeJoints[a + 3]).q_nr), n,
                   kGaugeJoints[a + 3]);
    }
    // The gauge does not change J's own effort.
    worst.update(data.effort[seg], tau(kdl_joints.at(c.joint).q_nr), n,
                 std::string("effort of ") + c.joint);
  }
  report(std::string(c.name) + " 6-D joint wrench vs gauged TreeIdSolver_RNE", worst, kRelTol);
}

INSTANTIATE_TEST_SUITE_P(Joints, KdlWrenchGauge, ::testing::ValuesIn(kGauges),
                         [](const ::testing::TestParamInfo<GaugeCase>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
