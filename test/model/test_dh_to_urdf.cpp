// dh_to_urdf: a DH table (standard or modified) with dynamic parameters, converted to a
// URDF, gives the package (and KDL) the table's own mechanics. The reference is written
// here from the DH equations alone, never from the tool's mapping:
//   - forward kinematics: the product of the DH matrices of each convention;
//   - inverse dynamics: the recursive Newton-Euler algorithm in DH frames, for modified
//     DH in Craig's form (Introduction to Robotics, 3rd ed., 2005, eqs. 6.45-6.53), for
//     standard DH in Luh, Walker & Paul's (1980) form, each link's parameters in its own
//     DH frame as the table gives them.
// Random tables (revolute and prismatic rows, offsets, off-diagonal inertias) and two
// PUMA 560 tables (test/data/dh/) go through the tool; the efforts agree to 1e-12.
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/tool_test.hpp>

#include <gtest/gtest.h>
#include <kdl/chain.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Eigen::Matrix3d;
using Eigen::Matrix4d;
using Eigen::Vector3d;
using jle_test::Result;

const std::string kData = JLE_TEST_DATA;
const Vector3d kGravity(0.0, 0.0, -9.80665);  // in DH frame 0 = the URDF root
// The efforts are sums of a few dozen products of O(1) to O(100) numbers: rounding
// leaves ~1e-14; 1e-12 N m (or N) is the brief's bound, and a wrong term (a lever arm,
// a transposed rotation) moves them by far more.
constexpr double kEffortTol = 1e-12;
constexpr double kPoseTol = 1e-13;  // [m] and rotation entries
// KDL reads the URDF through its own parser and sums in another order.
constexpr double kKdlTol = 1e-10;
constexpr double kPi = 3.14159265358979323846;

struct DhRow {
  bool prismatic = false;
  double a = 0, alpha = 0, d = 0, theta = 0;  // theta: offset (revolute); d: offset (prismatic)
  double mass = 0;
  Vector3d com = Vector3d::Zero();
  Matrix3d inertia = Matrix3d::Zero();  // about the COM, DH frame axes
};

struct DhTable {
  bool modified = false;
  std::vector<DhRow> rows;
};

Matrix4d rotX(double t) {
  Matrix4d m = Matrix4d::Identity();
  m.block<3, 3>(0, 0) = Eigen::AngleAxisd(t, Vector3d::UnitX()).toRotationMatrix();
  return m;
}
Matrix4d rotZ(double t) {
  Matrix4d m = Matrix4d::Identity();
  m.block<3, 3>(0, 0) = Eigen::AngleAxisd(t, Vector3d::UnitZ()).toRotationMatrix();
  return m;
}
Matrix4d transX(double x) {
  Matrix4d m = Matrix4d::Identity();
  m(0, 3) = x;
  return m;
}
Matrix4d transZ(double z) {
  Matrix4d m = Matrix4d::Identity();
  m(2, 3) = z;
  return m;
}

// theta_i and d_i of row i at coordinate q.
double thetaOf(const DhRow& r, double q) { return r.prismatic ? r.theta : r.theta + q; }
double dOf(const DhRow& r, double q) { return r.prismatic ? r.d + q : r.d; }

// The transform of DH frame i from frame i-1 (i = 1 .. n, row i-1 of the table).
Matrix4d dhTransform(const DhTable& t, std::size_t i, double q) {
  const DhRow& r = t.rows[i];
  if (t.modified)  // Craig: Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)
    return rotX(r.alpha) * transX(r.a) * rotZ(thetaOf(r, q)) * transZ(dOf(r, q));
  return rotZ(thetaOf(r, q)) * transZ(dOf(r, q)) * transX(r.a) * rotX(r.alpha);
}

Matrix4d forwardKinematics(const DhTable& t, const Eigen::VectorXd& q) {
  Matrix4d T = Matrix4d::Identity();
  for (std::size_t i = 0; i < t.rows.size(); ++i) T = T * dhTransform(t, i, q[i]);
  return T;
}

