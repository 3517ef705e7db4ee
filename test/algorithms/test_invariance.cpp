// Invariances of the joint loads: what must not change them (extra frames, a link's mass
// split in two, the choice of world frame, the scalar type) and what must change them
// in a known way (the output frame); and the global Newton-Euler balance of a floating
// humanoid, summed independently from the per-segment kinematics.
#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/random_models.hpp>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using VecX = jle::VectorX<double>;

constexpr double kG = 9.80665;  // [m/s^2]
const Vec3 kGravity(0, 0, -kG);

std::string urdfPath(const std::string& name) {
  return std::string(JLE_TEST_DATA) + "/urdf/" + name;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// ---------------------------------------------------------------------------------
// Random states and wrenches.

using jle_test::State;

// Joint angles over a full turn, rates and accelerations of a fast arm motion; sliders
// (the panda's fingers) within their 4 cm stroke.
State randomState(const jle::Model<double>& model, jle_test::Random& rng) {
  return jle_test::randomState(model, rng, {M_PI, 3.0, 20.0, 0.02, 0.02, 0.1, 1.0});
}

// `x` ordered like from.coordinate_names, reordered like to.coordinate_names.
VecX byName(const VecX& x, const jle::Model<double>& from, const jle::Model<double>& to) {
  VecX out(to.nq);
  for (int k = 0; k < to.nq; ++k) {
    const auto it = std::find(from.coordinate_names.begin(), from.coordinate_names.end(),
                              to.coordinate_names[k]);
    out[k] = x[it - from.coordinate_names.begin()];
  }
  return out;
}

jle::BaseState<double> randomBase(jle_test::Random& rng) {
  return jle_test::randomBase(rng, 2.0, 1.0, 2.0, 5.0, 10.0);
}

// A wrench applied at a named link, in that link's frame or the world.
struct Applied {
  std::string link;
  Vec3 force, moment;
  jle::WrenchFrame frame;
};

std::vector<Applied> randomWrenches(const std::vector<std::string>& links, jle_test::Random& rng) {
  std::vector<Applied> out;
  for (std::size_t k = 0; k < links.size(); ++k)
    out.push_back({links[k], rng.vector(100.0), rng.vector(10.0),
                   k % 2 ? jle::WrenchFrame::kWorld : jle::WrenchFrame::kLocal});
  return out;
}

template <typename Scalar>
void solve(const jle::Model<Scalar>& model, jle::Data<Scalar>& data, const jle::VectorX<Scalar>& q,
           const jle::VectorX<Scalar>& qd, const jle::VectorX<Scalar>& qdd,
           const Eigen::Matrix<Scalar, 3, 1>& gravity, const jle::BaseState<Scalar>& base,
           const std::vector<Applied>& wrenches) {
  jle::forwardKinematics(model, data, q, qd, qdd, gravity, base);
  for (const Applied& w : wrenches)
    jle::addExternalWrench(model, data, model.frameIndex(w.link),
                           Eigen::Matrix<Scalar, 3, 1>(w.force.cast<Scalar>()),
                           Eigen::Matrix<Scalar, 3, 1>(w.moment.cast<Scalar>()), w.frame);
  jle::inverseDynamics(model, data);
}

// Names of the joints whose loads are reported.
std::vector<std::string> movingJoints(const jle::Model<double>& model) {
  std::vector<std::string> out;
  for (int s : model.moving_segments) out.push_back(model.joint_name[s]);
  return out;
}

// ---------------------------------------------------------------------------------
// URDF editing (tinyxml2), with numbers printed to 17 significant digits.

std::string num(double x) {
  std::ostringstream os;
  os << std::setprecision(17) << x;
  return os.str();
}

std::string vec(const Vec3& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

// URDF rpy: R = Rz(yaw) Ry(pitch) Rx(roll).
Mat3 rpyMatrix(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

// The inverse (away from pitch = +-pi/2, which the random poses below never reach).
Vec3 rpyOf(const Mat3& R) {
  return Vec3(std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0))),
              std::atan2(R(1, 0), R(0, 0)));
}

Vec3 attributeVector(const tinyxml2::XMLElement* e, const char* name) {
  const char* text = e ? e->Attribute(name) : nullptr;
  Vec3 v = Vec3::Zero();
  if (text) std::istringstream(text) >> v.x() >> v.y() >> v.z();
  return v;
}

