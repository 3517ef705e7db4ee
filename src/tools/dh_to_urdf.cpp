// dh_to_urdf: a serial robot given as a Denavit-Hartenberg table (standard or modified)
// with each link's mass, centre of mass and inertia, to a URDF that the package and KDL
// read. The mapping is stated in kUsage and docs/dh_to_urdf.md.
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/io/csv.hpp>

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace jle::cli;  // command_line.hpp: UsageError, optionValues, the parsers
using Eigen::Matrix3d;
using Eigen::Vector3d;

const char* const kUsage =
    R"(usage: dh_to_urdf --input TABLE.yaml [--output ROBOT.urdf]

Writes the URDF of a serial robot given as a Denavit-Hartenberg table with the links'
dynamic parameters (docs/dh_to_urdf.md). TABLE.yaml:

  convention: standard | modified   required
  name: NAME                        the robot's name (default dh_robot)
  base_link: NAME                   the root link, DH frame 0 (default base_link)
  tip_link: NAME                    a massless link fixed at the last DH frame n
                                    (default flange), or at the flange entry's
                                    transform from it
  flange:                           a fixed transform from DH frame n to tip_link
                                    (default none), either a constant row of the
                                    table's convention:
    {a: A, alpha: ALPHA, d: D, theta: THETA}   (each default 0; the Panda's: {d: 0.107})
                                    or a URDF origin in DH frame n:
    {xyz: [X, Y, Z], rpy: [R, P, Y]}           [m]; R = Rz(Y) Ry(P) Rx(R) (default 0)
  angle_unit: rad | deg             of alpha, theta, lower, upper (default rad)
  inertia_about: com | origin       the inertias are about the link's centre of mass,
                                    or about its DH frame's origin (default com)
  links:                            one entry per joint, base to tip (1 .. 100)
    - joint: NAME                   required; names unique
      link: NAME                    default link_<i> (i = 1 ..)
      type: revolute | prismatic    default revolute
      a: A                          [m], default 0
      alpha: ALPHA                  default 0
      d: D                          [m], default 0; prismatic: the offset added to q
      theta: THETA                  default 0; revolute: the offset added to q
      mass: M                       [kg], >= 0, default 0
      com: [X, Y, Z]                [m] in the link's DH frame, default 0 0 0
      inertia: {ixx, iyy, izz, ixy, ixz, iyz}
                                    [kg m^2] in the link's DH frame axes; absent
                                    entries are 0; positive semi-definite (the
                                    package's model check does the rest)
      lower: L, upper: U            joint limits (both or neither); a revolute joint
                                    without them is continuous; prismatic: required
      effort: E, velocity: V        the URDF limits, > 0 (default 1000 and 10)

Conventions (i = 1 .. n; Rz, Rx rotations, Tz, Tx translations):
  standard  frame i = frame i-1 . Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i); joint i
            turns about (or slides along) z of frame i-1; link i's parameters are in
            frame i (at its distal end)
  modified  (Craig) frame i = frame i-1 . Rx(alpha_i-1) Tx(a_i-1) Rz(theta_i) Tz(d_i):
            the row of joint i holds a_i-1 and alpha_i-1; joint i is about z of frame
            i; link i's parameters are in frame i (at joint i)
  with theta_i = q_i + theta (revolute) or d_i = q_i + d (prismatic). The URDF joint i
  turns about its z axis; its child link's frame is DH frame i-1 . Rz/Tz(q_i) and the
  constant part of the row for standard, DH frame i turned by -theta about z for a
  revolute modified row (so that every URDF rpy is (roll, 0, yaw), no Euler
  singularity); the inertials carry the turn to the DH frame. Frame 0 is base_link,
  frame n is tip_link: the forward kinematics of the table, and the efforts of its
  inverse dynamics, are those of the URDF (tested to 1e-12, and against KDL).

  --input PATH   the table (YAML)
  --output PATH  default: standard output; written to a temporary file beside PATH and
                 renamed onto it on success only
  --help         this text

Exit status: 0 success; 1 a data error (an unreadable or invalid table: the message
names the key and the row; an unwritable output); 2 a usage error.
)";