// Craig's recursive Newton-Euler (modified DH). Frame i+1 from frame i: R (columns: the
// axes of i+1 in i) and P (origin of i+1 in i). Outward: omega, its rate, the origin's
// acceleration (gravity as an upward acceleration of the base), the COM's; inward:
// f_i = R f_{i+1} + F_i, n_i = N_i + R n_{i+1} + Pc x F_i + P x R f_{i+1}.
Eigen::VectorXd craigNewtonEuler(const DhTable& t, const Eigen::VectorXd& q,
                                 const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  const std::size_t n = t.rows.size();
  const Vector3d z = Vector3d::UnitZ();
  std::vector<Matrix3d> R(n + 1, Matrix3d::Identity());  // R[i]: frame i+1 (row i) in frame i
  std::vector<Vector3d> P(n + 1, Vector3d::Zero());
  std::vector<Vector3d> F(n), N(n);
  Vector3d w = Vector3d::Zero(), wd = Vector3d::Zero(), vd = -kGravity;
  for (std::size_t i = 0; i < n; ++i) {
    const Matrix4d T = dhTransform(t, i, q[i]);
    R[i] = T.block<3, 3>(0, 0);
    P[i] = T.block<3, 1>(0, 3);
    const Matrix3d Rt = R[i].transpose();
    const DhRow& r = t.rows[i];
    const Vector3d vd_next = Rt * (wd.cross(P[i]) + w.cross(w.cross(P[i])) + vd);
    if (r.prismatic) {
      w = Rt * w;
      wd = Rt * wd;
      vd = vd_next + 2.0 * w.cross(qd[i] * z) + qdd[i] * z;
    } else {
      const Vector3d w_in = Rt * w;
      w = w_in + qd[i] * z;
      wd = Rt * wd + w_in.cross(qd[i] * z) + qdd[i] * z;
      vd = vd_next;
    }
    const Vector3d vdc = wd.cross(r.com) + w.cross(w.cross(r.com)) + vd;
    F[i] = r.mass * vdc;
    N[i] = r.inertia * wd + w.cross(r.inertia * w);
  }
  Eigen::VectorXd tau(n);
  Vector3d f = Vector3d::Zero(), m = Vector3d::Zero();  // f_{n+1}, n_{n+1}: no tip load
  for (std::size_t k = n; k-- > 0;) {
    // R[k + 1], P[k + 1]: frame k+2 in frame k+1 (identity and zero past the tip).
    const Vector3d Rf = R[k + 1] * f;
    m = N[k] + R[k + 1] * m + t.rows[k].com.cross(F[k]) + P[k + 1].cross(Rf);
    f = Rf + F[k];
    tau[k] = t.rows[k].prismatic ? f.dot(z) : m.dot(z);
  }
  return tau;
}