struct Pose {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();
  Pose operator*(const Pose& o) const { return {R * o.R, p + R * o.p}; }
  Pose inverse() const { return {R.transpose(), -(R.transpose() * p)}; }
};

Pose originOf(const tinyxml2::XMLElement* parent) {
  const tinyxml2::XMLElement* o = parent->FirstChildElement("origin");
  return {rpyMatrix(attributeVector(o, "rpy")), attributeVector(o, "xyz")};
}

void setOrigin(tinyxml2::XMLElement* parent, const Pose& pose) {
  tinyxml2::XMLElement* o = parent->FirstChildElement("origin");
  if (!o) o = parent->InsertNewChildElement("origin");
  o->SetAttribute("xyz", vec(pose.p).c_str());
  o->SetAttribute("rpy", vec(rpyOf(pose.R)).c_str());
}

Pose randomPose(jle_test::Random& rng) { return {rpyMatrix(rng.vector(1.2)), rng.vector(0.3)}; }

tinyxml2::XMLElement* addLink(tinyxml2::XMLElement* robot, const std::string& name) {
  tinyxml2::XMLElement* l = robot->InsertNewChildElement("link");
  l->SetAttribute("name", name.c_str());
  return l;
}

void addFixedJoint(tinyxml2::XMLElement* robot, const std::string& name, const std::string& parent,
                   const std::string& child, const Pose& origin) {
  tinyxml2::XMLElement* j = robot->InsertNewChildElement("joint");
  j->SetAttribute("name", name.c_str());
  j->SetAttribute("type", "fixed");
  j->InsertNewChildElement("parent")->SetAttribute("link", parent.c_str());
  j->InsertNewChildElement("child")->SetAttribute("link", child.c_str());
  setOrigin(j, origin);
}

void setInertial(tinyxml2::XMLElement* link, double mass, const Pose& origin, const Mat3& I) {
  tinyxml2::XMLElement* in = link->FirstChildElement("inertial");
  if (!in) in = link->InsertNewChildElement("inertial");
  setOrigin(in, origin);
  tinyxml2::XMLElement* m = in->FirstChildElement("mass");
  if (!m) m = in->InsertNewChildElement("mass");
  m->SetAttribute("value", num(mass).c_str());
  tinyxml2::XMLElement* i = in->FirstChildElement("inertia");
  if (!i) i = in->InsertNewChildElement("inertia");
  const char* names[3][3] = {{"ixx", "ixy", "ixz"}, {"", "iyy", "iyz"}, {"", "", "izz"}};
  for (int r = 0; r < 3; ++r)
    for (int c = r; c < 3; ++c) i->SetAttribute(names[r][c], num(I(r, c)).c_str());
}

std::vector<tinyxml2::XMLElement*> children(tinyxml2::XMLElement* robot, const char* tag) {
  std::vector<tinyxml2::XMLElement*> out;
  for (tinyxml2::XMLElement* e = robot->FirstChildElement(tag); e; e = e->NextSiblingElement(tag))
    out.push_back(e);
  return out;
}

std::string print(const tinyxml2::XMLDocument& doc) {
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

// The same robot with massless frames inserted: before every moving joint a mount link
// at a random pose in the joint's parent (the joint's origin re-expressed from the
// mount, so nothing moves), and on every link a dangling marker link at a random pose,
// half of them with an explicit zero-mass <inertial>.
std::string withMasslessFrames(const std::string& xml, jle_test::Random& rng) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.Parse(xml.c_str()), tinyxml2::XML_SUCCESS);
  tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  for (tinyxml2::XMLElement* j : children(robot, "joint")) {
    const std::string type = j->Attribute("type");
    if (type != "revolute" && type != "continuous" && type != "prismatic") continue;
    const std::string name = j->Attribute("name");
    tinyxml2::XMLElement* parent = j->FirstChildElement("parent");
    const std::string parent_link = parent->Attribute("link");
    const Pose X_parent_mount = randomPose(rng);
    addLink(robot, name + "_mount");
    addFixedJoint(robot, name + "_mount_joint", parent_link, name + "_mount", X_parent_mount);
    parent->SetAttribute("link", (name + "_mount").c_str());
    setOrigin(j, X_parent_mount.inverse() * originOf(j));
  }
  int k = 0;
  for (tinyxml2::XMLElement* l : children(robot, "link")) {
    const std::string name = l->Attribute("name");
    tinyxml2::XMLElement* marker = addLink(robot, name + "_marker");
    if (k++ % 2) setInertial(marker, 0.0, randomPose(rng), Mat3::Zero());
    addFixedJoint(robot, name + "_marker_joint", name, name + "_marker", randomPose(rng));
  }
  return print(doc);
}