constexpr double kPi = 3.14159265358979323846;
constexpr double kDefaultEffort = 1000.0;  // N m or N: URDF requires one
constexpr double kDefaultVelocity = 10.0;  // rad/s or m/s
constexpr int kMaxLinks = 100;

struct Options {
  std::string input, output;
};

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v = optionValues(argc, argv, {"--input", "--output"});
  Options o;
  o.input = requiredValue(v, "--input", "TABLE.yaml");
  if (v.count("--output")) o.output = v["--output"];
  return o;
}

// ------------------------------------------------------------------------- the table

struct Row {
  std::string joint, link;
  bool prismatic = false;
  double a = 0.0, alpha = 0.0, d = 0.0, theta = 0.0;
  double mass = 0.0;
  Vector3d com = Vector3d::Zero();
  Matrix3d inertia = Matrix3d::Zero();  // about the COM, DH frame axes
  bool limited = false;
  double lower = 0.0, upper = 0.0, effort = kDefaultEffort, velocity = kDefaultVelocity;
};

struct Table {
  bool modified = false;
  std::string name = "dh_robot", base_link = "base_link", tip_link = "flange";
  std::vector<Row> rows;
  // The flange entry: tip_link in DH frame n (identity without it).
  Matrix3d R_n_tip = Matrix3d::Identity();
  Vector3d p_n_tip = Vector3d::Zero();
};

class TableReader {
 public:
  explicit TableReader(const std::string& path) : path_(path) {}

  Table read() {
    YAML::Node root;
    try {
      root = YAML::LoadFile(path_);
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(path_ + ": " + e.what());
    }
    if (!root.IsMap()) fail("", "the table is not a YAML map");
    checkKeys(root, "",
              {"convention", "name", "base_link", "tip_link", "angle_unit", "inertia_about",
               "links", "flange"});
    Table t;
    const std::string convention = text(root, "", "convention", "");
    if (convention != "standard" && convention != "modified")
      fail("", "'convention' must be standard or modified (is '" + convention + "')");
    t.modified = convention == "modified";
    t.name = name(root, "", "name", t.name);
    t.base_link = name(root, "", "base_link", t.base_link);
    t.tip_link = name(root, "", "tip_link", t.tip_link);
    const std::string unit = text(root, "", "angle_unit", "rad");
    if (unit != "rad" && unit != "deg") fail("", "'angle_unit' must be rad or deg");
    angle_ = unit == "deg" ? kPi / 180.0 : 1.0;
    const std::string about = text(root, "", "inertia_about", "com");
    if (about != "com" && about != "origin") fail("", "'inertia_about' must be com or origin");
    const YAML::Node links = root["links"];
    if (!links || !links.IsSequence() || links.size() == 0 || links.size() > kMaxLinks)
      fail("", "'links' must be a list of 1 to " + std::to_string(kMaxLinks) + " entries");
    for (std::size_t i = 0; i < links.size(); ++i)
      t.rows.push_back(row(links[i], static_cast<int>(i), about == "origin"));
    checkNames(t);
    if (root["flange"]) flange(root["flange"], t);
    return t;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw std::runtime_error(path_ + ": " + (where.empty() ? "" : where + ": ") + what);
  }

  void checkKeys(const YAML::Node& node, const std::string& where,
                 const std::set<std::string>& known) const {
    for (const auto& entry : node) {
      const std::string key = entry.first.as<std::string>();
      if (!known.count(key)) fail(where, "unknown key '" + key + "'");
    }
  }

  std::string text(const YAML::Node& node, const std::string& where, const char* key,
                   const std::string& fallback) const {
    const YAML::Node v = node[key];
    if (!v) {
      if (fallback.empty()) fail(where, std::string("'") + key + "' is required");
      return fallback;
    }
    if (!v.IsScalar()) fail(where, std::string("'") + key + "' must be a text");
    return v.as<std::string>();
  }