// Luh, Walker & Paul's recursive Newton-Euler (standard DH): every quantity of link i in
// frame i, whose origin O_i is at the link's distal end; joint i acts about z_{i-1}.
// p = O_i from O_{i-1} in frame i; the force and moment on link i from link i-1 act at
// O_{i-1}: n_i = R n_{i+1} + p x R f_{i+1} + (p + r_i) x F_i + N_i.
Eigen::VectorXd luhWalkerPaul(const DhTable& t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                              const Eigen::VectorXd& qdd) {
  const std::size_t n = t.rows.size();
  const Vector3d z0 = Vector3d::UnitZ();
  std::vector<Matrix3d> R(n + 1, Matrix3d::Identity());  // R[i]: frame i+1 in frame i
  std::vector<Vector3d> p(n), F(n), N(n), axis(n);       // axis: z_{i-1} in frame i
  Vector3d w = Vector3d::Zero(), wd = Vector3d::Zero(), vd = -kGravity;
  for (std::size_t i = 0; i < n; ++i) {
    const DhRow& r = t.rows[i];
    const Matrix4d T = dhTransform(t, i, q[i]);
    R[i] = T.block<3, 3>(0, 0);
    const Matrix3d Rt = R[i].transpose();
    p[i] = Vector3d(r.a, dOf(r, q[i]) * std::sin(r.alpha), dOf(r, q[i]) * std::cos(r.alpha));
    axis[i] = Rt * z0;
    if (r.prismatic) {
      w = Rt * w;
      wd = Rt * wd;
      vd = Rt * (qdd[i] * z0 + vd) + wd.cross(p[i]) + 2.0 * w.cross(qd[i] * axis[i]) +
           w.cross(w.cross(p[i]));
    } else {
      const Vector3d w_prev = w;
      w = Rt * (w_prev + qd[i] * z0);
      wd = Rt * (wd + qdd[i] * z0 + w_prev.cross(qd[i] * z0));
      vd = wd.cross(p[i]) + w.cross(w.cross(p[i])) + Rt * vd;
    }
    const Vector3d vdc = wd.cross(r.com) + w.cross(w.cross(r.com)) + vd;
    F[i] = r.mass * vdc;
    N[i] = r.inertia * wd + w.cross(r.inertia * w);
  }
  Eigen::VectorXd tau(n);
  Vector3d f = Vector3d::Zero(), m = Vector3d::Zero();
  for (std::size_t k = n; k-- > 0;) {
    const Vector3d Rf = R[k + 1] * f;
    m = R[k + 1] * m + p[k].cross(Rf) + (p[k] + t.rows[k].com).cross(F[k]) + N[k];
    f = Rf + F[k];
    tau[k] = t.rows[k].prismatic ? f.dot(axis[k]) : m.dot(axis[k]);
  }
  return tau;
}

Eigen::VectorXd referenceEfforts(const DhTable& t, const Eigen::VectorXd& q,
                                 const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  return t.modified ? craigNewtonEuler(t, q, qd, qdd) : luhWalkerPaul(t, q, qd, qdd);
}

// ------------------------------------------------------------------------ the tables

std::string number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

// The table as the tool's YAML input (angles in rad, inertia about the COM).
std::string yamlOf(const DhTable& t) {
  std::ostringstream y;
  y << "convention: " << (t.modified ? "modified" : "standard") << "\nname: random_arm\nlinks:\n";
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const DhRow& r = t.rows[i];
    const Matrix3d& I = r.inertia;
    y << "  - joint: j" << i + 1 << "\n    type: " << (r.prismatic ? "prismatic" : "revolute")
      << "\n    a: " << number(r.a) << "\n    alpha: " << number(r.alpha)
      << "\n    d: " << number(r.d) << "\n    theta: " << number(r.theta)
      << "\n    mass: " << number(r.mass) << "\n    com: [" << number(r.com.x()) << ", "
      << number(r.com.y()) << ", " << number(r.com.z())
      << "]\n    inertia: {ixx: " << number(I(0, 0)) << ", iyy: " << number(I(1, 1))
      << ", izz: " << number(I(2, 2)) << ", ixy: " << number(I(0, 1))
      << ", ixz: " << number(I(0, 2)) << ", iyz: " << number(I(1, 2)) << "}\n";
    if (r.prismatic) y << "    lower: -1\n    upper: 1\n";
  }
  return y.str();
}

// A random arm: rows of O(1) m and kg, angles anywhere, principal moments of a box (so
// that they satisfy the triangle inequality) in a random orientation.
DhTable randomTable(bool modified, int n, std::mt19937& gen) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.2, 1.0);
  DhTable t;
  t.modified = modified;
  for (int i = 0; i < n; ++i) {
    DhRow r;
    r.prismatic = i % 3 == 2;
    r.a = u(gen);
    r.alpha = 3.14159 * u(gen);
    r.d = 0.5 * u(gen);
    r.theta = 3.14159 * u(gen);
    r.mass = 2.0 * pos(gen);
    r.com = 0.3 * Vector3d(u(gen), u(gen), u(gen));
    const double x = 0.3 * pos(gen), y = 0.3 * pos(gen), zz = 0.3 * pos(gen);
    const Vector3d principal(y * y + zz * zz, x * x + zz * zz, x * x + y * y);
    const Matrix3d Q =
        Eigen::Quaterniond(u(gen), u(gen), u(gen), u(gen)).normalized().toRotationMatrix();
    r.inertia = Q * (r.mass / 12.0 * principal).asDiagonal() * Q.transpose();
    t.rows.push_back(r);
  }
  return t;
}

