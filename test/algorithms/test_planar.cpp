// The planar 3x3 path (planar.hpp, savings.planar) against the 6x6 path and the
// closed form of the paper's planar foot: random planar chains and trees, detection,
// forced mode, the per-sample fallback for out-of-plane wrenches (no allocation per
// sample: test_no_allocation.cpp).
//
// Tolerance: the two paths evaluate the same physics along different sums (world-plane
// 2-D sums against sums in each segment frame), so they agree to a few units of double
// rounding times the magnitude of the loads. Each comparison is relative to the largest
// force (or moment) of the sample over all segments (`scale`); the bound 1e-12 is the
// one the saving promises, and any missing term (a lever arm along n, a sign) would be
// of the order of the scale itself.
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/planar.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/papers_foot.hpp>
#include <jle_testing/random_models.hpp>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
const std::string kData = JLE_TEST_DATA;
constexpr double kRel = 1e-12;  // see the file comment
constexpr double kG = 9.80665;

using jle_test::detail::num;
using jle_test::detail::vec;

// ---------------------------------------------------------------------------------
// Random planar models. Every joint placement is a rotation about the parent's normal
// times one of the 24 rotations of the cube (so the normal lands on any signed axis of
// the child, or anywhere when the root normal is oblique), written as URDF rpy with 17
// digits: the reader's rounding (1e-16) is far inside the detection tolerance.

struct PlanarSpec {
  int joints = 6;
  bool tree = false;
  Vec3 normal = Vec3::UnitZ();  ///< root frame
  bool offsets = true;          ///< joint origins and centres of mass off the plane
  int prismatic_every = 0;      ///< every n-th joint prismatic (0: none)
  std::uint32_t seed = 1;
};

struct PlanarRobot {
  std::string urdf;
  Vec3 gravity;                  ///< root frame, perpendicular to the normal
  std::vector<Vec3> tip_normal;  ///< n in the frame of link tipK (K = 1..joints)
};

Mat3 cubeRotation(jle_test::Random& rng) {
  // A random signed permutation with determinant +1.
  static const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  const int* p = perms[rng.index(6)];
  Mat3 P = Mat3::Zero();
  for (int c = 0; c < 3; ++c) P(p[c], c) = rng.uniform(0, 1) < 0.5 ? -1.0 : 1.0;
  if (P.determinant() < 0) P.col(2) *= -1.0;
  return P;
}

std::string rpyOf(const Mat3& R) {
  const Vec3 ypr = R.eulerAngles(2, 1, 0);  // R = Rz(y) Ry(p) Rx(r), URDF's rpy
  return vec(Vec3(ypr[2], ypr[1], ypr[0]));
}

// A unit vector perpendicular to n.
Vec3 inPlane(jle_test::Random& rng, const Vec3& n) {
  Vec3 v;
  do v = rng.unitVector().cross(n);
  while (v.norm() < 0.1);
  return v.normalized();
}