  // A URDF name: letters, digits, '_', '-', '/', '.'.
  std::string name(const YAML::Node& node, const std::string& where, const char* key,
                   const std::string& fallback) const {
    const std::string s = text(node, where, key, fallback);
    for (char c : s)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '/' ||
            c == '.'))
        fail(where, std::string("'") + key + "': '" + s + "' holds characters other than " +
                        "A-Z a-z 0-9 _ - / .");
    return s;
  }

  double number(const YAML::Node& node, const std::string& where, const std::string& key,
                double fallback) const {
    const YAML::Node v = node[key];
    return v ? value(v, where, "'" + key + "'") : fallback;
  }

  // A scalar as a finite number; `what` names it in the message.
  double value(const YAML::Node& v, const std::string& where, const std::string& what) const {
    double x = 0.0;
    const std::string s = v.IsScalar() ? v.as<std::string>() : std::string();
    const char* end = s.data() + s.size();
    const std::from_chars_result r = std::from_chars(s.data(), end, x);
    if (s.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(x))
      fail(where, what + " must be a finite number (is '" + s + "')");
    return x;
  }

  Vector3d triple(const YAML::Node& node, const std::string& where, const char* key) const {
    const YAML::Node v = node[key];
    if (!v) return Vector3d::Zero();
    if (!v.IsSequence() || v.size() != 3)
      fail(where, std::string("'") + key + "' must be [X, Y, Z]");
    Vector3d out;
    for (std::size_t k = 0; k < 3; ++k)
      out[static_cast<int>(k)] =
          value(v[k], where, std::string("'") + key + "'[" + std::to_string(k) + "]");
    return out;
  }

  Row row(const YAML::Node& node, int i, bool about_origin) const;
  void flange(const YAML::Node& node, Table& t) const;
  void inertia(const YAML::Node& node, const std::string& where, Row& r) const;
  void limits(const YAML::Node& node, const std::string& where, Row& r) const;
  void checkNames(const Table& t) const;

  std::string path_;
  double angle_ = 1.0;  // of the table's angles, to rad
};

Row TableReader::row(const YAML::Node& node, int i, bool about_origin) const {
  std::string where = "links[" + std::to_string(i) + "]";
  if (!node.IsMap()) fail(where, "not a map");
  checkKeys(node, where,
            {"joint", "link", "type", "a", "alpha", "d", "theta", "mass", "com", "inertia", "lower",
             "upper", "effort", "velocity"});
  Row r;
  r.joint = name(node, where, "joint", "");
  where += " (" + r.joint + ")";
  r.link = name(node, where, "link", "link_" + std::to_string(i + 1));
  const std::string type = text(node, where, "type", "revolute");
  if (type != "revolute" && type != "prismatic")
    fail(where, "'type' must be revolute or prismatic (is '" + type + "')");
  r.prismatic = type == "prismatic";
  r.a = number(node, where, "a", 0.0);
  r.alpha = angle_ * number(node, where, "alpha", 0.0);
  r.d = number(node, where, "d", 0.0);
  r.theta = angle_ * number(node, where, "theta", 0.0);
  r.mass = number(node, where, "mass", 0.0);
  if (!(r.mass >= 0.0)) fail(where, "'mass' must be >= 0");
  const YAML::Node com = node["com"];
  if (com) {
    if (!com.IsSequence() || com.size() != 3) fail(where, "'com' must be [X, Y, Z]");
    for (std::size_t k = 0; k < 3; ++k)
      r.com[static_cast<int>(k)] = value(com[k], where, "'com'[" + std::to_string(k) + "]");
  }
  inertia(node, where, r);
  // About the DH frame's origin: the parallel-axis theorem gives it about the COM.
  if (about_origin)
    r.inertia -= r.mass * (r.com.squaredNorm() * Matrix3d::Identity() - r.com * r.com.transpose());
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(r.inertia);
  if (!(eig.eigenvalues().minCoeff() >= -1e-12 * std::max(1.0, r.inertia.norm())))
    fail(where,
         "the inertia about the centre of mass is not positive semi-definite"
         " (smallest principal moment " +
             std::to_string(eig.eigenvalues().minCoeff()) + " kg m^2)");
  limits(node, where, r);
  if (r.mass == 0.0 && !r.inertia.isZero(0.0))
    std::fprintf(stderr,
                 "dh_to_urdf: %s: warning: mass 0 with a non-zero inertia; the package treats a "
                 "link without mass as massless (no inertia), KDL keeps the inertia\n",
                 where.c_str());
  return r;
}