// The same robot with the mass of every link split between the link and a new link on
// a fixed joint at a random pose. Link L of mass m, centre c and inertia I (link axes)
// keeps a m at c + (1 - a) s e and gets (1 - a) m at c - a s e: the centre stays at c;
// the two offsets add a m (1 - a) s^2 (1 - e e^T) about c, which the parts' own inertias,
// a and (1 - a) times I minus that, give back. Taking e along the axis of the smallest
// principal moment and s^2 small keeps both parts physical (positive, triangle).
std::string withSplitMasses(const std::string& xml, jle_test::Random& rng) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.Parse(xml.c_str()), tinyxml2::XML_SUCCESS);
  tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  const double a = 0.35;
  for (tinyxml2::XMLElement* l : children(robot, "link")) {
    tinyxml2::XMLElement* in = l->FirstChildElement("inertial");
    if (!in) continue;
    const double m = in->FirstChildElement("mass")->DoubleAttribute("value");
    if (!(m > 0.0)) continue;
    const tinyxml2::XMLElement* ie = in->FirstChildElement("inertia");
    Mat3 I_inertial;
    I_inertial << ie->DoubleAttribute("ixx"), ie->DoubleAttribute("ixy"),
        ie->DoubleAttribute("ixz"), ie->DoubleAttribute("ixy"), ie->DoubleAttribute("iyy"),
        ie->DoubleAttribute("iyz"), ie->DoubleAttribute("ixz"), ie->DoubleAttribute("iyz"),
        ie->DoubleAttribute("izz");
    const Pose X_link_inertial = originOf(in);
    const Mat3 I = X_link_inertial.R * I_inertial * X_link_inertial.R.transpose();
    const Vec3 c = X_link_inertial.p;
    Eigen::SelfAdjointEigenSolver<Mat3> eig(I);
    const Vec3 e = eig.eigenvectors().col(0);
    const double s = std::sqrt(0.3 * eig.eigenvalues()[1] / (m * a * (1 - a)));
    const Mat3 I_rest = I - m * a * (1 - a) * s * s * (Mat3::Identity() - e * e.transpose());

    const std::string name = l->Attribute("name");
    setInertial(l, a * m, Pose{Mat3::Identity(), c + (1 - a) * s * e}, a * I_rest);
    const Pose X_link_part = randomPose(rng);
    const Pose X_part_inertial =
        X_link_part.inverse() * Pose{rpyMatrix(rng.vector(1.2)), c - a * s * e};
    // The inertia of the part, in its inertial axes.
    const Mat3 R = X_link_part.R * X_part_inertial.R;
    tinyxml2::XMLElement* part = addLink(robot, name + "_part");
    setInertial(part, (1 - a) * m, X_part_inertial, R.transpose() * ((1 - a) * I_rest) * R);
    addFixedJoint(robot, name + "_part_joint", name, name + "_part", X_link_part);
  }
  return print(doc);
}

// The size of the terms a joint's moment is summed from: its own moment and its force
// at the reach of these robots (about 1 m; no lever arm in them is longer). A joint's
// moment may be small against those terms (a finger's, about its slide), so relative
// to that sum, not to the moment alone, is where rounding errors are measured.
constexpr double kReach = 1.0;  // [m]

double momentScale(const Vec3& force, const Vec3& moment) {
  return moment.norm() + kReach * force.norm();
}