class DhToUrdf : public jle_test::ToolTest {
 protected:
  DhToUrdf() : ToolTest("jle_test_dh") {}

  Result run(const std::vector<std::string>& args) const {
    return ToolTest::run(JLE_DH_TO_URDF, args);
  }
  // The URDF the tool writes for the table text `yaml`.
  std::string convert(const std::string& yaml) const {
    write("table.yaml", yaml);
    const Result r = run({"--input", path("table.yaml"), "--output", path("out/robot.urdf")});
    EXPECT_EQ(r.status, 0) << r.err;
    return jle_test::readFile(path("out/robot.urdf"));
  }
};

// The package's efforts and the flange pose for (q, qd, qdd), coordinates in row order.
struct PackageResult {
  Eigen::VectorXd effort;
  Matrix4d flange = Matrix4d::Identity();
};

PackageResult packageRun(const jle::Model<double>& model, const Eigen::VectorXd& q,
                         const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  const int n = static_cast<int>(q.size());
  EXPECT_EQ(model.nq, n);
  jle::Data<double> data(model);
  jle::VectorX<double> mq(n), mqd(n), mqdd(n);
  for (int k = 0; k < n; ++k) {  // coordinate_names are j1 .. jn in some order
    const int row = std::stoi(model.coordinate_names[k].substr(1)) - 1;
    mq[k] = q[row];
    mqd[k] = qd[row];
    mqdd[k] = qdd[row];
  }
  jle::forwardKinematics(model, data, mq, mqd, mqdd, kGravity);
  jle::inverseDynamics(model, data);
  PackageResult out;
  out.effort.resize(n);
  for (int s : model.moving_segments)
    out.effort[std::stoi(model.joint_name[s].substr(1)) - 1] = data.effort[s];
  const jle::Frame<double>& tip = model.frames[model.frameIndex("flange")];
  out.flange.block<3, 3>(0, 0) = data.R_world[tip.segment] * tip.R_segment_frame;
  out.flange.block<3, 1>(0, 3) =
      data.p_world[tip.segment] + data.R_world[tip.segment] * tip.p_segment_frame;
  return out;
}

// KDL's chain solver on the same URDF (its own parser): efforts in chain order.
Eigen::VectorXd kdlEfforts(const std::string& urdf, const Eigen::VectorXd& q,
                           const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  KDL::Tree tree;
  EXPECT_TRUE(kdl_parser::treeFromString(urdf, tree));
  KDL::Chain chain;
  EXPECT_TRUE(tree.getChain("base_link", "flange", chain));
  const unsigned n = chain.getNrOfJoints();
  EXPECT_EQ(n, static_cast<unsigned>(q.size()));
  KDL::JntArray kq(n), kqd(n), kqdd(n), tau(n);
  for (unsigned k = 0; k < n; ++k) kq(k) = q[k], kqd(k) = qd[k], kqdd(k) = qdd[k];
  KDL::ChainIdSolver_RNE solver(chain, KDL::Vector(kGravity.x(), kGravity.y(), kGravity.z()));
  KDL::Wrenches none(chain.getNrOfSegments(), KDL::Wrench::Zero());
  EXPECT_GE(solver.CartToJnt(kq, kqd, kqdd, none, tau), 0);
  Eigen::VectorXd out(n);
  for (unsigned k = 0; k < n; ++k) out[k] = tau(k);
  return out;
}

// The table through the tool, at random states: FK, efforts against the DH reference
// and KDL.
// The worst differences seen, printed by each test (the figures docs/dh_to_urdf.md quotes).
struct Worst {
  double effort = 0.0, kdl = 0.0, pose = 0.0;
  void print(const char* what) const {
    std::printf("%s: worst |effort - reference| %.3g, |KDL - reference| %.3g, pose %.3g\n", what,
                effort, kdl, pose);
  }
};