// The flange entry: a constant DH row of the table's convention, or a URDF origin.
void TableReader::flange(const YAML::Node& node, Table& t) const {
  const std::string where = "flange";
  if (!node.IsMap()) fail(where, "must be a map {a, alpha, d, theta} or {xyz, rpy}");
  checkKeys(node, where, {"a", "alpha", "d", "theta", "xyz", "rpy"});
  const bool dh = node["a"] || node["alpha"] || node["d"] || node["theta"];
  if (dh && (node["xyz"] || node["rpy"]))
    fail(where, "give a DH row {a, alpha, d, theta} or an origin {xyz, rpy}, not both");
  using Eigen::AngleAxisd;
  if (dh) {
    const double a = number(node, where, "a", 0.0), d = number(node, where, "d", 0.0);
    const double alpha = angle_ * number(node, where, "alpha", 0.0);
    const double theta = angle_ * number(node, where, "theta", 0.0);
    const Matrix3d Rx = AngleAxisd(alpha, Vector3d::UnitX()).toRotationMatrix();
    const Matrix3d Rz = AngleAxisd(theta, Vector3d::UnitZ()).toRotationMatrix();
    if (t.modified) {  // Rx(alpha) Tx(a) Rz(theta) Tz(d)
      t.R_n_tip = Rx * Rz;
      t.p_n_tip = Vector3d(a, 0.0, 0.0) + Rx * Vector3d(0.0, 0.0, d);
    } else {  // Rz(theta) Tz(d) Tx(a) Rx(alpha)
      t.R_n_tip = Rz * Rx;
      t.p_n_tip = Vector3d(0.0, 0.0, d) + Rz * Vector3d(a, 0.0, 0.0);
    }
    return;
  }
  const Vector3d rpy = angle_ * triple(node, where, "rpy");
  t.p_n_tip = triple(node, where, "xyz");
  t.R_n_tip = (AngleAxisd(rpy.z(), Vector3d::UnitZ()) * AngleAxisd(rpy.y(), Vector3d::UnitY()) *
               AngleAxisd(rpy.x(), Vector3d::UnitX()))
                  .toRotationMatrix();
}

void TableReader::inertia(const YAML::Node& node, const std::string& where, Row& r) const {
  const YAML::Node in = node["inertia"];
  if (!in) return;
  if (!in.IsMap()) fail(where, "'inertia' must be a map {ixx, iyy, izz, ixy, ixz, iyz}");
  checkKeys(in, where + " inertia", {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"});
  const std::string w = where + " inertia";
  Matrix3d& I = r.inertia;
  I(0, 0) = number(in, w, "ixx", 0.0);
  I(1, 1) = number(in, w, "iyy", 0.0);
  I(2, 2) = number(in, w, "izz", 0.0);
  I(0, 1) = I(1, 0) = number(in, w, "ixy", 0.0);
  I(0, 2) = I(2, 0) = number(in, w, "ixz", 0.0);
  I(1, 2) = I(2, 1) = number(in, w, "iyz", 0.0);
}

void TableReader::limits(const YAML::Node& node, const std::string& where, Row& r) const {
  const bool lower = static_cast<bool>(node["lower"]), upper = static_cast<bool>(node["upper"]);
  if (lower != upper) fail(where, "'lower' and 'upper' go together");
  r.limited = lower;
  const double unit = r.prismatic ? 1.0 : angle_;
  if (r.limited) {
    r.lower = unit * number(node, where, "lower", 0.0);
    r.upper = unit * number(node, where, "upper", 0.0);
    if (!(r.lower <= r.upper)) fail(where, "'lower' must not exceed 'upper'");
  } else if (r.prismatic) {
    fail(where, "a prismatic joint needs 'lower' and 'upper' [m]");
  }
  r.effort = number(node, where, "effort", kDefaultEffort);
  r.velocity = number(node, where, "velocity", kDefaultVelocity);
  if (!(r.effort > 0.0) || !(r.velocity > 0.0)) fail(where, "'effort' and 'velocity' must be > 0");
}

void TableReader::checkNames(const Table& t) const {
  std::set<std::string> joints, links{t.base_link, t.tip_link};
  if (t.base_link == t.tip_link) fail("", "'base_link' and 'tip_link' must differ");
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const std::string where = "links[" + std::to_string(i) + "] (" + t.rows[i].joint + ")";
    if (!joints.insert(t.rows[i].joint).second) fail(where, "joint name given twice");
    if (!links.insert(t.rows[i].link).second)
      fail(where, "link '" + t.rows[i].link + "' given twice (or is base_link or tip_link)");
  }
  if (!joints.insert(t.tip_link + "_joint").second)
    fail("", "a joint is named '" + t.tip_link + "_joint', the tip link's fixed joint");
}

// ------------------------------------------------------------------------ the mapping

// Shortest text that reads back as the same double.
std::string num(double x) {
  if (x == 0.0) return "0";
  char buffer[32];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, r.ptr);
}

