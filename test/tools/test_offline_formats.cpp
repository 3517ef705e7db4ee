// joint_loads' floating base and force plates, per-kg efforts, and the OpenSim storage
// files of joint_loads and process_bag, run as processes. Expected values are worked by
// hand in the tests (Newton-Euler of one rigid body; the statics of a standing body),
// not taken from the library.
#include <jle_testing/tool_test.hpp>

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::string kData = JLE_TEST_DATA;
const std::string kFreeBody = kData + "/urdf/free_body.urdf";
const std::string kStand = kData + "/urdf/two_leg_stand.urdf";
const std::string kPandaDemo = kData + "/urdf/panda_demo.urdf";
constexpr double kG = 9.80665;

using jle_test::Result;
using jle_test::Table;
using jle_test::parseCsv;
using jle_test::readFile;

std::string num(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

// A .sto: the header lines up to endheader, then a tab-separated table.
struct Sto {
  std::vector<std::string> header_lines;
  Table table;
};

Sto parseSto(const std::string& text) {
  Sto sto;
  std::stringstream s(text);
  std::string line;
  while (std::getline(s, line) && line != "endheader") sto.header_lines.push_back(line);
  std::stringstream rest;
  rest << s.rdbuf();
  sto.table = parseCsv(rest.str(), '\t');
  return sto;
}

class OfflineFormatsTest : public jle_test::ToolTest {
 protected:
  OfflineFormatsTest() : ToolTest("jle_test_offline") {}
  Result jointLoads(const std::vector<std::string>& args) const {
    return run(JLE_JOINT_LOADS, args);
  }
};

// ------------------------------------------------------------- one free rigid body

// The free body's fixture: m = 2 kg, centre of mass c = (0.1, 0, 0) in the link frame,
// inertia about it diag(0.01, 0.02, 0.03).
const double kMass = 2.0;
const Eigen::Vector3d kCom(0.1, 0.0, 0.0);
const Eigen::Matrix3d kInertia = Eigen::Vector3d(0.01, 0.02, 0.03).asDiagonal();

// What the world must apply to a free rigid body (Newton-Euler, world frame, moment
// about the link origin): F = m (a_G - g), M = J_G alpha + w x J_G w + c_w x F with
// a_G = a + alpha x c_w + w x (w x c_w), c_w = R c, J_G = R J R^T.
void freeBodyResidual(const Eigen::Matrix3d& R, const Eigen::Vector3d& a, const Eigen::Vector3d& w,
                      const Eigen::Vector3d& alpha, Eigen::Vector3d& F, Eigen::Vector3d& M) {
  const Eigen::Vector3d c = R * kCom;
  const Eigen::Matrix3d J = R * kInertia * R.transpose();
  const Eigen::Vector3d a_G = a + alpha.cross(c) + w.cross(w.cross(c));
  F = kMass * (a_G - Eigen::Vector3d(0, 0, -kG));
  M = J * alpha + w.cross(J * w) + c.cross(F);
}

const char* const kBaseHeader =
    "t,base.x,base.y,base.z,base.qx,base.qy,base.qz,base.qw,base.vx,base.vy,base.vz,"
    "base.wx,base.wy,base.wz,base.ax,base.ay,base.az,base.alx,base.aly,base.alz";

TEST_F(OfflineFormatsTest, FreeBodyResidualIsNewtonEuler) {
  // Two states, the second turned and spinning about a skew axis (the gyroscopic term
  // and the rotation of J_G both enter).
  struct State {
    Eigen::Quaterniond q;
    Eigen::Vector3d p, v, w, a, alpha;
  };
  const std::vector<State> states = {
      {Eigen::Quaterniond::Identity(), {0, 0, 1}, {0, 0, 0}, {0, 0, 2}, {1, 2, 3}, {0, 0, 5}},
      {Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
       {0.3, -0.2, 1.1},
       {0.5, 0, 0},
       {1.5, -0.5, 0.8},
       {-2, 0.5, 1},
       {3, -1, 2}}};
  std::string csv = std::string(kBaseHeader) + "\n";
  for (std::size_t i = 0; i < states.size(); ++i) {
    const State& s = states[i];
    csv += num(0.1 * i);
    for (double x : {s.p.x(), s.p.y(), s.p.z(), s.q.x(), s.q.y(), s.q.z(), s.q.w(), s.v.x(),
                     s.v.y(), s.v.z(), s.w.x(), s.w.y(), s.w.z(), s.a.x(), s.a.y(), s.a.z(),
                     s.alpha.x(), s.alpha.y(), s.alpha.z()})
      csv += "," + num(x);
    csv += "\n";
  }
  write("in.csv", csv);
  const Result r = jointLoads({"--urdf", kFreeBody, "--input", path("in.csv"), "--floating-base"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table t = parseCsv(r.out);
  ASSERT_EQ(t.rows.size(), states.size());
  EXPECT_EQ(t.header, (std::vector<std::string>{"t", "base.fx", "base.fy", "base.fz", "base.mx",
                                                "base.my", "base.mz"}));
  // The first state by hand: c = (0.1, 0, 0); a_G = a + alpha x c + w x (w x c) =
  // (1, 2, 3) + (0, 0.5, 0) + (-0.4, 0, 0); F = 2 (0.6, 2.5, 3 + g);
  // M = (0, 0, 0.03 * 5) + c x F = (0, -0.1 F_z, 0.15 + 0.1 F_y).
  // 1e-12: a few roundings of numbers of order 30.
  EXPECT_NEAR(t.number(0, "base.fx"), 1.2, 1e-12);
  EXPECT_NEAR(t.number(0, "base.fy"), 5.0, 1e-12);
  EXPECT_NEAR(t.number(0, "base.fz"), 2 * (3 + kG), 1e-12);
  EXPECT_NEAR(t.number(0, "base.mx"), 0.0, 1e-12);
  EXPECT_NEAR(t.number(0, "base.my"), -0.2 * (3 + kG), 1e-12);
  EXPECT_NEAR(t.number(0, "base.mz"), 0.15 + 0.5, 1e-12);
  for (std::size_t i = 0; i < states.size(); ++i) {
    const State& s = states[i];
    Eigen::Vector3d F, M;
    freeBodyResidual(s.q.toRotationMatrix(), s.a, s.w, s.alpha, F, M);
    const char* names[] = {"base.fx", "base.fy", "base.fz", "base.mx", "base.my", "base.mz"};
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(t.number(i, names[k]), F[k], 1e-12) << i << names[k];
      EXPECT_NEAR(t.number(i, names[k + 3]), M[k], 1e-12) << i << names[k + 3];
    }
  }
}

// Pose only: the twist and the acceleration estimated from the rows (three-point
// quadratic, docs/joint_loads.md), on a non-uniform time grid, the quaternion's sign
// flipped on every other row. The motion: p = (A sin wt, 0, 1 + A cos wt), a turn
// theta = C sin wt about the fixed unit axis u.
TEST_F(OfflineFormatsTest, PoseOnlyBaseMotionIsEstimatedWithinTheMethodsOrder) {
  const double A = 0.1, C = 0.3, w = M_PI, h = 0.01;
  const Eigen::Vector3d u = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const int n = 101;
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) t[i] = i * h + 0.2 * h * std::sin(1.7 * i);  // steps 0.6h .. 1.4h
  std::string csv = "t,base.x,base.y,base.z,base.qx,base.qy,base.qz,base.qw\n";
  for (int i = 0; i < n; ++i) {
    const double s = std::sin(w * t[i]), c = std::cos(w * t[i]);
    Eigen::Quaterniond q(Eigen::AngleAxisd(C * s, u));
    if (i % 2) q.coeffs() = -q.coeffs();
    csv += num(t[i]) + "," + num(A * s) + ",0," + num(1 + A * c) + "," + num(q.x()) + "," +
           num(q.y()) + "," + num(q.z()) + "," + num(q.w()) + "\n";
  }
  write("in.csv", csv);
  const Result r = jointLoads({"--urdf", kFreeBody, "--input", path("in.csv"), "--floating-base"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table out = parseCsv(r.out);
  ASSERT_EQ(out.rows.size(), static_cast<std::size_t>(n));
  // Error bounds of the stencils (docs/joint_loads.md), per component, with the maxima
  // of the derivatives: |x'''| <= A w^3 (position), C w^3 (angle), |x''''| <= A w^4, C w^4.
  // Centred, steps h1, h2: first derivative h1 h2 |x'''|/6, second |h2 - h1| |x'''|/3 +
  // (h1^2 + h2^2) |x''''|/12. One-sided (first, last row): first derivative
  // h1 (h1 + h2) |x'''|/6, second (2 h1 + h2) |x'''|/3. A factor 2 covers the next terms.
  double worst_force = 0, worst_moment = 0;
  for (int i = 0; i < n; ++i) {
    const int m = i == 0 ? 0 : i == n - 1 ? 2 : 1;
    const int first = i - m;
    const double h1 = t[first + 1] - t[first], h2 = t[first + 2] - t[first + 1];
    double e1, e2;  // per unit of |x'''| (and |x''''| scaled by w)
    if (m == 1) {
      e1 = h1 * h2 / 6;
      e2 = std::abs(h2 - h1) / 3 + (h1 * h1 + h2 * h2) * w / 12;
    } else {
      const double a = m == 0 ? h1 : h2, b = m == 0 ? h2 : h1;
      e1 = a * (a + b) / 6;
      e2 = (2 * a + b) / 3;
    }
    const double a_err = 2 * std::sqrt(2.0) * A * std::pow(w, 3) * e2;
    const double w_err = 2 * C * std::pow(w, 3) * e1;
    const double al_err = 2 * C * std::pow(w, 3) * e2;
    const double s = std::sin(w * t[i]), c = std::cos(w * t[i]);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(C * s, u).toRotationMatrix();
    const Eigen::Vector3d a(-A * w * w * s, 0, -A * w * w * c);
    const Eigen::Vector3d om = u * (C * w * c), al = u * (-C * w * w * s);
    Eigen::Vector3d F, M;
    freeBodyResidual(R, a, om, al, F, M);
    // |dF| <= m (|da| + |c| |dalpha| + 2 |c| |w| |dw|); |dM| <= |J| |dalpha| +
    // 2 |J| |w| |dw| + |c| |dF|, with |c| = 0.1, |J| <= 0.03.
    const double wmax = C * w;
    const double bound_F = kMass * (a_err + 0.1 * al_err + 0.2 * wmax * w_err);
    const double bound_M = 0.03 * al_err + 0.06 * wmax * w_err + 0.1 * bound_F;
    const Eigen::Vector3d F_out(out.number(i, "base.fx"), out.number(i, "base.fy"),
                                out.number(i, "base.fz"));
    const Eigen::Vector3d M_out(out.number(i, "base.mx"), out.number(i, "base.my"),
                                out.number(i, "base.mz"));
    EXPECT_LE((F_out - F).norm(), bound_F) << "row " << i;
    EXPECT_LE((M_out - M).norm(), bound_M) << "row " << i;
    worst_force = std::max(worst_force, (F_out - F).norm() / bound_F);
    worst_moment = std::max(worst_moment, (M_out - M).norm() / bound_M);
  }
  // The input moves: a residual of a body at rest (m g) would be off by m A w^2 ~ 2 N.
  RecordProperty("worst_force_error_over_bound", std::to_string(worst_force));
  RecordProperty("worst_moment_error_over_bound", std::to_string(worst_moment));
}

// Positions only with a floating base: the joints' JOINT.q and the base's pose, whose
// twist and acceleration are computed from the smoothed pose like the joints' rates. The
// two-leg body (two_leg_stand.urdf) with every joint at 0 is one rigid body: its residual
// is the Newton-Euler of its five parts written here (part i: mass m_i, centre of mass
// c_i and inertia J_i in the pelvis frame), F = sum m_i (a_i - g), M = sum R J_i R^T alpha
// + w x R J_i R^T w + R c_i x m_i (a_i - g), a_i = a + alpha x R c_i + w x (w x R c_i);
// and the left ankle holds its foot: F = m_f (a_f - g) (world frame). The motion: p =
// (0.3 sin pi t, 0.2 sin 0.8 pi t, 0.9 + 0.1 cos pi t), a turn 0.3 sin pi t about the
// fixed axis u, the quaternion's sign flipped on every other row; 4 s at 1 kHz, compared
// over the middle 2 s: the zero-phase filter's end transients (its own, as for the
// joints: docs/studies/zero_phase.md) are still 0.4 N at 0.4 s from the ends, far below 1e-3
// after 1 s (they decay as exp(-19 t) at 8 Hz).
TEST_F(OfflineFormatsTest, PositionsOnlyFloatingBaseDifferentiatesThePose) {
  const double w = M_PI;
  const Eigen::Vector3d u = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  struct Part {
    double m;
    Eigen::Vector3d c;
    Eigen::Vector3d J;  // principal, along the pelvis axes
  };
  const Part parts[] = {{10, {0.02, 0, 0}, {0.1, 0.08, 0.1}},
                        {5, {0, 0.1, -0.4}, {0.27, 0.27, 0.01}},
                        {5, {0, -0.1, -0.4}, {0.27, 0.27, 0.01}},
                        {1, {0.05, 0.1, -0.85}, {0.002, 0.004, 0.004}},
                        {1, {0.05, -0.1, -0.85}, {0.002, 0.004, 0.004}}};
  const int n = 4001;
  std::string csv = std::string("t,base.x,base.y,base.z,base.qx,base.qy,base.qz,base.qw,") +
                    "hip_l.q,ankle_l.q,hip_r.q,ankle_r.q\n";
  for (int i = 0; i < n; ++i) {
    const double t = 0.001 * i;
    Eigen::Quaterniond q(Eigen::AngleAxisd(0.3 * std::sin(w * t), u));
    if (i % 2) q.coeffs() = -q.coeffs();
    csv += num(t) + "," + num(0.3 * std::sin(w * t)) + "," + num(0.2 * std::sin(0.8 * w * t)) +
           "," + num(0.9 + 0.1 * std::cos(w * t)) + "," + num(q.x()) + "," + num(q.y()) + "," +
           num(q.z()) + "," + num(q.w()) + ",0,0,0,0\n";
  }
  write("in.csv", csv);
  const Result r = jointLoads({"--urdf", kStand, "--input", path("in.csv"), "--floating-base",
                               "--frame", "world", "--cutoff", "8"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table out = parseCsv(r.out);
  ASSERT_EQ(out.rows.size(), static_cast<std::size_t>(n));
  const Eigen::Vector3d g(0, 0, -kG);
  double worst = 0.0;
  for (int i = 1000; i <= 3000; i += 50) {
    const double t = 0.001 * i, s = std::sin(w * t), c = std::cos(w * t);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3 * s, u).toRotationMatrix();
    const Eigen::Vector3d om = u * (0.3 * w * c), al = u * (-0.3 * w * w * s);
    const Eigen::Vector3d a(-0.3 * w * w * s, -0.2 * 0.64 * w * w * std::sin(0.8 * w * t),
                            -0.1 * w * w * c);
    Eigen::Vector3d F = Eigen::Vector3d::Zero(), M = Eigen::Vector3d::Zero();
    Eigen::Vector3d F_foot = Eigen::Vector3d::Zero();
    for (int k = 0; k < 5; ++k) {
      const Eigen::Vector3d ci = R * parts[k].c;
      const Eigen::Matrix3d Ji = R * parts[k].J.asDiagonal() * R.transpose();
      const Eigen::Vector3d Fi = parts[k].m * (a + al.cross(ci) + om.cross(om.cross(ci)) - g);
      F += Fi;
      M += Ji * al + om.cross(Ji * om) + ci.cross(Fi);
      if (k == 3) F_foot = Fi;
    }
    const Eigen::Vector3d F_out(out.number(i, "base.fx"), out.number(i, "base.fy"),
                                out.number(i, "base.fz"));
    const Eigen::Vector3d M_out(out.number(i, "base.mx"), out.number(i, "base.my"),
                                out.number(i, "base.mz"));
    const Eigen::Vector3d A_out(out.number(i, "ankle_l.fx"), out.number(i, "ankle_l.fy"),
                                out.number(i, "ankle_l.fz"));
    // 1e-4 N, N m: a residual of a body at rest would be off by 22 x 0.3 pi^2 = 65 N; the
    // smoothing (8 Hz against a 0.5 Hz motion) and differentiation leave 3.7e-6.
    EXPECT_LE((F_out - F).norm(), 1e-4) << "row " << i;
    EXPECT_LE((M_out - M).norm(), 1e-4) << "row " << i;
    EXPECT_LE((A_out - F_foot).norm(), 1e-4) << "row " << i;
    worst = std::max({worst, (F_out - F).norm(), (M_out - M).norm(), (A_out - F_foot).norm()});
  }
  RecordProperty("worst_error", std::to_string(worst));
  std::printf("positions-only floating base: worst error %.3g\n", worst);
  // A twist or acceleration beside positions only is refused, saying why.
  write("twist.csv",
        "t,base.x,base.y,base.z,base.qx,base.qy,base.qz,base.qw,base.vx,base.vy,"
        "base.vz,base.wx,base.wy,base.wz,hip_l.q,ankle_l.q,hip_r.q,ankle_r.q\n"
        "0,0,0,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0\n");
  const Result twist =
      jointLoads({"--urdf", kStand, "--input", path("twist.csv"), "--floating-base"});
  EXPECT_EQ(twist.status, 1);
  EXPECT_NE(twist.err.find("computed from its smoothed pose"), std::string::npos) << twist.err;
}

// ------------------------------------------------------- standing on two force plates

// The two-leg fixture standing still, every angle zero, pelvis origin 0.9 m up: total
// mass 22 kg, centre of mass x_G = (10 * 0.02 + 2 * 1 * 0.05) / 22 = 0.3 / 22 m. Each
// plate carries half the weight at a COP under the centre of mass, x_c = x_G. The left
// plate lies under the left ankle (0, 0.1, 0), yaw 0; the right one under the right
// ankle (0, -0.1, 0), turned 90 degrees: its x axis is the world's y.
const double kWeight = 22 * kG;
const double kXc = 0.3 / 22;

std::string standRow(double t, double left_fz, double left_mx, double left_my, double right_fz,
                     double right_mx, double right_my) {
  std::string row = num(t) + ",0,0,0.9,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0";  // at rest
  for (const char* j : {"hip_l", "ankle_l", "hip_r", "ankle_r"}) {
    (void)j;
    row += ",0,0,0";
  }
  for (double x :
       {0.0, 0.0, left_fz, left_mx, left_my, 0.0, 0.0, 0.0, right_fz, right_mx, right_my, 0.0})
    row += "," + num(x);
  return row + "\n";
}

std::string standCsv() {
  std::string csv = kBaseHeader;
  for (const char* j : {"hip_l", "ankle_l", "hip_r", "ankle_r"})
    for (const char* s : {"q", "qd", "qdd"}) csv += std::string(",") + j + "." + s;
  for (const char* p : {"left", "right"})
    for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"})
      csv += std::string(",plate@") + p + "." + c;
  csv += "\n";
  // Row 0: both feet, half the weight each. The foot pushes down, F = (0, 0, -W/2) in
  // the plate frame; its moment about the plate origin is r x F with r the COP in the
  // plate frame: left r = (x_c, 0, 0) -> (0, x_c W/2, 0); right (turned) r = (0, -x_c, 0)
  // -> (x_c W/2, 0, 0).
  csv += standRow(0.0, -kWeight / 2, 0, kXc * kWeight / 2, -kWeight / 2, kXc * kWeight / 2, 0);
  // Row 1: all the weight on the left plate, COP at (x_c, -0.1) in its frame (under the
  // centre of mass): r x F = (y F_z, -x F_z, 0) = (0.1 W, x_c W, 0);
  // the right plate reads 5 N of noise, below the contact threshold.
  csv += standRow(0.01, -kWeight, 0.1 * kWeight, kXc * kWeight, -5.0, 0, 0);
  return csv;
}

const std::vector<std::string> kPlates = {"--plate", "left=foot_l,0,0.1,0", "--plate",
                                          "right=foot_r,0,-0.1,0,90"};

std::vector<std::string> standArgs(const std::string& input, std::vector<std::string> more = {}) {
  std::vector<std::string> args = {"--urdf", kStand, "--input", input, "--floating-base"};
  args.insert(args.end(), kPlates.begin(), kPlates.end());
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

TEST_F(OfflineFormatsTest, StandingOnTwoPlatesLeavesNoResidualAndLoadsTheAnkles) {
  write("in.csv", standCsv());
  const Result r = jointLoads(standArgs(path("in.csv")));
  ASSERT_EQ(r.status, 0) << r.err;
  const Table t = parseCsv(r.out);
  ASSERT_EQ(t.rows.size(), 2u);
  // Row 0: the plates explain the whole weight and its moment: 1e-11 covers rounding of
  // terms of order W = 216 N. Row 1: the right plate's 5 N (below the threshold: no COP,
  // but it acts as measured, at its origin (0, -0.1, 0), 0.9 m below the pelvis and 0.1 m
  // to its right) is more than the weight: the world must pull down by 5 N, and about x
  // cancel (0, -0.1, -0.9) x (0, 0, 5) = (-0.5, 0, 0).
  const double row1[6] = {0.0, 0.0, -5.0, 0.5, 0.0, 0.0};
  int i = 0;
  for (const char* c : {"base.fx", "base.fy", "base.fz", "base.mx", "base.my", "base.mz"}) {
    EXPECT_NEAR(t.number(0, c), 0.0, 1e-11) << c;
    EXPECT_NEAR(t.number(1, c), row1[i++], 1e-11) << c;
  }
  // Row 0, the left foot (1 kg, centre of mass (0.05, 0, -0.05) from the ankle) in
  // equilibrium under the ankle wrench, its weight and the reaction W/2 up at the COP,
  // (x_c, 0, -0.1) from the ankle. About y: M + (-x_c W/2) + 0.05 g = 0 (r x F, y
  // component z F_x - x F_z), so M_y = x_c W/2 - 0.05 g = 0.15 g - 0.05 g = 0.1 g; the
  // force is (0, 0, -(W/2 - g)) (the leg holds the foot down against the push).
  EXPECT_NEAR(t.number(0, "ankle_l.my"), 0.1 * kG, 1e-11);
  EXPECT_NEAR(t.number(0, "ankle_l.effort"), 0.1 * kG, 1e-11);
  EXPECT_NEAR(t.number(0, "ankle_l.fz"), -(kWeight / 2 - kG), 1e-11);
  EXPECT_NEAR(t.number(0, "ankle_l.mx"), 0.0, 1e-11);
  EXPECT_NEAR(t.number(0, "ankle_r.my"), 0.1 * kG, 1e-11);  // the turned plate, same load
  // The left hip holds leg and foot: about y, the reaction at (x_c, 0, -0.9) from the
  // hip gives -x_c W/2, the foot's weight at (0.05, 0, -0.85) gives 0.05 g, the leg's
  // weight (on the hip's vertical) nothing: M_y = x_c W/2 - 0.05 g = 0.1 g again.
  EXPECT_NEAR(t.number(0, "hip_l.my"), 0.1 * kG, 1e-11);
  // COPs in the world, contact flags.
  EXPECT_EQ(t.number(0, "plate@left.contact"), 1.0);
  EXPECT_NEAR(t.number(0, "plate@left.cop_x"), kXc, 1e-14);
  EXPECT_NEAR(t.number(0, "plate@left.cop_y"), 0.1, 1e-14);
  EXPECT_NEAR(t.number(0, "plate@right.cop_x"), kXc, 1e-14);
  EXPECT_NEAR(t.number(0, "plate@right.cop_y"), -0.1, 1e-14);
  EXPECT_NEAR(t.number(0, "plate@right.cop_z"), 0.0, 1e-14);
  // Row 1: the right foot barely touching (5 N is below the 20 N threshold): no contact,
  // its COP written as zeros; its ankle holds the foot (M_y = -0.05 g: the foot's weight
  // 5 cm forward pulls its toe down, about -y) less the 5 N pushing up below the ankle
  // (no moment about it): F_z = g - 5.
  EXPECT_EQ(t.number(1, "plate@right.contact"), 0.0);
  for (const char* c : {"plate@right.cop_x", "plate@right.cop_y", "plate@right.cop_z"})
    EXPECT_EQ(t.number(1, c), 0.0) << c;
  EXPECT_NEAR(t.number(1, "ankle_r.my"), -0.05 * kG, 1e-12);
  EXPECT_NEAR(t.number(1, "ankle_r.fz"), kG - 5.0, 1e-12);
  EXPECT_NEAR(t.number(1, "plate@left.cop_y"), 0.0, 1e-14);
  // With --contact-threshold 1 the 5 N are in contact (a COP), with the same loads: the
  // world must pull down by 5 N.
  const Result r2 = jointLoads(standArgs(path("in.csv"), {"--contact-threshold", "1"}));
  ASSERT_EQ(r2.status, 0) << r2.err;
  const Table t2 = parseCsv(r2.out);
  EXPECT_EQ(t2.number(1, "plate@right.contact"), 1.0);
  EXPECT_NEAR(t2.number(1, "base.fz"), -5.0, 1e-11);
}

TEST_F(OfflineFormatsTest, PerKgEffortsDivideByTheBodyMass) {
  write("in.csv", standCsv());
  Result r = jointLoads(standArgs(path("in.csv"), {"--per-kg"}));
  ASSERT_EQ(r.status, 0) << r.err;
  Table t = parseCsv(r.out);
  // Default mass: the URDF's total, 22 kg. The ankle moment 0.1 g (above) per kg.
  EXPECT_NEAR(t.number(0, "ankle_l.effort_per_kg"), 0.1 * kG / 22, 1e-12);
  EXPECT_EQ(t.column("ankle_l.effort_per_kg"), t.column("ankle_l.effort") + 1);
  r = jointLoads(standArgs(path("in.csv"), {"--per-kg", "--body-mass", "70"}));
  ASSERT_EQ(r.status, 0) << r.err;
  t = parseCsv(r.out);
  EXPECT_NEAR(t.number(0, "ankle_l.effort_per_kg"), 0.1 * kG / 70, 1e-12);
  EXPECT_NEAR(t.number(0, "hip_r.effort_per_kg"), t.number(0, "hip_r.effort") / 70, 1e-15);
  // Without --per-kg no such column.
  r = jointLoads(standArgs(path("in.csv")));
  EXPECT_EQ(parseCsv(r.out).column("ankle_l.effort_per_kg"), -1);
}

// ------------------------------------------------------------------- OpenSim .sto

// A .sto column and the CSV column it holds, times `sign`: OpenSim's ground axes are x
// forward, y up, z right, the model's world x forward, y left, z up, so a world
// vector's (x, y, z) is written (x, z, -y).
struct StoColumn {
  std::string csv, sto;
  double sign = 1.0;
};

void expectStoMatchesCsv(const Sto& sto, const Table& csv, const std::vector<StoColumn>& names) {
  // OpenSim's Storage header.
  ASSERT_GE(sto.header_lines.size(), 5u);
  EXPECT_EQ(sto.header_lines[0], "Inverse Dynamics Generalized Forces");
  EXPECT_EQ(sto.header_lines[1], "version=1");
  EXPECT_EQ(sto.header_lines[2], "nRows=" + std::to_string(csv.rows.size()));
  // process_bag's CSV has a status column last, and so has its .sto.
  const std::size_t columns = csv.header.size();
  EXPECT_EQ(sto.header_lines[3], "nColumns=" + std::to_string(columns));
  EXPECT_EQ(sto.header_lines[4], "inDegrees=no");
  ASSERT_EQ(sto.table.header.size(), columns);
  ASSERT_EQ(sto.table.rows.size(), csv.rows.size());
  for (const auto& [csv_name, sto_name, sign] : names) {
    const int c = csv.column(csv_name), s = sto.table.column(sto_name);
    ASSERT_GE(c, 0) << csv_name;
    ASSERT_GE(s, 0) << sto_name;
    for (std::size_t row = 0; row < csv.rows.size(); ++row)  // exact: %.17g reads back
      EXPECT_EQ(std::strtod(sto.table.rows[row][s].c_str(), nullptr),
                sign * std::strtod(csv.rows[row][c].c_str(), nullptr))
          << sto_name << " row " << row;
  }
}

TEST_F(OfflineFormatsTest, JointLoadsWritesOpenSimStorage) {
  write("in.csv", standCsv());
  for (const char* frame : {"child", "parent", "world"}) {
    const Result csv = jointLoads(standArgs(path("in.csv"), {"--per-kg", "--frame", frame}));
    ASSERT_EQ(csv.status, 0) << csv.err;
    const Result sto =
        jointLoads(standArgs(path("in.csv"), {"--per-kg", "--frame", frame, "--format", "sto",
                                              "--output", path("o.sto")}));
    ASSERT_EQ(sto.status, 0) << sto.err;
    const std::string in = std::string(frame) == "child"    ? "foot_l"
                           : std::string(frame) == "parent" ? "leg_l"
                                                            : "ground";
    const Sto s = parseSto(readFile(path("o.sto")));
    // The link frames' components as they are; the world's (ground) turned to y up.
    const bool ground = in == "ground";
    const std::string ankle = "ankle_l_on_foot_l_in_" + in + "_";
    expectStoMatchesCsv(s, parseCsv(csv.out),
                        {{"t", "time"},
                         {"base.fx", "pelvis_tx_force"},
                         {"base.fz", "pelvis_ty_force"},
                         {"base.fy", "pelvis_tz_force", -1.0},
                         {"base.my", "pelvis_mz_moment", -1.0},
                         {"base.mz", "pelvis_my_moment"},
                         {"ankle_l.effort", "ankle_l_moment"},
                         {"ankle_l.effort_per_kg", "ankle_l_moment_per_kg"},
                         {"ankle_l.fx", ankle + "fx"},
                         {"ankle_l.fz", ankle + (ground ? "fy" : "fz")},
                         {"ankle_l.my", ankle + (ground ? "mz" : "my"), ground ? -1.0 : 1.0},
                         {"plate@left.contact", "left_contact"},
                         {"plate@left.cop_x", "left_ground_force_px"},
                         {"plate@left.cop_y", "left_ground_force_pz", -1.0},
                         {"plate@right.cop_z", "right_ground_force_py"}});
    EXPECT_EQ(s.table.header[0], "time");
  }
}

// OpenSim's ground is y up: a vertical force, a centre of pressure's height, land in the
// _ty / _fy / _py columns. Hand values: the free body's first state of
// FreeBodyResidualIsNewtonEuler, F = (1.2, 5, 2 (3 + g)), M = (0, -0.2 (3 + g), 0.65) in
// the z-up world, is written tx = 1.2, ty = 2 (3 + g), tz = -5 and mx = 0, my = 0.65,
// mz = 0.2 (3 + g); standing on plates raised to z = 0.25 m, the COPs (x_c, +-0.1,
// 0.25) are written (x_c, 0.25, -+0.1), and the left ankle's vertical force -(W/2 - g)
// (world frame) is its _fy.
TEST_F(OfflineFormatsTest, StoWritesWorldVectorsInOpenSimsGroundAxes) {
  write("body.csv", std::string(kBaseHeader) + "\n0,0,0,1,0,0,0,1,0,0,0,0,0,2,1,2,3,0,0,5\n");
  Result r = jointLoads({"--urdf", kFreeBody, "--input", path("body.csv"), "--floating-base",
                         "--format", "sto", "--output", path("body.sto")});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table body = parseSto(readFile(path("body.sto"))).table;
  ASSERT_EQ(body.rows.size(), 1u);
  // 1e-12: a few roundings of numbers of order 30.
  EXPECT_NEAR(body.number(0, "body_tx_force"), 1.2, 1e-12);
  EXPECT_NEAR(body.number(0, "body_ty_force"), 2.0 * (3.0 + kG), 1e-12);
  EXPECT_NEAR(body.number(0, "body_tz_force"), -5.0, 1e-12);
  EXPECT_NEAR(body.number(0, "body_mx_moment"), 0.0, 1e-12);
  EXPECT_NEAR(body.number(0, "body_my_moment"), 0.65, 1e-12);
  EXPECT_NEAR(body.number(0, "body_mz_moment"), 0.2 * (3.0 + kG), 1e-12);

  write("in.csv", standCsv());
  r = jointLoads({"--urdf", kStand, "--input", path("in.csv"), "--floating-base", "--plate",
                  "left=foot_l,0,0.1,0.25", "--plate", "right=foot_r,0,-0.1,0.25,90", "--frame",
                  "world", "--format", "sto", "--output", path("stand.sto")});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table stand = parseSto(readFile(path("stand.sto"))).table;
  EXPECT_NEAR(stand.number(0, "left_ground_force_px"), kXc, 1e-14);
  EXPECT_NEAR(stand.number(0, "left_ground_force_py"), 0.25, 1e-14);
  EXPECT_NEAR(stand.number(0, "left_ground_force_pz"), -0.1, 1e-14);
  EXPECT_NEAR(stand.number(0, "right_ground_force_py"), 0.25, 1e-14);
  EXPECT_NEAR(stand.number(0, "right_ground_force_pz"), 0.1, 1e-14);
  EXPECT_NEAR(stand.number(0, "ankle_l_on_foot_l_in_ground_fy"), -(kWeight / 2 - kG), 1e-11);
  EXPECT_NEAR(stand.number(0, "ankle_l_on_foot_l_in_ground_fx"), 0.0, 1e-11);
  EXPECT_NEAR(stand.number(0, "ankle_l_on_foot_l_in_ground_fz"), 0.0, 1e-11);

  // A world that is not z up has no such turn: refused.
  r = jointLoads({"--urdf", kFreeBody, "--input", path("body.csv"), "--floating-base", "--gravity",
                  "0,-9.8,0", "--format", "sto"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--format sto"), std::string::npos) << r.err;
}

TEST_F(OfflineFormatsTest, ProcessBagWritesOpenSimStorage) {
  Result r = run(JLE_MAKE_EXAMPLE_BAG,
                 {"--urdf", kPandaDemo, "--samples", "200", "--output", path("in.bag")});
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(JLE_PROCESS_BAG, {"--bag", path("in.bag"), "--urdf", kPandaDemo, "--csv", path("o.csv"),
                            "--sto", path("o.sto")});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table csv = parseCsv(readFile(path("o.csv")));
  ASSERT_GT(csv.rows.size(), 10u);
  expectStoMatchesCsv(parseSto(readFile(path("o.sto"))), csv,
                      {{"t", "time"},
                       {"panda_joint2.effort", "panda_joint2_moment"},
                       {"panda_joint4.mx", "panda_joint4_on_panda_link4_in_panda_link4_mx"},
                       {"panda_joint7.fz", "panda_joint7_on_panda_link7_in_panda_link7_fz"},
                       {"status", "status"}});
  // The status column (LoadsStatus bits): the first loads settling (1), the last trusted.
  const Table sto = parseSto(readFile(path("o.sto"))).table;
  EXPECT_EQ(sto.header.back(), "status");
  EXPECT_EQ(sto.number(0, "status"), 1.0);
  EXPECT_EQ(sto.number(sto.rows.size() - 1, "status"), 0.0);
  // Only a .sto.
  r = run(JLE_PROCESS_BAG,
          {"--bag", path("in.bag"), "--urdf", kPandaDemo, "--sto", path("only.sto")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readFile(path("only.sto")), readFile(path("o.sto")));
}

// ------------------------------------------------------------------------ refusals

TEST_F(OfflineFormatsTest, RefusesBadPlatesBaseColumnsAndPlateNames) {
  write("in.csv", standCsv());
  struct Case {
    std::vector<std::string> args;
    int status;
    std::string message;
  };
  const std::string in = path("in.csv");
  const std::vector<Case> cases = {
      {{"--urdf", kStand, "--input", in, "--floating-base", "--plate", "left=foot_l,0,0.1"},
       2,
       "--plate: 'left=foot_l,0,0.1' is not NAME=LINK,X,Y,Z[,YAW_DEG]"},
      {{"--urdf", kStand, "--input", in, "--floating-base", "--plate", "left=foot_l,0,a,0"},
       2,
       "--plate: 'left=foot_l,0,a,0'"},
      {{"--urdf", kStand, "--input", in, "--floating-base", "--plate", "left=toe,0,0,0"},
       2,
       "--plate left: unknown link 'toe'"},
      {{"--urdf", kStand, "--input", in, "--floating-base", "--plate", "left=foot_l,0,0,0",
        "--plate", "left=foot_r,0,0,0"},
       2,
       "plate 'left' is given twice"},
      // The CSV has plate@right.* columns, but only the left plate is declared.
      {{"--urdf", kStand, "--input", in, "--floating-base", "--plate", "left=foot_l,0,0.1,0"},
       1,
       "in.csv:1: columns 'plate@right.fx', 'plate@right.fy', 'plate@right.fz', "
       "'plate@right.mx', 'plate@right.my', 'plate@right.mz': unknown plate 'right'"},
      // Base columns for a fixed base.
      {{"--urdf", kStand, "--input", in, "--plate", "left=foot_l,0,0.1,0", "--plate",
        "right=foot_r,0,-0.1,0,90"},
       1,
       "a floating-base column, but the base is fixed"},
      {{"--urdf", kStand, "--input", in, "--floating-base", "--body-mass", "70"},
       2,
       "--body-mass is only used with --per-kg"},
      {{"--urdf", kStand, "--input", in, "--floating-base", "--format", "mot"},
       2,
       "--format: 'mot' is not csv or sto"},
  };
  for (const Case& c : cases) {
    const Result r = jointLoads(c.args);
    EXPECT_EQ(r.status, c.status) << c.message << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(r.err.rfind("joint_loads: ", 0), 0u) << r.err;
  }
  // Incomplete base pose and twist.
  write("base.csv", "t,base.x,base.y,base.z,base.qx,base.qy,base.qz,base.vx\n0,0,0,1,0,0,0,0\n");
  Result r = jointLoads({"--urdf", kFreeBody, "--input", path("base.csv"), "--floating-base"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("base.csv:1: floating base: missing column 'base.qw' (the root link's "
                       "pose is required); floating base twist: missing columns 'base.vy', "
                       "'base.vz', 'base.wx', 'base.wy', 'base.wz' (all six or none)"),
            std::string::npos)
      << r.err;
  // A quaternion that is not a unit one, named with its line.
  write("q.csv",
        "t,base.x,base.y,base.z,base.qx,base.qy,base.qz,base.qw\n0,0,0,1,0,0,0,1\n"
        "0.1,0,0,1,0,0,0,2\n0.2,0,0,1,0,0,0,1\n");
  r = jointLoads({"--urdf", kFreeBody, "--input", path("q.csv"), "--floating-base"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("q.csv:3: column 'base.qw': the quaternion"), std::string::npos) << r.err;
  // Times that do not increase (the estimate needs them), and too few rows.
  write("t.csv",
        "t,base.x,base.y,base.z,base.qx,base.qy,base.qz,base.qw\n0,0,0,1,0,0,0,1\n"
        "0.1,0,0,1,0,0,0,1\n0.1,0,0,1,0,0,0,1\n");
  r = jointLoads({"--urdf", kFreeBody, "--input", path("t.csv"), "--floating-base"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("t.csv:4: column 't': time does not increase"), std::string::npos) << r.err;
  write("two.csv",
        "t,base.x,base.y,base.z,base.qx,base.qy,base.qz,base.qw\n0,0,0,1,0,0,0,1\n"
        "0.1,0,0,1,0,0,0,1\n");
  r = jointLoads({"--urdf", kFreeBody, "--input", path("two.csv"), "--floating-base", "--output",
                  path("two.out")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("2 rows; estimating the base twist"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("two.out")));
}

}  // namespace