void expectAgreement(const DhTable& table, const std::string& urdf, std::mt19937& gen,
                     Worst& worst) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t n = table.rows.size();
  const jle::Model<double> model = jle::modelFromUrdfString(urdf);
  for (int sample = 0; sample < 20; ++sample) {
    Eigen::VectorXd q(n), qd(n), qdd(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double scale = table.rows[i].prismatic ? 0.5 : 3.0;
      q[i] = scale * u(gen), qd[i] = 2.0 * u(gen), qdd[i] = 5.0 * u(gen);
    }
    const PackageResult ours = packageRun(model, q, qd, qdd);
    const Matrix4d fk = forwardKinematics(table, q);
    EXPECT_LE((ours.flange - fk).cwiseAbs().maxCoeff(), kPoseTol) << "sample " << sample;
    worst.pose = std::max(worst.pose, (ours.flange - fk).cwiseAbs().maxCoeff());
    const Eigen::VectorXd reference = referenceEfforts(table, q, qd, qdd);
    const Eigen::VectorXd kdl = kdlEfforts(urdf, q, qd, qdd);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_NEAR(ours.effort[i], reference[i], kEffortTol) << "sample " << sample << " j" << i + 1;
      worst.effort = std::max(worst.effort, std::abs(ours.effort[i] - reference[i]));
      worst.kdl = std::max(worst.kdl, std::abs(kdl[i] - reference[i]));
      EXPECT_NEAR(kdl[i], reference[i], kKdlTol * std::max(1.0, std::abs(reference[i])))
          << "KDL, sample " << sample << " j" << i + 1;
    }
  }
}

TEST_F(DhToUrdf, RandomStandardTablesMatchNewtonEulerInDhFrames) {
  std::mt19937 gen(7);
  Worst worst;
  for (int trial = 0; trial < 5; ++trial) {
    const DhTable table = randomTable(false, 6, gen);
    expectAgreement(table, convert(yamlOf(table)), gen, worst);
  }
  worst.print("standard");
}

TEST_F(DhToUrdf, RandomModifiedTablesMatchCraigsNewtonEuler) {
  std::mt19937 gen(11);
  Worst worst;
  for (int trial = 0; trial < 5; ++trial) {
    const DhTable table = randomTable(true, 6, gen);
    expectAgreement(table, convert(yamlOf(table)), gen, worst);
  }
  worst.print("modified");
}

// The bundled examples (docs/offline_tools.md, docs/dh_to_urdf.md) convert and load.
TEST_F(DhToUrdf, BundledPumaTablesConvert) {
  for (const char* file : {"puma560_standard.yaml", "puma560_modified.yaml"}) {
    const Result r = run({"--input", kData + "/dh/" + file, "--output", path("out/puma.urdf")});
    ASSERT_EQ(r.status, 0) << r.err;
    const jle::Model<double> model = jle::modelFromUrdfFile(path("out/puma.urdf"));
    EXPECT_EQ(model.nq, 6) << file;
    EXPECT_GT(model.totalMass(), 20.0) << file;
  }
}

TEST_F(DhToUrdf, InertiaAboutTheOriginIsMovedToTheCom) {
  std::mt19937 gen(3);
  DhTable table = randomTable(true, 3, gen);
  std::string yaml = yamlOf(table);
  // The same rows with each inertia about the DH frame origin (parallel axes).
  DhTable about_origin = table;
  for (DhRow& r : about_origin.rows)
    r.inertia += r.mass * (r.com.squaredNorm() * Matrix3d::Identity() - r.com * r.com.transpose());
  std::string shifted = yamlOf(about_origin);
  shifted.insert(shifted.find("links:"), "inertia_about: origin\n");
  const jle::Model<double> a = jle::modelFromUrdfString(convert(yaml));
  const jle::Model<double> b = jle::modelFromUrdfString(convert(shifted));
  for (int s = 0; s < a.nsegments(); ++s)
    EXPECT_LE((a.inertia_com[s] - b.inertia_com[s]).cwiseAbs().maxCoeff(), 1e-14) << s;
}

// ------------------------------------------------------------------------ the flange