std::string vec(const Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

// A URDF origin Rz(yaw) Rx(roll) plus a translation: rpy = (roll, 0, yaw).
struct Placement {
  Vector3d xyz = Vector3d::Zero();
  double roll = 0.0, yaw = 0.0;
  Matrix3d rotation() const {
    return (Eigen::AngleAxisd(yaw, Vector3d::UnitZ()) * Eigen::AngleAxisd(roll, Vector3d::UnitX()))
        .toRotationMatrix();
  }
  std::string text() const {
    return "<origin xyz=\"" + vec(xyz) + "\" rpy=\"" + num(roll) + " 0 " + num(yaw) + "\"/>";
  }
};

// The URDF link frame L_i of row i is the DH frame after the joint's motion and the
// row's constant translation along z; DH frame i is L_i . Rz(yaw_i) (modified) or
// L_i . Rz(yaw_i) Tx(a_i) Rx(alpha_i) (standard), yaw_i = theta (the revolute offset, or
// the prismatic row's constant angle). Rz(yaw) commutes with the motion along z, so it
// is carried to the next placement instead of the joint origin.
Placement frameInLink(const Table& t, const Row& r) {
  Placement p;
  p.yaw = r.theta;
  if (!t.modified) {
    p.roll = r.alpha;
    p.xyz = Eigen::AngleAxisd(r.theta, Vector3d::UnitZ()) * Vector3d(r.a, 0.0, 0.0);
  }
  return p;
}

// The origin of URDF joint i in L_{i-1}: DH frame i-1 (frameInLink of the previous row;
// base_link for i = 0), then Rx(alpha) Tx(a) of the connecting parameters (modified: of
// row i; standard: none, they are in frame i-1), then Tz(d) (revolute; a prismatic
// row's d is its offset, also constant).
Placement jointOrigin(const Table& t, std::size_t i) {
  Placement previous;  // DH frame i-1 in L_{i-1}
  if (i > 0) previous = frameInLink(t, t.rows[i - 1]);
  const Row& r = t.rows[i];
  const double alpha = t.modified ? r.alpha : 0.0, a = t.modified ? r.a : 0.0;
  // DH frame i-1 . Rx(alpha) Tx(a) Tz(d) = a rotation Rx(alpha), a translation
  // (a, -sin(alpha) d, cos(alpha) d) in frame i-1.
  const Vector3d local(a, -std::sin(alpha) * r.d, std::cos(alpha) * r.d);
  Placement p;
  p.xyz = previous.xyz + previous.rotation() * local;
  // previous.rotation() . Rx(alpha) = Rz(yaw) Rx(roll) Rx(alpha): roll adds.
  p.roll = previous.roll + alpha;
  p.yaw = previous.yaw;
  return p;
}

class Writer {
 public:
  std::string text;
  void line(const std::string& s) { text += s + "\n"; }

  void link(const std::string& name, const Table& t, const Row* r) {
    if (!r || (r->mass == 0.0 && r->inertia.isZero(0.0))) {
      line("  <link name=\"" + name + "\"/>");
      return;
    }
    // The inertial frame: the DH frame of the row, moved to the COM.
    const Placement dh = frameInLink(t, *r);
    Placement inertial = dh;
    inertial.xyz = dh.xyz + dh.rotation() * r->com;
    const Matrix3d& I = r->inertia;
    line("  <link name=\"" + name + "\">");
    line("    <inertial>");
    line("      " + inertial.text());
    line("      <mass value=\"" + num(r->mass) + "\"/>");
    line("      <inertia ixx=\"" + num(I(0, 0)) + "\" ixy=\"" + num(I(0, 1)) + "\" ixz=\"" +
         num(I(0, 2)) + "\" iyy=\"" + num(I(1, 1)) + "\" iyz=\"" + num(I(1, 2)) + "\" izz=\"" +
         num(I(2, 2)) + "\"/>");
    line("    </inertial>");
    line("  </link>");
  }

  void joint(const Row& r, const std::string& parent, const Placement& origin) {
    const char* type = r.prismatic ? "prismatic" : (r.limited ? "revolute" : "continuous");
    line("  <joint name=\"" + r.joint + "\" type=\"" + type + "\">");
    line("    <parent link=\"" + parent + "\"/>");
    line("    <child link=\"" + r.link + "\"/>");
    line("    " + origin.text());
    line("    <axis xyz=\"0 0 1\"/>");
    std::string limit = "    <limit ";
    if (r.limited) limit += "lower=\"" + num(r.lower) + "\" upper=\"" + num(r.upper) + "\" ";
    line(limit + "effort=\"" + num(r.effort) + "\" velocity=\"" + num(r.velocity) + "\"/>");
    line("  </joint>");
  }
};

// A URDF <origin> of any rotation R = Rz(yaw) Ry(pitch) Rx(roll) and translation p.
std::string originText(const Matrix3d& R, const Vector3d& p) {
  const double pitch = std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0)));
  double roll = std::atan2(R(2, 1), R(2, 2)), yaw = std::atan2(R(1, 0), R(0, 0));
  if (std::hypot(R(0, 0), R(1, 0)) < 1e-12) {  // pitch +-90 deg: only roll -+ yaw is defined
    roll = 0.0;
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  return "<origin xyz=\"" + vec(p) + "\" rpy=\"" + num(roll) + " " + num(pitch) + " " + num(yaw) +
         "\"/>";
}