PlanarRobot randomPlanar(const PlanarSpec& spec) {
  jle_test::Random rng(spec.seed);
  PlanarRobot out;
  const Vec3 n0 = spec.normal.normalized();
  out.gravity = kG * inPlane(rng, n0);
  std::vector<Mat3> R_root(1, Mat3::Identity());  // link frames at q = 0
  std::string xml = "<?xml version=\"1.0\"?>\n<robot name=\"planar\">\n";
  auto link = [&](int k, const Vec3& n) {
    const double m = rng.logUniform(0.5, 5.0);
    const Vec3 e1 = inPlane(rng, n), e2 = n.cross(e1);
    const double a = rng.uniform(0.05, 0.3), b = rng.uniform(0.05, 0.3), c = rng.uniform(0.05, 0.3);
    // A box of sides a, b, c, its c side along n: n is a principal axis.
    const Mat3 J = m / 12.0 *
                   ((b * b + c * c) * e1 * e1.transpose() + (a * a + c * c) * e2 * e2.transpose() +
                    (a * a + b * b) * n * n.transpose());
    Vec3 com = 0.2 * rng.uniform(0, 1) * inPlane(rng, n);
    if (spec.offsets) com += rng.uniform(-0.1, 0.1) * n;
    xml += "<link name=\"link" + std::to_string(k) + "\"><inertial><origin xyz=\"" + vec(com) +
           "\"/><mass value=\"" + num(m) + "\"/><inertia ixx=\"" + num(J(0, 0)) + "\" ixy=\"" +
           num(J(0, 1)) + "\" ixz=\"" + num(J(0, 2)) + "\" iyy=\"" + num(J(1, 1)) + "\" iyz=\"" +
           num(J(1, 2)) + "\" izz=\"" + num(J(2, 2)) + "\"/></inertial></link>\n";
  };
  link(0, n0);
  out.tip_normal.push_back(Vec3::Zero());
  for (int k = 1; k <= spec.joints; ++k) {
    const int parent = spec.tree ? rng.index(k) : k - 1;
    // Normalized: an axis of length 1 - 1e-16 makes AngleAxis a little non-orthogonal,
    // and that compounds down a chain.
    const Vec3 n_p = (R_root[parent].transpose() * n0).normalized();
    // Away from rpy's gimbal lock (pitch near +-pi/2), where the angles, hence the
    // matrix the reader rebuilds, lose digits (1e-13 measured).
    Mat3 R_pj;
    do
      R_pj =
          Eigen::AngleAxisd(rng.uniform(-M_PI, M_PI), n_p).toRotationMatrix() * cubeRotation(rng);
    while (std::abs(R_pj(2, 0)) > 0.9);
    R_root.push_back(R_root[parent] * R_pj);
    const Vec3 n_c = R_pj.transpose() * n_p;
    Vec3 xyz = 0.3 * rng.uniform(0.3, 1.0) * inPlane(rng, n_p);
    if (spec.offsets) xyz += rng.uniform(-0.1, 0.1) * n_p;
    const bool prismatic = spec.prismatic_every > 0 && k % spec.prismatic_every == 0;
    const Vec3 axis = prismatic ? inPlane(rng, n_c) : (rng.uniform(0, 1) < 0.5 ? -n_c : n_c);
    link(k, n_c);
    xml += "<joint name=\"j" + std::to_string(k) + "\" type=\"" +
           (prismatic ? "prismatic" : "revolute") + "\"><parent link=\"link" +
           std::to_string(parent) + "\"/><child link=\"link" + std::to_string(k) +
           "\"/><origin xyz=\"" + vec(xyz) + "\" rpy=\"" + rpyOf(R_pj) + "\"/><axis xyz=\"" +
           vec(axis) +
           "\"/><limit lower=\"-1e9\" upper=\"1e9\" effort=\"1e9\" velocity=\"1e9\"/></joint>\n";
    // A massless tool frame on every link, turned arbitrarily: wrench inputs act there.
    Mat3 R_tip;
    do R_tip = Eigen::AngleAxisd(rng.uniform(-M_PI, M_PI), rng.unitVector()).toRotationMatrix();
    while (std::abs(R_tip(2, 0)) > 0.9);
    Vec3 tip = 0.2 * rng.uniform(0, 1) * inPlane(rng, n_c);
    if (spec.offsets) tip += rng.uniform(-0.1, 0.1) * n_c;
    xml += "<link name=\"tip" + std::to_string(k) + "\"/><joint name=\"tip" + std::to_string(k) +
           "_joint\" type=\"fixed\"><parent link=\"link" + std::to_string(k) +
           "\"/><child link=\"tip" + std::to_string(k) + "\"/><origin xyz=\"" + vec(tip) +
           "\" rpy=\"" + rpyOf(R_tip) + "\"/></joint>\n";
    out.tip_normal.push_back(R_tip.transpose() * n_c);
  }
  out.urdf = xml + "</robot>\n";
  return out;
}

struct Loads {
  std::vector<Vec3> force, moment;
  std::vector<double> effort;
};

Loads loadsOf(const jle::Data<double>& d, const std::vector<int>& segments) {
  Loads l;
  for (int i : segments) {
    l.force.push_back(d.force[i]);
    l.moment.push_back(d.moment[i]);
    l.effort.push_back(d.effort[i]);
  }
  return l;
}