// The flange pose and the efforts of `urdf` at random states against the DH product
// followed by `T_n_flange` (the fixed transform from DH frame n), and the Newton-Euler
// reference (the flange is massless: the efforts are the table's).
void expectFlange(const DhTable& table, const Matrix4d& T_n_flange, const std::string& urdf,
                  std::mt19937& gen) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t n = table.rows.size();
  const jle::Model<double> model = jle::modelFromUrdfString(urdf);
  for (int sample = 0; sample < 20; ++sample) {
    Eigen::VectorXd q(n), qd(n), qdd(n);
    for (std::size_t i = 0; i < n; ++i)
      q[i] = (table.rows[i].prismatic ? 0.5 : 3.0) * u(gen), qd[i] = 2.0 * u(gen),
      qdd[i] = 5.0 * u(gen);
    const PackageResult ours = packageRun(model, q, qd, qdd);
    const Matrix4d fk = forwardKinematics(table, q) * T_n_flange;
    EXPECT_LE((ours.flange - fk).cwiseAbs().maxCoeff(), kPoseTol) << "sample " << sample;
    const Eigen::VectorXd reference = referenceEfforts(table, q, qd, qdd);
    for (std::size_t i = 0; i < n; ++i)
      EXPECT_NEAR(ours.effort[i], reference[i], kEffortTol) << "sample " << sample << " j" << i + 1;
  }
}

// The Panda's modified DH table (Franka Emika, "Robot and interface specifications":
// a, d, alpha per joint, then the flange d = 0.107 m) with unit masses at the frame
// origins. At q = 0 the flange is at (0.088, 0, 0.333 + 0.316 + 0.384 - 0.107) =
// (0.088, 0, 0.926) m with its z axis down (the alphas sum to pi), Franka's figure.
TEST_F(DhToUrdf, FlangeOffsetAfterTheLastJointOfThePanda) {
  constexpr double h = kPi / 2.0;
  DhTable panda;
  panda.modified = true;
  const double a[] = {0, 0, 0, 0.0825, -0.0825, 0, 0.088};
  const double d[] = {0.333, 0, 0.316, 0, 0.384, 0, 0};
  const double alpha[] = {0, -h, h, h, -h, h, h};
  for (int i = 0; i < 7; ++i) {
    DhRow r;
    r.a = a[i], r.d = d[i], r.alpha = alpha[i], r.mass = 1.0;
    r.inertia = 0.01 * Matrix3d::Identity();
    panda.rows.push_back(r);
  }
  std::string yaml = yamlOf(panda);
  yaml.insert(yaml.find("links:"), "flange: {d: 0.107}\n");
  const std::string urdf = convert(yaml);
  const jle::Model<double> model = jle::modelFromUrdfString(urdf);
  const PackageResult zero = packageRun(model, Eigen::VectorXd::Zero(7), Eigen::VectorXd::Zero(7),
                                        Eigen::VectorXd::Zero(7));
  EXPECT_LE((zero.flange.block<3, 1>(0, 3) - Vector3d(0.088, 0.0, 0.926)).norm(), 1e-15);
  EXPECT_LE((zero.flange.block<3, 3>(0, 0) - Vector3d(1, -1, -1).asDiagonal().toDenseMatrix())
                .cwiseAbs()
                .maxCoeff(),
            1e-15);
  std::mt19937 gen(17);
  expectFlange(panda, transZ(0.107), urdf, gen);
}