// Loads of the joints `names` in both models: forces (and prismatic efforts) within
// `rel` of the joint's force, moments (and revolute efforts) within `rel` of
// momentScale.
void expectSameLoads(const jle::Model<double>& ma, const jle::Data<double>& da,
                     const jle::Model<double>& mb, const jle::Data<double>& db,
                     const std::vector<std::string>& names, double rel) {
  for (const std::string& name : names) {
    const int a = ma.segmentOfJoint(name), b = mb.segmentOfJoint(name);
    const double fs = da.force[a].norm(), ms = momentScale(da.force[a], da.moment[a]);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(db.force[b][k], da.force[a][k], rel * fs) << name << " force " << k;
      EXPECT_NEAR(db.moment[b][k], da.moment[a][k], rel * ms) << name << " moment " << k;
    }
    const double es = ma.joint_type[a] == jle::JointType::kPrismatic ? fs : ms;
    EXPECT_NEAR(db.effort[b], da.effort[a], rel * es) << name << " effort";
  }
}

// ---------------------------------------------------------------------------------
// Extra fixed-joint frames change nothing.

// Tolerance: the edited models hold the same mass distribution up to the rounding of
// the re-expressed poses and inertias (printed to 17 digits, but the rpy of a
// re-expressed joint origin is only good to a few ulp) and of the lumping sums, so the
// loads agree to some eps of each joint's own load (forces; momentScale for moments).
// Largest difference measured: 6.2e-15 (28 eps, panda_joint1's force with mounts
// inserted; the split masses stay under 1.6 eps); 1e-12 leaves a margin of 160.
constexpr double kSameRobotRel = 1e-12;

class SameRobot : public testing::TestWithParam<std::string> {};

TEST_P(SameRobot, MasslessFramesChangeNoLoad) {
  const std::string xml = readFile(urdfPath(GetParam()));
  jle_test::Random rng(61);
  const jle::Model<double> original = jle::modelFromUrdfString(xml);
  const jle::Model<double> edited = jle::modelFromUrdfString(withMasslessFrames(xml, rng));
  // The edit really added frames, none of them a segment.
  ASSERT_GT(edited.frames.size(), 2 * original.frames.size());
  ASSERT_EQ(edited.nsegments(), original.nsegments());
  const std::vector<std::string> joints = movingJoints(original);
  const std::string tip = original.frames.back().name;
  jle::Data<double> da(original), db(edited);
  for (int trial = 0; trial < 20; ++trial) {
    const State s = randomState(original, rng);
    const std::vector<Applied> w = randomWrenches({tip, original.link_name[1]}, rng);
    solve(original, da, s.q, s.qd, s.qdd, kGravity, {}, w);
    solve(edited, db, byName(s.q, original, edited), byName(s.qd, original, edited),
          byName(s.qdd, original, edited), kGravity, {}, w);
    expectSameLoads(original, da, edited, db, joints, kSameRobotRel);
  }
}

TEST_P(SameRobot, SplitMassesChangeNoLoad) {
  const std::string xml = readFile(urdfPath(GetParam()));
  jle_test::Random rng(62);
  const jle::Model<double> original = jle::modelFromUrdfString(xml);
  const jle::Model<double> edited = jle::modelFromUrdfString(withSplitMasses(xml, rng));
  ASSERT_GT(edited.frames.size(), original.frames.size());
  ASSERT_EQ(edited.nsegments(), original.nsegments());
  EXPECT_NEAR(edited.totalMass(), original.totalMass(), 1e-12 * original.totalMass());
  const std::vector<std::string> joints = movingJoints(original);
  const std::string tip = original.frames.back().name;
  jle::Data<double> da(original), db(edited);
  for (int trial = 0; trial < 20; ++trial) {
    const State s = randomState(original, rng);
    const std::vector<Applied> w = randomWrenches({tip}, rng);
    solve(original, da, s.q, s.qd, s.qdd, kGravity, {}, w);
    solve(edited, db, byName(s.q, original, edited), byName(s.qd, original, edited),
          byName(s.qdd, original, edited), kGravity, {}, w);
    expectSameLoads(original, da, edited, db, joints, kSameRobotRel);
  }
}

INSTANTIATE_TEST_SUITE_P(Arms, SameRobot, testing::Values("panda.urdf", "ur5_robot.urdf"));

// ---------------------------------------------------------------------------------
// Another world frame: turn and shift the whole scene (base pose, gravity, base motion,
// world-frame wrenches) by (R, p). The child-frame loads must not change; the
// world-frame loads turn by R.

// Tolerance: the turned scene rounds gravity, the base motion and the wrenches once
// more (1 ulp each), and the forward pass carries that through the chain; the largest
// difference measured is 2.3e-15 of the joint's own load (10 eps; momentScale for
// moments), and 1e-11 leaves a margin of 4000.
constexpr double kWorldFrameRel = 1e-11;