// The tip link's origin in the last link: DH frame n, then the flange entry.
std::string tipOrigin(const Table& t) {
  const Placement n = frameInLink(t, t.rows.back());
  if (t.R_n_tip == Matrix3d::Identity() && t.p_n_tip.isZero(0.0)) return n.text();
  return originText(n.rotation() * t.R_n_tip, n.xyz + n.rotation() * t.p_n_tip);
}

std::string makeUrdf(const Table& t, const std::string& input) {
  Writer w;
  w.line("<?xml version=\"1.0\"?>");
  w.line("<!-- Generated by dh_to_urdf from " + input + " (" +
         (t.modified ? "modified" : "standard") + " DH); docs/dh_to_urdf.md. -->");
  w.line("<robot name=\"" + t.name + "\">");
  w.link(t.base_link, t, nullptr);
  std::string parent = t.base_link;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    w.joint(t.rows[i], parent, jointOrigin(t, i));
    w.link(t.rows[i].link, t, &t.rows[i]);
    parent = t.rows[i].link;
  }
  // The tip: DH frame n, or the flange entry's transform from it.
  w.line("  <joint name=\"" + t.tip_link + "_joint\" type=\"fixed\">");
  w.line("    <parent link=\"" + parent + "\"/>");
  w.line("    <child link=\"" + t.tip_link + "\"/>");
  w.line("    " + tipOrigin(t));
  w.line("  </joint>");
  w.line("  <link name=\"" + t.tip_link + "\"/>");
  w.line("</robot>");
  return w.text;
}

void run(const Options& o) {
  const Table table = TableReader(o.input).read();
  jle::CsvWriter out(o.output);  // an atomic text file (or standard output)
  out.writeText(makeUrdf(table, o.input));
  out.commit();
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "dh_to_urdf", kUsage, parseOptions, run);
}