// Largest relative difference (per the file comment's scales); also checked here.
double expectClose(const Loads& planar, const Loads& full, double rel, const std::string& what) {
  double f_scale = 0, m_scale = 0, worst = 0;
  for (std::size_t i = 0; i < full.force.size(); ++i) {
    f_scale = std::max(f_scale, full.force[i].norm());
    m_scale = std::max(m_scale, full.moment[i].norm());
  }
  for (std::size_t i = 0; i < full.force.size(); ++i) {
    const double ef = (planar.force[i] - full.force[i]).norm() / f_scale;
    const double em = (planar.moment[i] - full.moment[i]).norm() / m_scale;
    const double ee = std::abs(planar.effort[i] - full.effort[i]) / std::max(f_scale, m_scale);
    EXPECT_LE(ef, rel) << what << " segment " << i;
    EXPECT_LE(em, rel) << what << " segment " << i;
    EXPECT_LE(ee, rel) << what << " segment " << i;
    worst = std::max({worst, ef, em, ee});
  }
  return worst;
}

std::vector<int> allSegments(const jle::Model<double>& m) {
  std::vector<int> s;
  for (int i = 0; i < m.nsegments(); ++i) s.push_back(i);
  return s;
}

// In-plane wrench for a frame whose normal is n (link frame): force across n, moment along n.
void inPlaneWrench(jle_test::Random& rng, const Vec3& n, Vec3& f, Vec3& m) {
  f = rng.uniform(-50, 50) * inPlane(rng, n);
  m = rng.uniform(-5, 5) * n;
}

TEST(Planar, RandomChainsAndTreesMatchThe6x6Path) {
  double worst = 0;
  int cases = 0;
  for (int variant = 0; variant < 8; ++variant) {
    PlanarSpec spec;
    spec.joints = 3 + 5 * variant;
    spec.tree = variant % 2 == 1;
    spec.offsets = variant % 4 != 0;
    spec.prismatic_every = variant >= 4 ? 3 : 0;
    // An oblique normal (not along an axis of any frame) for half of them.
    spec.normal = variant % 3 == 0 ? Vec3::UnitZ() : Vec3(1, 2, 2);
    spec.seed = 100 + variant;
    const PlanarRobot robot = randomPlanar(spec);
    const jle::Model<double> model = jle::modelFromUrdfString(robot.urdf);
    const jle::PlanarCheck<double> check = jle::detectPlanar(model, robot.gravity);
    ASSERT_TRUE(check.planar) << check.reason;
    const jle::PlanarModel<double> pm = jle::planarModel(model, check.normal);
    EXPECT_EQ(pm.offsets, spec.offsets);
    jle::PlanarData<double> pd(model.nsegments());
    jle::Data<double> planar(model), full(model);
    const std::vector<int> segments = allSegments(model);
    jle_test::Random rng(spec.seed + 7);
    for (int trial = 0; trial < 20; ++trial) {
      const jle_test::State s = jle_test::randomState(model, rng, 3.0, 20.0);
      jle::forwardKinematics(model, full, s.q, s.qd, s.qdd, robot.gravity);
      jle::planarKinematics(model, pm, pd, s.q, s.qd, s.qdd, robot.gravity, segments);
      for (int k = 1; k <= spec.joints; k += 2) {
        Vec3 f, m;
        inPlaneWrench(rng, robot.tip_normal[k], f, m);
        const int frame = model.frameIndex("tip" + std::to_string(k));
        ASSERT_TRUE(jle::planarWrenchInPlane(pm, frame, f, m));
        jle::addExternalWrench(model, full, frame, f, m, jle::WrenchFrame::kLocal);
        jle::planarAddExternalWrench(model, pm, pd, frame, f, m);
      }
      jle::inverseDynamics(model, full);
      jle::planarInverseDynamics(model, pm, pd, planar, segments);
      worst = std::max(worst, expectClose(loadsOf(planar, segments), loadsOf(full, segments), kRel,
                                          "variant " + std::to_string(variant)));
      ++cases;
    }
  }
  EXPECT_EQ(cases, 160);
  std::printf("planar vs 6x6: largest relative difference %.2g\n", worst);
}