struct Scene {
  std::string urdf;
  bool floating;
  std::vector<std::string> wrench_links;
};

void PrintTo(const Scene& scene, std::ostream* os) { *os << scene.urdf; }

class WorldFrame : public testing::TestWithParam<Scene> {};

TEST_P(WorldFrame, ChildFrameLoadsDoNotDependOnIt) {
  const Scene& scene = GetParam();
  jle::ModelOptions options;
  options.floating_base = scene.floating;
  const jle::Model<double> model = jle::modelFromUrdfFile(urdfPath(scene.urdf), options);
  jle::Data<double> da(model), db(model);
  const std::vector<std::string> joints = movingJoints(model);
  jle_test::Random rng(71);
  for (int trial = 0; trial < 20; ++trial) {
    const State s = randomState(model, rng);
    jle::BaseState<double> base;  // the reference scene: the base at the world origin
    if (scene.floating) {
      base.v_world = rng.vector(1.0);
      base.omega_world = rng.vector(2.0);
      base.a_world = rng.vector(5.0);
      base.alpha_world = rng.vector(10.0);
    }
    const std::vector<Applied> w = randomWrenches(scene.wrench_links, rng);

    const Mat3 R = rng.rotation();
    jle::BaseState<double> moved;
    moved.R_world_base = R;
    moved.p_world_base = rng.vector(5.0);
    moved.v_world = R * base.v_world;
    moved.omega_world = R * base.omega_world;
    moved.a_world = R * base.a_world;
    moved.alpha_world = R * base.alpha_world;
    std::vector<Applied> w_moved = w;
    for (Applied& a : w_moved)
      if (a.frame == jle::WrenchFrame::kWorld) {
        a.force = R * a.force;
        a.moment = R * a.moment;
      }

    solve(model, da, s.q, s.qd, s.qdd, kGravity, base, w);
    solve(model, db, s.q, s.qd, s.qdd, Vec3(R * kGravity), moved, w_moved);
    expectSameLoads(model, da, model, db, joints, kWorldFrameRel);
    for (int i = 0; i < model.nsegments(); ++i) {
      const jle::Wrench<double> wa = jle::jointWrench(model, da, i, jle::WrenchFrame::kWorld);
      const jle::Wrench<double> wb = jle::jointWrench(model, db, i, jle::WrenchFrame::kWorld);
      const Vec3 f = R * wa.force, m = R * wa.moment;
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(wb.force[k], f[k], kWorldFrameRel * wa.force.norm()) << i << " " << k;
        EXPECT_NEAR(wb.moment[k], m[k], kWorldFrameRel * momentScale(wa.force, wa.moment))
            << i << " " << k;
      }
    }
    // The base reaction (fixed) or residual (floating), in the base frame, too.
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(db.force[0][k], da.force[0][k], kWorldFrameRel * da.force[0].norm());
      EXPECT_NEAR(db.moment[0][k], da.moment[0][k],
                  kWorldFrameRel * momentScale(da.force[0], da.moment[0]));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Robots, WorldFrame,
    testing::Values(Scene{"panda.urdf", false, {"panda_hand_tcp", "panda_link5"}},
                    Scene{"talos_reduced.urdf",
                          true,
                          {"left_sole_link", "right_sole_link", "wrist_left_ft_tool_link",
                           "wrist_right_ft_tool_link"}}));

// ---------------------------------------------------------------------------------
// float, double and long double.
//
// The same model (model.cast) and the same inputs (values representable in float, so
// that all three types start from identical numbers) in the three types; the loads
// compared with long double's. The error of a joint's force is taken relative to the
// largest force of the robot, that of its moment relative to the largest moment: the
// rounding errors come from the large terms (the base and thigh loads, the arm's
// weight times its reach), not from the joint's own load, which may be small.
// Measured worst case over 1000 random states with external wrenches (the test runs
// 20 and records its worst as the property "measured"):
//   double: 1.2e-15 (panda), 1.4e-15 (talos), a few of double's eps (2.2e-16) -> bound
//   1e-13, a margin of 70;
//   float: 6.4e-7 (panda), 5.9e-7 (talos), some five of float's eps (1.2e-7), what a
//   chain of a dozen rotations accumulates -> bound 1e-5, a margin of 15.