// Every form of the entry on random tables: the table's own convention's row (a, alpha,
// d, theta; standard Rz Tz Tx Rx, modified Rx Tx Rz Tz) or a URDF origin (xyz, then
// rpy: Rz(yaw) Ry(pitch) Rx(roll)), in the table's angle unit.
TEST_F(DhToUrdf, FlangeEntryInEveryFormMatchesTheDhProduct) {
  std::mt19937 gen(23);
  for (const bool modified : {false, true}) {
    const DhTable table = randomTable(modified, 6, gen);
    const std::string yaml = yamlOf(table);
    const auto with = [&](const std::string& entry) {
      std::string y = yaml;
      y.insert(y.find("links:"), "flange: " + entry + "\n");
      return convert(y);
    };
    const Matrix4d row = modified ? rotX(0.3) * transX(0.05) * rotZ(-0.7) * transZ(0.1)
                                  : rotZ(-0.7) * transZ(0.1) * transX(0.05) * rotX(0.3);
    expectFlange(table, row, with("{a: 0.05, alpha: 0.3, d: 0.1, theta: -0.7}"), gen);
    Matrix4d origin = Matrix4d::Identity();
    origin.block<3, 3>(0, 0) =
        (Eigen::AngleAxisd(0.6, Vector3d::UnitZ()) * Eigen::AngleAxisd(-0.5, Vector3d::UnitY()) *
         Eigen::AngleAxisd(0.4, Vector3d::UnitX()))
            .toRotationMatrix();
    origin.block<3, 1>(0, 3) = Vector3d(0.1, -0.2, 0.3);
    expectFlange(table, origin, with("{xyz: [0.1, -0.2, 0.3], rpy: [0.4, -0.5, 0.6]}"), gen);
  }
  // Degrees, the table's angle unit, for the flange's angles too: the same table written
  // in degrees, and Franka's hand mount (-45 deg about z, 0.107 m along it).
  const DhTable table = randomTable(true, 3, gen);
  DhTable in_degrees = table;
  for (DhRow& r : in_degrees.rows) r.alpha *= 180.0 / kPi, r.theta *= 180.0 / kPi;
  std::string yaml = yamlOf(in_degrees);
  yaml.insert(yaml.find("links:"), "angle_unit: deg\nflange: {theta: -45, d: 0.107}\n");
  expectFlange(table, rotZ(-kPi / 4.0) * transZ(0.107), convert(yaml), gen);
}

TEST_F(DhToUrdf, BadTablesAreRefusedNamingTheRow) {
  const std::string head = "convention: modified\nlinks:\n";
  const auto refused = [&](const std::string& yaml, const std::vector<std::string>& parts) {
    write("bad.yaml", yaml);
    const Result r = run({"--input", path("bad.yaml"), "--output", path("out/x.urdf")});
    EXPECT_EQ(r.status, 1) << yaml;
    for (const std::string& p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << r.err;
    EXPECT_FALSE(std::ifstream(path("out/x.urdf")).good());
  };
  refused("links:\n  - joint: a\n", {"'convention' is required"});
  refused("convention: craig\nlinks:\n  - joint: a\n", {"standard or modified"});
  refused(head + "  - joint: a\n    mass: -1\n", {"links[0] (a)", "'mass'"});
  refused(head + "  - joint: a\n  - joint: a\n", {"links[1] (a)", "twice"});
  refused(head + "  - joint: a\n    type: prismatic\n", {"links[0] (a)", "'lower' and 'upper'"});
  refused(head + "  - joint: a\n    alpha: ninety\n", {"'alpha'", "ninety"});
  refused(head + "  - joint: a\n    inertia: {ixx: 1, iyy: 1, izz: -3}\n",
          {"links[0] (a)", "positive semi-definite"});
  refused(head + "  - joint: a\n    colour: red\n", {"unknown key 'colour'"});
  refused(head, {"'links'"});
  refused("convention: modified\nflange: {d: 0.1, xyz: [0, 0, 0.1]}\nlinks:\n  - joint: a\n",
          {"flange", "not both"});
  refused("convention: modified\nflange: {colour: red}\nlinks:\n  - joint: a\n",
          {"flange", "unknown key 'colour'"});
  refused("convention: modified\nflange: {xyz: [0, 0]}\nlinks:\n  - joint: a\n",
          {"flange", "'xyz'"});
  const Result usage = run({"--output", path("out/x.urdf")});
  EXPECT_EQ(usage.status, 2);
  const Result help = run({"--help"});
  EXPECT_EQ(help.status, 0);
  for (const char* part :
       {"standard", "modified", "Rx(alpha_i-1) Tx(a_i-1)", "inertia_about", "Exit status"})
    EXPECT_NE(help.out.find(part), std::string::npos) << part;
}

}  // namespace