// ---------------------------------------------------------------------------------
// Through the estimator: auto (planar) against off, same samples, wrench inputs.

struct EstimatorRun {
  std::vector<Loads> loads;
  int planar = 0;
};

EstimatorRun runEstimator(const jle::Model<double>& model, jle::EstimatorConfig config,
                          const std::function<void(jle::Estimator&, int, double)>& wrenches,
                          int n = 80) {
  jle::Estimator estimator(model, config);
  EstimatorRun out;
  Eigen::VectorXd q(model.nq);
  for (int k = 0; k < n; ++k) {
    const double t = 1e-3 * k;
    for (int i = 0; i < model.nq; ++i) q[i] = 0.5 * std::sin(3 * t + i) + 0.1 * i;
    wrenches(estimator, k, t);
    if (estimator.addJointSample(t, q.data()) != jle::SampleStatus::kPublished) continue;
    out.loads.push_back(loadsOf(estimator.last().data(), estimator.layout().dynamicsSegments()));
    out.planar += estimator.last().planar();
  }
  return out;
}

jle::EstimatorConfig withPlanar(jle::PlanarMode mode) {
  jle::EstimatorConfig c;
  c.differentiator.type = jle::DifferentiatorType::kFiniteDifference;
  c.savings.planar = mode;
  return c;
}

TEST(Planar, EstimatorAutoMatchesOffOnATreeWithWrenchInputs) {
  PlanarSpec spec;
  spec.joints = 9;
  spec.tree = true;
  spec.prismatic_every = 4;
  spec.normal = Vec3(0, 1, 0);
  spec.seed = 7;
  const PlanarRobot robot = randomPlanar(spec);
  const jle::Model<double> model = jle::modelFromUrdfString(robot.urdf);
  jle::EstimatorConfig on = withPlanar(jle::PlanarMode::kAuto),
                       off = withPlanar(jle::PlanarMode::kOff);
  for (jle::EstimatorConfig* c : {&on, &off}) {
    c->gravity_world = robot.gravity;
    for (int k : {2, 5, 9}) {
      jle::WrenchInputConfig w;
      w.name = w.link = "tip" + std::to_string(k);
      w.sign = k == 5 ? -1.0 : 1.0;
      c->wrenches.push_back(w);
    }
  }
  jle::Estimator probe(model, on);
  EXPECT_TRUE(probe.layout().planar()) << probe.layout().planarReason();
  auto feed = [&](jle::Estimator& e, int, double t) {
    int input = 0;
    for (int k : {2, 5, 9}) {
      const Vec3& n = robot.tip_normal[k];
      const Vec3 across =
          n.cross(Vec3(1, 0, 0)).norm() > 0.1 ? n.cross(Vec3(1, 0, 0)) : n.cross(Vec3(0, 1, 0));
      e.addWrench(input++, t, (20 + 100 * t) * across.normalized(), (1 - 30 * t) * n);
    }
  };
  const EstimatorRun a = runEstimator(model, on, feed), b = runEstimator(model, off, feed);
  ASSERT_EQ(a.loads.size(), b.loads.size());
  ASSERT_GT(a.loads.size(), 50u);
  EXPECT_EQ(a.planar, static_cast<int>(a.loads.size()));
  EXPECT_EQ(b.planar, 0);
  for (std::size_t k = 0; k < a.loads.size(); ++k)
    expectClose(a.loads[k], b.loads[k], kRel, "sample");
}