// Every segment's joint force and moment, widened to long double.
struct Loads {
  std::vector<Eigen::Matrix<long double, 3, 1>> force, moment;
};

template <typename Scalar>
Loads loadsIn(const jle::Model<double>& model_double, const State& s, const Vec3& gravity,
              const jle::BaseState<double>& base_double, const std::vector<Applied>& wrenches) {
  const jle::Model<Scalar> model = model_double.template cast<Scalar>();
  const jle::BaseState<Scalar> base = jle_test::castBase<Scalar>(base_double);
  jle::Data<Scalar> data(model);
  solve(model, data, jle::VectorX<Scalar>(s.q.cast<Scalar>()),
        jle::VectorX<Scalar>(s.qd.cast<Scalar>()), jle::VectorX<Scalar>(s.qdd.cast<Scalar>()),
        Eigen::Matrix<Scalar, 3, 1>(gravity.cast<Scalar>()), base, wrenches);
  Loads out;
  for (int i = 0; i < model.nsegments(); ++i) {
    out.force.push_back(data.force[i].template cast<long double>());
    out.moment.push_back(data.moment[i].template cast<long double>());
  }
  return out;
}

// Largest difference from the reference, relative to the reference's largest force
// (moment); the larger of the two.
double relativeError(const Loads& x, const Loads& ref) {
  long double fmax = 0, mmax = 0, ferr = 0, merr = 0;
  for (std::size_t i = 0; i < ref.force.size(); ++i) {
    fmax = std::max(fmax, ref.force[i].norm());
    mmax = std::max(mmax, ref.moment[i].norm());
    ferr = std::max(ferr, (x.force[i] - ref.force[i]).norm());
    merr = std::max(merr, (x.moment[i] - ref.moment[i]).norm());
  }
  return static_cast<double>(std::max(ferr / fmax, merr / mmax));
}

// Rounds to the nearest float, so that every type starts from the same numbers.
VecX toFloat(const VecX& x) { return x.cast<float>().cast<double>(); }
Vec3 toFloat(const Vec3& x) { return x.cast<float>().cast<double>(); }

class Precision : public testing::TestWithParam<Scene> {};

TEST_P(Precision, FloatDoubleAndLongDoubleAgree) {
  const Scene& scene = GetParam();
  jle::ModelOptions options;
  options.floating_base = scene.floating;
  // The model itself rounded to float, so that the types share it exactly.
  const jle::Model<double> model =
      jle::modelFromUrdfFile(urdfPath(scene.urdf), options).cast<float>().cast<double>();
  jle_test::Random rng(81);
  double worst_double = 0, worst_float = 0;
  for (int trial = 0; trial < 20; ++trial) {
    State s = randomState(model, rng);
    s = {toFloat(s.q), toFloat(s.qd), toFloat(s.qdd)};
    jle::BaseState<double> base;
    if (scene.floating) {
      base.R_world_base = rng.rotation().cast<float>().cast<double>();
      base.p_world_base = toFloat(rng.vector(2.0));
      base.omega_world = toFloat(rng.vector(2.0));
      base.a_world = toFloat(rng.vector(5.0));
      base.alpha_world = toFloat(rng.vector(10.0));
    }
    std::vector<Applied> w = randomWrenches(scene.wrench_links, rng);
    for (Applied& a : w) {
      a.force = toFloat(a.force);
      a.moment = toFloat(a.moment);
    }
    const Vec3 gravity = toFloat(kGravity);
    const Loads ref = loadsIn<long double>(model, s, gravity, base, w);
    const double e_double = relativeError(loadsIn<double>(model, s, gravity, base, w), ref);
    const double e_float = relativeError(loadsIn<float>(model, s, gravity, base, w), ref);
    EXPECT_LT(e_double, 1e-13) << "trial " << trial;
    EXPECT_LT(e_float, 1e-5) << "trial " << trial;
    worst_double = std::max(worst_double, e_double);
    worst_float = std::max(worst_float, e_float);
  }
  // The comparison is not vacuous: float really is coarser than double.
  EXPECT_GT(worst_float, 1e3 * worst_double);
  std::ostringstream measured;
  measured << "worst relative error: double " << worst_double << ", float " << worst_float;
  RecordProperty("measured", measured.str());
}