TEST(Planar, OutOfPlaneWrenchSampleFallsBackTo6x6) {
  const jle::Model<double> arm = jle::modelFromUrdfFile(kData + "/urdf/planar_arm.urdf");
  jle::EstimatorConfig on = withPlanar(jle::PlanarMode::kAuto),
                       off = withPlanar(jle::PlanarMode::kOff);
  for (jle::EstimatorConfig* c : {&on, &off}) {
    jle::WrenchInputConfig w;
    w.name = "tool";
    w.link = "tool";
    c->wrenches.push_back(w);
  }
  on.gravity_world = off.gravity_world = Vec3(0, -kG, 0);  // the arm turns about z
  // In-plane wrenches except for samples 30..49 (a force along z, a moment about x).
  auto feed = [](jle::Estimator& e, int k, double t) {
    const bool out = k >= 30 && k < 50;
    e.addWrench(0, t, Vec3(3 + t, -2, out ? 1.5 : 0.0), Vec3(out ? 0.2 : 0.0, 0, 0.4 - t));
  };
  const EstimatorRun a = runEstimator(arm, on, feed), b = runEstimator(arm, off, feed);
  ASSERT_EQ(a.loads.size(), b.loads.size());
  // The 20 samples of the episode (and at most the filter's 3-sample memory more) take
  // the 6x6 path, the rest the planar one.
  const int fallback = static_cast<int>(a.loads.size()) - a.planar;
  EXPECT_GE(fallback, 20);
  EXPECT_LE(fallback, 22);
  for (std::size_t k = 0; k < a.loads.size(); ++k)
    expectClose(a.loads[k], b.loads[k], kRel, "sample");
}

// ---------------------------------------------------------------------------------
// The paper's section 6 foot (papers_foot.hpp: its numbers and closed form, as in
// test_closed_form.cpp) through the planar path.

TEST(Planar, PapersFootThroughThePlanarPath) {
  const jle_test::PapersFoot foot;
  const jle::Model<double> model = jle::modelFromUrdfString(foot.urdf());
  const Vec3 gravity(foot.g.x(), foot.g.y(), 0);
  const jle::PlanarCheck<double> check = jle::detectPlanar(model, gravity);
  ASSERT_TRUE(check.planar) << check.reason;
  const jle::PlanarModel<double> pm = jle::planarModel(model, check.normal);
  EXPECT_FALSE(pm.offsets);
  jle::PlanarData<double> pd(model.nsegments());
  jle::Data<double> data(model);
  const int s = model.segmentOfJoint("ankle"), cop = model.frameIndex("cop");
  const std::vector<int> segments = allSegments(model);
  for (int k = 0; k <= 40; ++k) {
    const jle_test::PapersFoot::Instant i = foot.at(k);
    const double t = i.t, theta = i.theta;
    jle::VectorX<double> q(1), qd(1), qdd(1);
    q << theta;
    qd << i.theta_d;
    qdd << i.theta_dd;
    jle::planarKinematics(model, pm, pd, q, qd, qdd, gravity, segments);
    // The plate's force in the cop frame (which turns with the foot).
    const Eigen::Vector2d F_P_foot = i.Q.transpose() * i.F_P;
    jle::planarAddExternalWrench(model, pm, pd, cop, Vec3(F_P_foot.x(), F_P_foot.y(), 0),
                                 Vec3(Vec3::Zero()));
    jle::planarInverseDynamics(model, pm, pd, data, segments);
    // Child frame -> world: the foot frame is turned by theta about z.
    const Vec3 F = Eigen::AngleAxisd(theta, Vec3::UnitZ()) * data.force[s];
    const Vec3 M = Eigen::AngleAxisd(theta, Vec3::UnitZ()) * data.moment[s];
    EXPECT_NEAR(F.x(), i.F_A.x(), kRel * i.force_scale) << "t " << t;
    EXPECT_NEAR(F.y(), i.F_A.y(), kRel * i.force_scale) << "t " << t;
    EXPECT_NEAR(M.z(), i.M_A, kRel * i.moment_scale) << "t " << t;
    EXPECT_EQ(F.z(), 0.0);  // nothing leaves the plane: exact zeros, not small numbers
    EXPECT_EQ(M.x(), 0.0);
    EXPECT_EQ(M.y(), 0.0);
    EXPECT_NEAR(data.effort[s], i.M_A, kRel * i.moment_scale) << "t " << t;
  }
}

// ---------------------------------------------------------------------------------
// Detection.

std::string twoLinks(const std::string& axis2,
                     const std::string& inertia2 = "ixy=\"0\" ixz=\"0\" iyz=\"0\"",
                     const std::string& rpy2 = "0 0 0.4") {
  return "<robot name=\"two\"><link name=\"base\"/>"
         "<link name=\"a\"><inertial><origin xyz=\"0.2 0.01 0.03\"/><mass value=\"2\"/>"
         "<inertia ixx=\"0.01\" ixy=\"0.001\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" "
         "izz=\"0.025\"/></inertial></link>"
         "<link name=\"b\"><inertial><origin xyz=\"0.1 0 0\"/><mass value=\"1\"/>"
         "<inertia ixx=\"0.004\" iyy=\"0.005\" izz=\"0.006\" " +
         inertia2 +
         "/></inertial></link>"
         "<joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"a\"/>"
         "<axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" "
         "velocity=\"1\"/></joint>"
         "<joint name=\"j2\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>"
         "<origin xyz=\"0.4 0 0.05\" rpy=\"" +
         rpy2 + "\"/><axis xyz=\"" + axis2 +
         "\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint></robot>";
}

TEST(Planar, DetectionAcceptsPlanarModels) {
  const Vec3 g(0, -kG, 0);
  for (const std::string& urdf :
       {twoLinks("0 0 1"), twoLinks("0 0 -1"),
        // A child frame flipped about x: its axis is -z... of the parent.
        twoLinks("0 0 -1", "ixy=\"0\" ixz=\"0\" iyz=\"0\"", "3.141592653589793 0 0")}) {
    const jle::Model<double> model = jle::modelFromUrdfString(urdf);
    const jle::PlanarCheck<double> c = jle::detectPlanar(model, g);
    EXPECT_TRUE(c.planar) << c.reason;
    EXPECT_TRUE(c.normal == Vec3::UnitZ()) << c.normal.transpose();
  }
  const jle::Model<double> arm = jle::modelFromUrdfFile(kData + "/urdf/planar_arm.urdf");
  EXPECT_TRUE(jle::detectPlanar(arm, Vec3(0, -kG, 0)).planar);
  jle::EstimatorConfig c;
  c.gravity_world = Vec3(0, -kG, 0);
  EXPECT_TRUE(jle::Estimator(arm, c).layout().planar());
}

TEST(Planar, DetectionRefusesWhatIsNotPlanar) {
  const Vec3 g(0, -kG, 0);
  auto refused = [&](const jle::Model<double>& model, const Vec3& gravity, const std::string& why) {
    const jle::PlanarCheck<double> c = jle::detectPlanar(model, gravity);
    EXPECT_FALSE(c.planar) << why;
    EXPECT_NE(c.reason.find(why), std::string::npos) << c.reason;
    jle::EstimatorConfig config;
    config.gravity_world = gravity;
    jle::Estimator e(model, config);
    EXPECT_FALSE(e.layout().planar());
  };
  // One axis tilted by 1e-9 rad: far beyond the tolerance (1e-13), far below anything
  // a user would see: detection must still refuse.
  refused(jle::modelFromUrdfString(twoLinks("0 1e-9 1")), g, "'j2'");
  // Gravity with a component along the normal.
  refused(jle::modelFromUrdfString(twoLinks("0 0 1")), Vec3(0, -kG, -1e-6), "gravity");
  // A product of inertia coupling n (ixz).
  refused(jle::modelFromUrdfString(twoLinks("0 0 1", "ixy=\"0\" ixz=\"0.0001\" iyz=\"0\"")), g,
          "'b'");
  // A floating base.
  jle::ModelOptions floating;
  floating.floating_base = true;
  refused(jle::modelFromUrdfString(twoLinks("0 0 1"), floating), g, "floating");
  // A spatial arm (whatever it is refused for first: "" matches any reason).
  refused(jle::modelFromUrdfFile(kData + "/urdf/chains/panda_chain.urdf"), Vec3(0, -kG, 0), "");
  // Off, and float precision, keep the 6x6 path on a planar model.
  const jle::Model<double> planar = jle::modelFromUrdfString(twoLinks("0 0 1"));
  jle::EstimatorConfig c;
  c.gravity_world = g;
  c.savings.planar = jle::PlanarMode::kOff;
  EXPECT_FALSE(jle::Estimator(planar, c).layout().planar());
  c.savings.planar = jle::PlanarMode::kOn;
  c.precision = jle::Precision::kFloat;
  EXPECT_FALSE(jle::Estimator(planar, c).layout().planar());
}