INSTANTIATE_TEST_SUITE_P(
    Robots, Precision,
    testing::Values(Scene{"panda.urdf", false, {"panda_hand_tcp", "panda_link5"}},
                    Scene{"talos_reduced.urdf",
                          true,
                          {"left_sole_link", "right_sole_link", "wrist_left_ft_tool_link",
                           "wrist_right_ft_tool_link"}}));

// ---------------------------------------------------------------------------------
// Output frames of jointWrench.

// The URDF parent link of every joint, read from the file.
std::map<std::string, std::string> parentLinks(const std::string& xml) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.Parse(xml.c_str()), tinyxml2::XML_SUCCESS);
  std::map<std::string, std::string> out;
  for (tinyxml2::XMLElement* j : children(doc.FirstChildElement("robot"), "joint"))
    out[j->Attribute("name")] = j->FirstChildElement("parent")->Attribute("link");
  return out;
}

// Tolerance: the rotations compared are products along the chain, built in a different
// order here (world rotations of both links) than in jointWrench (the joint's own
// rotation); measured 1.3e-15 of the force (momentScale for moments), 6 eps; bound
// 1e-13, a margin of 80, while a wrong frame would be off by the wrench itself.
constexpr double kFrameRel = 1e-13;

TEST(JointWrenchFrames, ParentAndWorldAreTheChildWrenchRotated) {
  struct Case {
    std::string urdf;
    std::vector<std::string> keep;
  };
  // Panda: the fingers' parent (panda_hand) is lumped into panda_link7's segment, turned
  // by -45 degrees; the kept hand mount's parent (panda_link8) too. Talos: many lumped
  // links, the force-torque sensor mounts kept.
  for (const Case& c :
       {Case{"panda.urdf", {"panda_joint8"}},
        Case{"talos_reduced.urdf", {"wrist_left_ft_joint", "wrist_right_ft_joint"}}}) {
    const std::string xml = readFile(urdfPath(c.urdf));
    jle::ModelOptions options;
    options.keep_fixed_joints = c.keep;
    const jle::Model<double> model = jle::modelFromUrdfString(xml, options);
    const std::map<std::string, std::string> parent_of = parentLinks(xml);
    jle::Data<double> data(model);
    jle_test::Random rng(91);
    int lumped_parents = 0;
    for (int trial = 0; trial < 10; ++trial) {
      const State s = randomState(model, rng);
      jle::BaseState<double> base;
      base.R_world_base = rng.rotation();
      solve(model, data, s.q, s.qd, s.qdd, kGravity, base,
            randomWrenches({model.frames.back().name}, rng));
      for (int i = 1; i < model.nsegments(); ++i) {
        const std::string& joint = model.joint_name[i];
        const jle::Frame<double>& child = model.frames[model.frameIndex(model.link_name[i])];
        const jle::Frame<double>& parent = model.frames[model.frameIndex(parent_of.at(joint))];
        if (trial == 0 && parent.segment != model.parent[i]) ADD_FAILURE() << joint;
        if (trial == 0 && !parent.R_segment_frame.isIdentity(1e-12)) ++lumped_parents;
        const Mat3 R_world_child = data.R_world[child.segment] * child.R_segment_frame;
        const Mat3 R_world_parent = data.R_world[parent.segment] * parent.R_segment_frame;
        const Vec3& f = data.force[i];
        const Vec3& m = data.moment[i];
        const jle::Wrench<double> in_child =
            jle::jointWrench(model, data, i, jle::WrenchFrame::kChild);
        const jle::Wrench<double> in_parent =
            jle::jointWrench(model, data, i, jle::WrenchFrame::kParent);
        const jle::Wrench<double> in_world =
            jle::jointWrench(model, data, i, jle::WrenchFrame::kWorld);
        const Mat3 R_parent_child = R_world_parent.transpose() * R_world_child;
        const Vec3 f_parent = R_parent_child * f, m_parent = R_parent_child * m;
        const Vec3 f_world = R_world_child * f, m_world = R_world_child * m;
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(in_child.force[k], f[k]) << joint;
          EXPECT_EQ(in_child.moment[k], m[k]) << joint;
          EXPECT_NEAR(in_parent.force[k], f_parent[k], kFrameRel * f.norm()) << joint;
          EXPECT_NEAR(in_parent.moment[k], m_parent[k], kFrameRel * momentScale(f, m)) << joint;
          EXPECT_NEAR(in_world.force[k], f_world[k], kFrameRel * f.norm()) << joint;
          EXPECT_NEAR(in_world.moment[k], m_world[k], kFrameRel * momentScale(f, m)) << joint;
        }
      }
    }
    // The case that needs R_parentsegment_parentlink was exercised.
    EXPECT_GT(lumped_parents, 0) << c.urdf;
  }
}