TEST(Planar, PruningLeavesOnlyTheJointsThatMatter) {
  // A planar leg below a spatial joint elsewhere in the tree: with only the leg's
  // joints published, detection looks at the leg alone.
  const std::string urdf =
      "<robot name=\"mixed\"><link name=\"base\"/>"
      "<link name=\"leg\"><inertial><mass value=\"1\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" "
      "iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial></link>"
      "<link name=\"arm\"><inertial><mass value=\"1\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" "
      "iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial></link>"
      "<joint name=\"knee\" type=\"revolute\"><parent link=\"base\"/><child link=\"leg\"/><axis "
      "xyz=\"0 0 1\"/>"
      "<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>"
      "<joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/><child "
      "link=\"arm\"/><axis xyz=\"1 0 0\"/>"
      "<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint></robot>";
  const jle::Model<double> model = jle::modelFromUrdfString(urdf);
  jle::EstimatorConfig c;
  c.gravity_world = Vec3(0, -kG, 0);
  EXPECT_FALSE(jle::Estimator(model, c).layout().planar());
  c.joints = {"knee"};
  EXPECT_TRUE(jle::Estimator(model, c).layout().planar());
}

TEST(Planar, ForcedModeDropsWhatDetectionRefused) {
  // Axis tilted by 1e-9: forced, the planar path runs and agrees with 6x6 to the size
  // of what it drops (1e-9 relative; bound 1e-7 with margin for the lever arms).
  const jle::Model<double> tilted = jle::modelFromUrdfString(twoLinks("0 1e-9 1"));
  jle::EstimatorConfig on = withPlanar(jle::PlanarMode::kOn),
                       off = withPlanar(jle::PlanarMode::kOff);
  on.gravity_world = off.gravity_world = Vec3(0, -kG, 0);
  jle::Estimator probe(tilted, on);
  EXPECT_TRUE(probe.layout().planar());
  EXPECT_NE(probe.layout().planarReason().find("'j2'"), std::string::npos);
  auto none = [](jle::Estimator&, int, double) {};
  const EstimatorRun a = runEstimator(tilted, on, none), b = runEstimator(tilted, off, none);
  ASSERT_EQ(a.loads.size(), b.loads.size());
  EXPECT_EQ(a.planar, static_cast<int>(a.loads.size()));
  for (std::size_t k = 0; k < a.loads.size(); ++k)
    expectClose(a.loads[k], b.loads[k], 1e-7, "forced");
  // Forced on a planar model: same as auto.
  const jle::Model<double> planar = jle::modelFromUrdfString(twoLinks("0 0 1"));
  jle::EstimatorConfig aut = withPlanar(jle::PlanarMode::kAuto);
  aut.gravity_world = on.gravity_world;
  const EstimatorRun c = runEstimator(planar, on, none), d = runEstimator(planar, aut, none);
  ASSERT_EQ(c.loads.size(), d.loads.size());
  for (std::size_t k = 0; k < c.loads.size(); ++k)
    for (std::size_t i = 0; i < c.loads[k].force.size(); ++i) {
      EXPECT_EQ(c.loads[k].force[i], d.loads[k].force[i]);
      EXPECT_EQ(c.loads[k].moment[i], d.loads[k].moment[i]);
    }
  // What cannot be forced: a floating base, a model without a revolute joint.
  jle::ModelOptions floating;
  floating.floating_base = true;
  EXPECT_THROW(jle::Estimator(jle::modelFromUrdfString(twoLinks("0 0 1"), floating), on),
               std::invalid_argument);
}

}  // namespace