// ---------------------------------------------------------------------------------
// Newton-Euler for the whole floating humanoid: the residual at the root is what the
// external loads fail to explain of the rate of change of the total momentum,
//   F_res = sum_i m_i a_Gi - sum_k F_k - m_total g
//   M_res = sum_i (J_i alpha_i + w_i x J_i w_i + (x_Gi - x_0) x m_i (a_Gi - g))
//           - sum_k ((x_k - x_0) x F_k + M_k)
// about the root origin x_0, world frame; summed here over the segments from their own
// kinematics, with no joint load involved.

// Tolerance: relative to the sum of the magnitudes of the terms (the momentum rates,
// the applied wrenches and the weights with their lever arms); measured 4.2e-16 of it
// (2 eps); bound 1e-13, a margin of 240 (the library's sum runs through some 40 joints).
constexpr double kBalanceRel = 1e-13;

TEST(NewtonEuler, FloatingTalosResidualIsTheGlobalMomentumBalance) {
  jle::ModelOptions options;
  options.floating_base = true;
  const jle::Model<double> model = jle::modelFromUrdfFile(urdfPath("talos_reduced.urdf"), options);
  jle::Data<double> data(model);
  const std::vector<std::string> links = {
      "left_sole_link",           "right_sole_link", "wrist_left_ft_tool_link",
      "wrist_right_ft_tool_link", "head_2_link",     "torso_2_link"};
  jle_test::Random rng(101);
  for (int trial = 0; trial < 20; ++trial) {
    const State s = randomState(model, rng);
    const jle::BaseState<double> base = randomBase(rng);
    const std::vector<Applied> w = randomWrenches(links, rng);
    solve(model, data, s.q, s.qd, s.qdd, kGravity, base, w);

    const Vec3 x0 = base.p_world_base;
    Vec3 F = Vec3::Zero(), M = Vec3::Zero();
    double f_scale = 0, m_scale = 0;
    for (int i = 0; i < model.nsegments(); ++i) {
      const double m = model.mass[i];
      const Vec3 a_G = jle::comAccelerationWorld(model, data, i, kGravity);
      const Vec3 r = jle::comWorld(model, data, i) - x0;
      const Vec3 w_i = jle::omegaWorld(data, i), al = jle::alphaWorld(data, i);
      const Mat3 J = data.R_world[i] * model.inertia_com[i] * data.R_world[i].transpose();
      F += m * (a_G - kGravity);
      M += J * al + w_i.cross(J * w_i) + r.cross(m * (a_G - kGravity));
      f_scale += m * (a_G.norm() + kG);
      m_scale += J.norm() * (al.norm() + w_i.squaredNorm()) + r.norm() * m * (a_G.norm() + kG);
    }
    for (const Applied& a : w) {
      const jle::Frame<double>& fr = model.frames[model.frameIndex(a.link)];
      const Mat3 R_world_frame = data.R_world[fr.segment] * fr.R_segment_frame;
      const Vec3 x = data.p_world[fr.segment] + data.R_world[fr.segment] * fr.p_segment_frame;
      const Vec3 f = a.frame == jle::WrenchFrame::kWorld ? a.force : Vec3(R_world_frame * a.force);
      const Vec3 n =
          a.frame == jle::WrenchFrame::kWorld ? a.moment : Vec3(R_world_frame * a.moment);
      F -= f;
      M -= (x - x0).cross(f) + n;
      f_scale += f.norm();
      m_scale += (x - x0).norm() * f.norm() + n.norm();
    }
    const Vec3 F_res = data.R_world[0] * data.force[0];
    const Vec3 M_res = data.R_world[0] * data.moment[0];
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(F_res[k], F[k], kBalanceRel * f_scale) << "trial " << trial;
      EXPECT_NEAR(M_res[k], M[k], kBalanceRel * m_scale) << "trial " << trial;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
