// make_body_urdf: a URDF of a human lower body (pelvis carrying head-arms-trunk, hips,
// knees, ankles, optionally subtalar joints, feet) scaled from body mass and height with
// the classic anthropometric tables. Every table value, its source and every assumption
// is documented here and in docs/body_model.md.
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace jle::cli;  // command_line.hpp: UsageError, optionValues, the parsers

const char* const kUsage =
    R"(usage: make_body_urdf --mass KG --height M [--subtalar | --sagittal]
                      [--segments SEGMENTS.yaml] [--name NAME] [--output FILE]
                      [--thigh-length M] [--shank-length M] [--foot-length M]
                      [--foot-height M] [--pelvis-width M] [--hat-length M]

Writes the URDF of a human lower body, scaled from body mass and height with
Dempster's segment parameters as tabulated by Winter (Biomechanics and Motor Control
of Human Movement, 4th ed., 2009, Table 4.1) and Drillis & Contini's segment lengths
(Winter Fig. 4.1). Tables, conventions and assumptions: docs/body_model.md.

Links: pelvis (the root; it carries the head-arms-trunk mass so that the model's mass
is the body mass; float it with the reader's or the node's floating-base option), and
per side s in {r, l}: femur_s, tibia_s, foot_s, fixed frames heel_s and toe_s on the
sole, massless hip_flexion_link_s and hip_adduction_link_s (and talus_s with
--subtalar). Joints: hip_flexion_s, hip_adduction_s, hip_rotation_s, knee_flexion_s,
ankle_flexion_s (and subtalar_inversion_s). Axes: x anterior, y left, z up in the
standing pose at q = 0; positive angles are hip flexion, adduction and internal
rotation, knee flexion, ankle dorsiflexion, subtalar inversion (left and right
mirrored), so that each effort is the net moment on the distal segment in that sense.

  --mass KG          body mass, 1 .. 500 (required)
  --height M         body height, 0.5 .. 2.7 (required)
  --subtalar         add a subtalar inversion joint (talus_s, massless) at each ankle
  --sagittal         a sagittal-plane (2-D) body: a root link `world` and the pelvis on
                     pelvis_tx (prismatic, +x forward), pelvis_tz (prismatic, +z up) and
                     pelvis_tilt (revolute about +y: anterior tilt); per side only
                     hip_flexion_s, knee_flexion_s and ankle_flexion_s. Every axis is
                     along y, so the package's planar solver (3x3 per segment) detects
                     it: joint_loads --planar on. Out-of-plane moments of inertia never
                     enter its loads; a segment given only iyy (below) gets ixx = izz =
                     iyy / 2, which satisfies the model's inertia check
  --segments PATH    a YAML map of the lab's own segment parameters, each overriding
                     the tables: keys thigh, shank, foot, hat (the pelvis link), each a
                     map of
                       mass: KG          > 0
                       com: [X, Y, Z]    [m] centre of mass in the link frame (thigh,
                                         shank: from the proximal joint, z down is
                                         negative; foot: from the ankle; hat: from the
                                         hip joint centres' midpoint)
                       inertia: {ixx, iyy, izz, ixy, ixz, iyz}
                                         [kg m^2] about the centre of mass, link axes;
                                         absent entries 0; with --sagittal iyy alone
                                         is enough (the sagittal moment)
                       gyration: [KX, KY, KZ]
                                         [m] radii of gyration about the centre of mass
                                         along the link axes, inertia m k^2 (or
                                         gyration: K with --sagittal: iyy = m K^2);
                                         not with inertia
                       length: M         thigh, shank, hat: as --thigh-length,
                                         --shank-length, --hat-length; foot: as
                                         --foot-length; foot also height: M (as
                                         --foot-height); and a map pelvis: {width: M}
                                         (as --pelvis-width); each within a factor of
                                         2 of the table's value, not with the option
                     a segment or value not given keeps the table's (the tables'
                     masses scale with --mass; the model's mass is then the sum); a
                     mass without inertia or gyration keeps the table's radii of
                     gyration (of the segment's length, given or the table's)
  --thigh-length M   hip to knee joint centre (default 0.245 x height)
  --shank-length M   knee to ankle joint centre (default 0.246 x height)
  --foot-length M    heel to toe (default 0.152 x height)
  --foot-height M    ankle joint centre above the sole (default 0.039 x height)
  --pelvis-width M   between the two hip joint centres (default: Hara et al. 2016's
                     regression on leg length, 0.178 m for the 1.75 m body; A4)
  --hat-length M     hip to shoulder (glenohumeral) height (default 0.288 x height)
  --name NAME        the robot's name (default human_lower_body)
  --output PATH      default: standard output; written to a temporary file beside PATH
                     and renamed onto it on success only
  --help             this text

The URDF goes through the package's model check (what joint_loads and the node run)
before it is written: an inertia it refuses (not positive semi-definite, or principal
moments breaking the triangle inequality, e.g. --sagittal with {iyy, ixy}, whose ixx
and izz are then 0) stops the tool naming the segment, its link and the violation.

Exit status: 0 success; 1 a data error (a --segments file, a model the model check
refuses, the output cannot be written); 2 a usage error (unknown, missing or repeated
option, a value out of range).
)";

constexpr double kPi = 3.14159265358979323846;

// ------------------------------------------------------------------------ the tables
// Winter, D. A. (2009). Biomechanics and Motor Control of Human Movement, 4th ed.,
// Wiley, Table 4.1 "Anthropometric data" (Dempster, W. T., 1955, WADC TR 55-159, via
// Miller & Nelson and Plagenhoef): segment mass / body mass, centre of mass from the
// proximal end / segment length, radius of gyration about the centre of mass /
// segment length.
struct SegmentTable {
  double mass_fraction;  // of body mass
  double com_fraction;   // of segment length, from the proximal end
  double gyration;       // radius of gyration about the COM, of segment length
  // Longitudinal / transverse radius of gyration (our assumption A2, see below).
  double longitudinal_ratio;
};

// A2. Winter gives one radius of gyration per segment; we take it about both axes
// across the segment and the longitudinal one as that radius times the ratio of the
// longitudinal to the sagittal radius in de Leva, P. (1996), "Adjustments to
// Zatsiorsky-Seluyanov's segment inertia parameters", J. Biomech. 29(9) 1223-1230,
// Table 4 (males). The principal moments (k_t, k_t, k_l) with k_l < k_t are positive
// and satisfy the triangle inequality (k_l^2 <= 2 k_t^2).

// Table 4.1 "Thigh" (greater trochanter / femoral condyles): 0.100, 0.433, 0.323.
// de Leva Table 4 thigh: longitudinal 14.9 %, sagittal 32.9 %.
constexpr SegmentTable kThigh{0.100, 0.433, 0.323, 14.9 / 32.9};
// Table 4.1 "Leg" (femoral condyles / medial malleolus): 0.0465, 0.433, 0.302.
// de Leva Table 4 shank: longitudinal 10.3 %, sagittal 25.5 %.
constexpr SegmentTable kShank{0.0465, 0.433, 0.302, 10.3 / 25.5};
// Table 4.1 "Foot" (lateral malleolus / head metatarsal II): 0.0145, 0.50, 0.475.
// de Leva Table 4 foot: longitudinal 12.4 %, sagittal 25.7 %.
constexpr SegmentTable kFoot{0.0145, 0.50, 0.475, 12.4 / 25.7};
// Table 4.1 "HAT" (head, arms and trunk; greater trochanter / glenohumeral joint):
// 0.678, 0.626, 0.496. de Leva Table 4 trunk: longitudinal 16.9 %, sagittal 32.8 %.
// A1. The pelvis link carries the HAT: Table 4.1's "Total leg" is 0.161 = 0.100 +
// 0.0465 + 0.0145, and 0.678 + 2 x 0.161 = 1.000, so the model's mass is the body mass.
constexpr SegmentTable kHat{0.678, 0.626, 0.496, 16.9 / 32.8};

// Drillis, R. & Contini, R. (1966), "Body segment parameters", Report 1166-03, New York
// University, as drawn in Winter (2009) Fig. 4.1: lengths as fractions of height H.
constexpr double kThighLength = 0.245;     // Fig. 4.1 thigh (hip 0.530 H - knee 0.285 H)
constexpr double kShankLength = 0.246;     // Fig. 4.1 leg (knee 0.285 H - ankle 0.039 H)
constexpr double kAnkleHeight = 0.039;     // Fig. 4.1 ankle height above the floor
constexpr double kFootLength = 0.152;      // Fig. 4.1 foot length
constexpr double kFootWidth = 0.055;       // Fig. 4.1 foot width (drawing only)
constexpr double kHatLength = 0.288;       // Fig. 4.1 shoulder 0.818 H - hip 0.530 H
constexpr double kShoulderWidth = 0.259;   // Fig. 4.1 shoulder width (drawing only)
constexpr double kChinHeight = 0.870;      // Fig. 4.1 chin height (drawing only)
constexpr double kShoulderHeight = 0.818;  // Fig. 4.1 shoulder height (drawing only)

// A3. Winter places the ankle only by its height; the foot's plan is ours: the heel
// 0.25 of the foot length behind the ankle joint centre, the toe 0.75 ahead, and
// Dempster's distal end (head of metatarsal II) on the sole 0.5 of the foot length
// ahead of the ankle. The foot segment is the line from the ankle to that point.
constexpr double kHeelBehindAnkle = 0.25;
constexpr double kMetatarsalAheadOfAnkle = 0.5;

// A4. The hip joint centres: Hara, R., McGinley, J., Briggs, C., Baker, R., Sangeux, M.
// (2016), "Predicting the location of the hip joint centres, impact of age group and
// sex", Sci. Rep. 6, 37707, the regression on leg length LL (ASIS to medial malleolus)
// alone: each centre 8 mm + 0.086 LL lateral of the mid-ASIS and 9 mm + 0.078 LL below
// it. LL is the model's hip-to-ankle length plus that drop (LL = (thigh + shank +
// 9 mm) / (1 - 0.078)). Drillis & Contini's hip width (0.191 H) is about the
// bitrochanteric breadth, about twice the joint centres' spacing.
constexpr double kHipLateral = 0.008, kHipLateralPerLeg = 0.086;  // [m], [m/m]
constexpr double kHipDrop = 0.009, kHipDropPerLeg = 0.078;        // [m], [m/m]

// The distance between the hip joint centres [m] for a hip-to-ankle length [m] (A4).
double hipJointSpacing(double hip_to_ankle) {
  const double leg_length = (hip_to_ankle + kHipDrop) / (1.0 - kHipDropPerLeg);
  return 2.0 * (kHipLateral + kHipLateralPerLeg * leg_length);
}

// Drawing only: cylinders of the segment's mass at Dempster's mean density (about
// 1.05 kg/l for the thigh, Winter Table 4.1).
constexpr double kDrawingDensity = 1050.0;  // kg/m^3

// Normal ranges of motion, American Academy of Orthopaedic Surgeons (1965), "Joint
// motion: method of measuring and recording" [deg]: hip flexion 120, extension 30,
// abduction 45, adduction 30, internal and external rotation 45; knee flexion 135
// (we allow 10 of hyperextension); ankle dorsiflexion 20, plantar flexion 50;
// inversion 35, eversion 15.
struct Range {
  double lower_deg, upper_deg;
};
constexpr Range kHipFlexion{-30.0, 120.0};
constexpr Range kHipAdduction{-45.0, 30.0};
constexpr Range kHipRotation{-45.0, 45.0};
constexpr Range kKneeFlexion{-10.0, 135.0};
constexpr Range kAnkleFlexion{-50.0, 20.0};
constexpr Range kSubtalarInversion{-15.0, 35.0};
// URDF requires effort and velocity limits; these bound nothing a human does (they are
// not a strength model) so that no tool clips a computed load.
constexpr double kEffortLimit = 2000.0;  // N m
constexpr double kVelocityLimit = 30.0;  // rad/s
// --sagittal: the pelvis's planar coordinates (a walkway's length, any tilt a body has).
constexpr double kWalkwayLimit = 1000.0;            // m, pelvis_tx and pelvis_tz
constexpr Range kPelvisTilt{-90.0, 90.0};           // deg, anterior tilt positive
constexpr double kPrismaticEffortLimit = 100000.0;  // N: bounds nothing

// ----------------------------------------------------------------------- the options

using Eigen::Matrix3d;
using Eigen::Vector3d;

// A segment's parameters from --segments, each overriding the table's.
struct SegmentOverride {
  std::optional<double> mass;
  std::optional<Vector3d> com;
  std::optional<Matrix3d> inertia;   // about the COM, link axes
  std::optional<Vector3d> gyration;  // [m] along the link axes
  bool sagittal_only = false;        // only iyy (or a scalar gyration) was given
};

// What --segments holds: per segment, and the lengths (option name -> metres).
struct Segments {
  std::map<std::string, SegmentOverride> segment;  // thigh, shank, foot, hat
  std::map<std::string, double> length;            // "--thigh-length" -> m
};

class SegmentsReader {
 public:
  SegmentsReader(const std::string& path, bool sagittal) : path_(path), sagittal_(sagittal) {}

  Segments read() const {
    YAML::Node root;
    try {
      root = YAML::LoadFile(path_);
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(path_ + ": " + e.what());
    }
    if (!root.IsMap()) fail("", "not a YAML map of segments");
    Segments out;
    for (const auto& entry : root) {
      const std::string name = entry.first.as<std::string>();
      if (name == "pelvis") {
        keys(entry.second, name, {"width"});
        out.length["--pelvis-width"] = number(entry.second["width"], name + ".width");
      } else if (name == "thigh" || name == "shank" || name == "foot" || name == "hat") {
        out.segment[name] = segment(entry.second, name, out);
      } else {
        fail(name, "unknown segment (thigh, shank, foot, hat, pelvis)");
      }
    }
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw std::runtime_error(path_ + ": " + (where.empty() ? "" : where + ": ") + what);
  }

  void keys(const YAML::Node& node, const std::string& where,
            const std::set<std::string>& known) const {
    if (!node.IsMap()) fail(where, "not a map");
    for (const auto& entry : node)
      if (!known.count(entry.first.as<std::string>()))
        fail(where, "unknown key '" + entry.first.as<std::string>() + "'");
  }

  double number(const YAML::Node& v, const std::string& where) const {
    const std::string s = v && v.IsScalar() ? v.as<std::string>() : std::string();
    double x = 0.0;
    const std::from_chars_result r = std::from_chars(s.data(), s.data() + s.size(), x);
    if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(x))
      fail(where, "must be a finite number (is '" + s + "')");
    return x;
  }

  Vector3d triple(const YAML::Node& v, const std::string& where) const {
    if (!v.IsSequence() || v.size() != 3) fail(where, "must be [X, Y, Z]");
    return Vector3d(number(v[0], where + "[0]"), number(v[1], where + "[1]"),
                    number(v[2], where + "[2]"));
  }

  SegmentOverride segment(const YAML::Node& node, const std::string& name, Segments& out) const {
    keys(node, name, {"mass", "com", "inertia", "gyration", "length", "height"});
    SegmentOverride o;
    if (node["mass"]) {
      o.mass = number(node["mass"], name + ".mass");
      if (!(*o.mass > 0.0)) fail(name + ".mass", "must be > 0 [kg]");
    }
    if (node["com"]) o.com = triple(node["com"], name + ".com");
    if (node["inertia"] && node["gyration"]) fail(name, "give inertia or gyration, not both");
    if (node["inertia"]) inertia(node["inertia"], name + ".inertia", o);
    if (node["gyration"]) gyration(node["gyration"], name + ".gyration", o);
    if (node["length"]) {
      static const std::map<std::string, std::string> option{{"thigh", "--thigh-length"},
                                                             {"shank", "--shank-length"},
                                                             {"foot", "--foot-length"},
                                                             {"hat", "--hat-length"}};
      out.length[option.at(name)] = number(node["length"], name + ".length");
    }
    if (node["height"]) {
      if (name != "foot") fail(name, "'height' is a key of foot only (the ankle's height)");
      out.length["--foot-height"] = number(node["height"], "foot.height");
    }
    return o;
  }

  void inertia(const YAML::Node& node, const std::string& where, SegmentOverride& o) const {
    keys(node, where, {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"});
    const auto at = [&](const char* key) {
      return node[key] ? number(node[key], where + "." + key) : 0.0;
    };
    Matrix3d I;
    I << at("ixx"), at("ixy"), at("ixz"), at("ixy"), at("iyy"), at("iyz"), at("ixz"), at("iyz"),
        at("izz");
    o.sagittal_only = node.size() == 1 && node["iyy"];
    if (o.sagittal_only && !sagittal_)
      fail(where,
           "iyy alone describes a sagittal (--sagittal) body; a 3-D body needs ixx, "
           "iyy and izz");
    o.inertia = I;
  }

  void gyration(const YAML::Node& node, const std::string& where, SegmentOverride& o) const {
    if (node.IsScalar()) {
      if (!sagittal_) fail(where, "one radius is the sagittal one (--sagittal); give [KX, KY, KZ]");
      o.gyration = Vector3d(0.0, number(node, where), 0.0);
      o.sagittal_only = true;
    } else {
      o.gyration = triple(node, where);
    }
    if (!(o.gyration->minCoeff() >= 0.0)) fail(where, "radii of gyration must be >= 0 [m]");
  }

  std::string path_;
  bool sagittal_;
};

struct Options {
  double mass = 0.0, height = 0.0;
  bool subtalar = false;
  bool sagittal = false;
  std::string segments;  // --segments PATH, "" none
  double thigh_length = 0.0, shank_length = 0.0, foot_length = 0.0, foot_height = 0.0,
         pelvis_width = 0.0, hat_length = 0.0;
  Segments overrides;  // from --segments
  std::string name = "human_lower_body", output;
  std::string command;  // how the file was made, for its header comment
};

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v = optionValues(
      argc, argv,
      {"--mass", "--height", "--thigh-length", "--shank-length", "--foot-length", "--foot-height",
       "--pelvis-width", "--hat-length", "--name", "--output", "--segments"},
      {"--subtalar", "--sagittal"});
  const std::string mass = requiredValue(v, "--mass", "KG");
  const std::string height = requiredValue(v, "--height", "M");
  Options o;
  o.mass = parseNumberIn("--mass", mass, 1.0, 500.0);
  o.height = parseNumberIn("--height", height, 0.5, 2.7);
  o.subtalar = v.count("--subtalar") > 0;
  o.sagittal = v.count("--sagittal") > 0;
  if (o.subtalar && o.sagittal) throw UsageError("--subtalar and --sagittal exclude each other");
  if (v.count("--segments")) {
    o.segments = v["--segments"];
    o.overrides = SegmentsReader(o.segments, o.sagittal).read();
  }
  const double h = o.height;
  const auto length = [&](const char* key, double table) {
    // A measured length may differ from the table's by a factor of 2 either way.
    const auto yaml = o.overrides.length.find(key);
    if (yaml == o.overrides.length.end())
      return v.count(key) ? parseNumberIn(key, v[key], 0.5 * table, 2.0 * table) : table;
    if (v.count(key)) throw UsageError(std::string(key) + " is also given by --segments");
    if (!(yaml->second >= 0.5 * table && yaml->second <= 2.0 * table))
      throw std::runtime_error(o.segments + ": the length of " + key + " (" +
                               std::to_string(yaml->second) + " m) is not within " +
                               std::to_string(0.5 * table) + " .. " + std::to_string(2.0 * table) +
                               " m (the table's value / 2 .. x 2)");
    return yaml->second;
  };
  o.thigh_length = length("--thigh-length", kThighLength * h);
  o.shank_length = length("--shank-length", kShankLength * h);
  o.foot_length = length("--foot-length", kFootLength * h);
  o.foot_height = length("--foot-height", kAnkleHeight * h);
  o.pelvis_width = length("--pelvis-width", hipJointSpacing(o.thigh_length + o.shank_length));
  o.hat_length = length("--hat-length", kHatLength * h);
  if (v.count("--name")) {
    o.name = v["--name"];
    for (char c : o.name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'))
        throw UsageError("--name: '" + o.name + "' holds characters other than A-Z a-z 0-9 _ -");
  }
  if (v.count("--output")) o.output = v["--output"];
  // The header comment repeats the options (not the output path), in a fixed order.
  o.command = "make_body_urdf";
  for (const char* key : {"--mass", "--height", "--thigh-length", "--shank-length", "--foot-length",
                          "--foot-height", "--pelvis-width", "--hat-length", "--name"})
    if (v.count(key)) o.command += std::string(" ") + key + " " + v[key];
  if (o.subtalar) o.command += " --subtalar";
  if (o.sagittal) o.command += " --sagittal";
  if (!o.segments.empty()) o.command += " --segments " + o.segments;
  return o;
}

// ------------------------------------------------------------------------- the model

// Shortest text that reads back as the same double (deterministic, locale-free).
std::string num(double x) {
  if (x == 0.0) return "0";  // also turns -0 into 0
  char buffer[32];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, r.ptr);
}

std::string vec(const Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

struct Body {
  double m_hat, m_thigh, m_shank, m_foot;
  Vector3d com_hat, com_thigh, com_shank, com_foot;  // in the segment's own link frame
  Matrix3d i_hat, i_thigh, i_shank, i_foot;          // about the COM, link axes
  double foot_segment_length;
};

// Inertia about the COM of a segment of mass m and length l whose long axis is the unit
// vector u: k_t l about every axis across it, k_l l along it (assumption A2).
Matrix3d segmentInertia(double m, double l, const SegmentTable& t, const Vector3d& u) {
  const double transverse = m * (t.gyration * l) * (t.gyration * l);
  const double kl = t.gyration * t.longitudinal_ratio * l;
  const double longitudinal = m * kl * kl;
  const Matrix3d uu = u * u.transpose();
  return transverse * (Matrix3d::Identity() - uu) + longitudinal * uu;
}

// A segment's table values replaced by what --segments gives. A mass without an inertia
// keeps the table's radii of gyration (the table's inertia, m k^2 with k from the segment
// length given or the table's, scales with the mass). A sagittal-only inertia (iyy) gets
// ixx = izz = iyy / 2: the least that meets the triangle inequality; a planar body
// turning about y never multiplies them.
void applyOverride(const SegmentOverride& s, double& mass, Vector3d& com, Matrix3d& inertia) {
  if (s.mass && !s.inertia && !s.gyration) inertia *= *s.mass / mass;
  if (s.mass) mass = *s.mass;
  if (s.com) com = *s.com;
  if (s.inertia) inertia = *s.inertia;
  if (s.gyration)
    inertia = mass * s.gyration->cwiseProduct(*s.gyration).asDiagonal().toDenseMatrix();
  if (s.sagittal_only) {
    const double iyy = inertia(1, 1);
    inertia = Vector3d(0.5 * iyy, iyy, 0.5 * iyy).asDiagonal();
  }
}

Body makeBody(const Options& o) {
  Body b;
  const double m = o.mass;
  b.m_thigh = kThigh.mass_fraction * m;
  b.m_shank = kShank.mass_fraction * m;
  b.m_foot = kFoot.mass_fraction * m;
  b.m_hat = kHat.mass_fraction * m;
  const Vector3d down(0.0, 0.0, -1.0);
  // Thigh and shank hang straight down from their proximal joint at q = 0.
  b.com_thigh = kThigh.com_fraction * o.thigh_length * down;
  b.com_shank = kShank.com_fraction * o.shank_length * down;
  b.i_thigh = segmentInertia(b.m_thigh, o.thigh_length, kThigh, down);
  b.i_shank = segmentInertia(b.m_shank, o.shank_length, kShank, down);
  // HAT: from the hip joint centres' level (the pelvis origin) up to the shoulders.
  b.com_hat = kHat.com_fraction * o.hat_length * Vector3d::UnitZ();
  b.i_hat = segmentInertia(b.m_hat, o.hat_length, kHat, Vector3d::UnitZ());
  // Foot: from the ankle to the head of metatarsal II on the sole (A3).
  const Vector3d metatarsal(kMetatarsalAheadOfAnkle * o.foot_length, 0.0, -o.foot_height);
  b.foot_segment_length = metatarsal.norm();
  b.com_foot = kFoot.com_fraction * metatarsal;
  b.i_foot = segmentInertia(b.m_foot, b.foot_segment_length, kFoot, metatarsal.normalized());
  const std::map<std::string, SegmentOverride>& given = o.overrides.segment;
  const auto apply = [&](const char* name, double& mass, Vector3d& com, Matrix3d& inertia) {
    const auto it = given.find(name);
    if (it != given.end()) applyOverride(it->second, mass, com, inertia);
  };
  apply("thigh", b.m_thigh, b.com_thigh, b.i_thigh);
  apply("shank", b.m_shank, b.com_shank, b.i_shank);
  apply("foot", b.m_foot, b.com_foot, b.i_foot);
  apply("hat", b.m_hat, b.com_hat, b.i_hat);
  return b;
}

// ------------------------------------------------------------------------ the writer

class UrdfText {
 public:
  std::string text;

  void line(const std::string& s) { text += s + "\n"; }

  void inertial(double mass, const Vector3d& com, const Matrix3d& i) {
    line("    <inertial>");
    line("      <origin xyz=\"" + vec(com) + "\" rpy=\"0 0 0\"/>");
    line("      <mass value=\"" + num(mass) + "\"/>");
    line("      <inertia ixx=\"" + num(i(0, 0)) + "\" ixy=\"" + num(i(0, 1)) + "\" ixz=\"" +
         num(i(0, 2)) + "\" iyy=\"" + num(i(1, 1)) + "\" iyz=\"" + num(i(1, 2)) + "\" izz=\"" +
         num(i(2, 2)) + "\"/>");
    line("    </inertial>");
  }
  // A visual at xyz (rpy zero): geometry is "<cylinder .../>", "<box .../>", "<sphere .../>".
  void visual(const Vector3d& xyz, const std::string& geometry, const std::string& material,
              const std::string& rpy = "0 0 0") {
    line("    <visual>");
    line("      <origin xyz=\"" + vec(xyz) + "\" rpy=\"" + rpy + "\"/>");
    line("      <geometry>" + geometry + "</geometry>");
    line("      <material name=\"" + material + "\"/>");
    line("    </visual>");
  }
  void revolute(const std::string& name, const std::string& parent, const std::string& child,
                const Vector3d& xyz, const Vector3d& axis, const Range& range) {
    line("  <joint name=\"" + name + "\" type=\"revolute\">");
    line("    <parent link=\"" + parent + "\"/>");
    line("    <child link=\"" + child + "\"/>");
    line("    <origin xyz=\"" + vec(xyz) + "\" rpy=\"0 0 0\"/>");
    line("    <axis xyz=\"" + vec(axis) + "\"/>");
    line("    <limit lower=\"" + num(range.lower_deg * kPi / 180.0) + "\" upper=\"" +
         num(range.upper_deg * kPi / 180.0) + "\" effort=\"" + num(kEffortLimit) +
         "\" velocity=\"" + num(kVelocityLimit) + "\"/>");
    line("  </joint>");
  }
  void fixed(const std::string& name, const std::string& parent, const std::string& child,
             const Vector3d& xyz) {
    line("  <joint name=\"" + name + "\" type=\"fixed\">");
    line("    <parent link=\"" + parent + "\"/>");
    line("    <child link=\"" + child + "\"/>");
    line("    <origin xyz=\"" + vec(xyz) + "\" rpy=\"0 0 0\"/>");
    line("  </joint>");
  }
  void emptyLink(const std::string& name) { line("  <link name=\"" + name + "\"/>"); }
  // A prismatic joint at the parent's origin, limits [m].
  void prismatic(const std::string& name, const std::string& parent, const std::string& child,
                 const Vector3d& axis, double limit) {
    line("  <joint name=\"" + name + "\" type=\"prismatic\">");
    line("    <parent link=\"" + parent + "\"/>");
    line("    <child link=\"" + child + "\"/>");
    line("    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>");
    line("    <axis xyz=\"" + vec(axis) + "\"/>");
    line("    <limit lower=\"" + num(-limit) + "\" upper=\"" + num(limit) + "\" effort=\"" +
         num(kPrismaticEffortLimit) + "\" velocity=\"" + num(kVelocityLimit) + "\"/>");
    line("  </joint>");
  }
};

std::string cylinder(double radius, double length) {
  return "<cylinder radius=\"" + num(radius) + "\" length=\"" + num(length) + "\"/>";
}
std::string box(const Vector3d& size) { return "<box size=\"" + vec(size) + "\"/>"; }
std::string sphere(double radius) { return "<sphere radius=\"" + num(radius) + "\"/>"; }

// Radius of a cylinder of mass m and length l at the drawing density.
double drawingRadius(double m, double l) { return std::sqrt(m / (kDrawingDensity * kPi * l)); }

void writeLeg(UrdfText& u, const Options& o, const Body& b, const std::string& s) {
  // Mirror: the right side's adduction, rotation and inversion axes point along +x, +z,
  // +x; the left side's along -x, -z, -x. Flexion of hip and dorsiflexion turn the
  // distal segment forward and up about -y; knee flexion turns the shank back about +y.
  const double side = s == "r" ? 1.0 : -1.0;
  const Vector3d hip(0.0, -side * 0.5 * o.pelvis_width, 0.0);
  const Vector3d minus_y(0.0, -1.0, 0.0), plus_y(0.0, 1.0, 0.0);
  const Vector3d mirrored_x(side, 0.0, 0.0), mirrored_z(0.0, 0.0, side);

  if (o.sagittal) {  // flexion only: every axis along y
    u.revolute("hip_flexion_" + s, "pelvis", "femur_" + s, hip, minus_y, kHipFlexion);
  } else {
    u.revolute("hip_flexion_" + s, "pelvis", "hip_flexion_link_" + s, hip, minus_y, kHipFlexion);
    u.emptyLink("hip_flexion_link_" + s);
    u.revolute("hip_adduction_" + s, "hip_flexion_link_" + s, "hip_adduction_link_" + s,
               Vector3d::Zero(), mirrored_x, kHipAdduction);
    u.emptyLink("hip_adduction_link_" + s);
    u.revolute("hip_rotation_" + s, "hip_adduction_link_" + s, "femur_" + s, Vector3d::Zero(),
               mirrored_z, kHipRotation);
  }

  u.line("  <link name=\"femur_" + s + "\">");
  u.inertial(b.m_thigh, b.com_thigh, b.i_thigh);
  u.visual(Vector3d(0.0, 0.0, -0.5 * o.thigh_length),
           cylinder(drawingRadius(b.m_thigh, o.thigh_length), o.thigh_length), "skin");
  u.line("  </link>");
  u.revolute("knee_flexion_" + s, "femur_" + s, "tibia_" + s, Vector3d(0.0, 0.0, -o.thigh_length),
             plus_y, kKneeFlexion);

  u.line("  <link name=\"tibia_" + s + "\">");
  u.inertial(b.m_shank, b.com_shank, b.i_shank);
  u.visual(Vector3d(0.0, 0.0, -0.5 * o.shank_length),
           cylinder(drawingRadius(b.m_shank, o.shank_length), o.shank_length), "skin");
  u.line("  </link>");
  const Vector3d ankle(0.0, 0.0, -o.shank_length);
  if (o.subtalar) {
    // The subtalar joint is put at the ankle joint centre with its axis along the foot
    // (x): the real axis is oblique (Inman 1976), but this one makes the effort the
    // inversion moment in the anatomical sense.
    u.revolute("ankle_flexion_" + s, "tibia_" + s, "talus_" + s, ankle, minus_y, kAnkleFlexion);
    u.emptyLink("talus_" + s);
    u.revolute("subtalar_inversion_" + s, "talus_" + s, "foot_" + s, Vector3d::Zero(), mirrored_x,
               kSubtalarInversion);
  } else {
    u.revolute("ankle_flexion_" + s, "tibia_" + s, "foot_" + s, ankle, minus_y, kAnkleFlexion);
  }

  u.line("  <link name=\"foot_" + s + "\">");
  u.inertial(b.m_foot, b.com_foot, b.i_foot);
  const double width = kFootWidth * o.height;
  u.visual(Vector3d((0.5 - kHeelBehindAnkle) * o.foot_length, 0.0, -0.5 * o.foot_height),
           box(Vector3d(o.foot_length, width, o.foot_height)), "shoe");
  u.line("  </link>");
  u.fixed("heel_joint_" + s, "foot_" + s, "heel_" + s,
          Vector3d(-kHeelBehindAnkle * o.foot_length, 0.0, -o.foot_height));
  u.emptyLink("heel_" + s);
  u.fixed("toe_joint_" + s, "foot_" + s, "toe_" + s,
          Vector3d((1.0 - kHeelBehindAnkle) * o.foot_length, 0.0, -o.foot_height));
  u.emptyLink("toe_" + s);
}

std::string makeUrdf(const Options& o) {
  const Body b = makeBody(o);
  UrdfText u;
  u.line("<?xml version=\"1.0\"?>");
  // No double hyphen may appear inside an XML comment: the options are spelled out.
  std::string command = o.command, segments = o.segments;
  for (std::size_t p; (p = command.find("--")) != std::string::npos;) command.replace(p, 2, "");
  for (std::size_t p; (p = segments.find("--")) != std::string::npos;) segments.replace(p, 2, "-");
  u.line("<!-- Generated by make_body_urdf (" + command + "); do not edit.");
  u.line("     Human lower body, Dempster's segment parameters via Winter (2009) Table 4.1,");
  u.line("     Drillis and Contini's lengths via Winter Fig. 4.1, the hip joint centres of");
  u.line("     Hara et al. (2016): docs/body_model.md.");
  u.line("     Body mass " + num(o.mass) + " kg, height " + num(o.height) +
         " m; the pelvis carries head, arms and trunk." +
         (o.segments.empty()
              ? std::string()
              : "\n     Segment parameters of " + segments + " replace the tables' where given.") +
         (o.sagittal ? "\n     Sagittal plane: every joint turns about y (planar solver)." : "") +
         " -->");
  u.line("<robot name=\"" + o.name + "\">");
  u.line("  <material name=\"skin\"><color rgba=\"0.87 0.72 0.6 1\"/></material>");
  u.line("  <material name=\"shoe\"><color rgba=\"0.2 0.2 0.25 1\"/></material>");
  u.line("  <material name=\"cloth\"><color rgba=\"0.25 0.4 0.65 1\"/></material>");

  if (o.sagittal) {
    // A 2-D body: the pelvis moves in the x-z plane of a fixed root.
    u.emptyLink("world");
    u.prismatic("pelvis_tx", "world", "pelvis_tx_link", Vector3d::UnitX(), kWalkwayLimit);
    u.emptyLink("pelvis_tx_link");
    u.prismatic("pelvis_tz", "pelvis_tx_link", "pelvis_tz_link", Vector3d::UnitZ(), kWalkwayLimit);
    u.emptyLink("pelvis_tz_link");
    u.revolute("pelvis_tilt", "pelvis_tz_link", "pelvis", Vector3d::Zero(), Vector3d::UnitY(),
               kPelvisTilt);
  }
  u.line("  <link name=\"pelvis\">");
  u.inertial(b.m_hat, b.com_hat, b.i_hat);
  const double h = o.height;
  // Drawing only: a pelvis block across the hips, the trunk up to the shoulders, a head.
  u.visual(Vector3d(0.0, 0.0, 0.05 * h), box(Vector3d(0.1 * h, o.pelvis_width + 0.05 * h, 0.1 * h)),
           "cloth");
  u.visual(Vector3d(0.0, 0.0, 0.5 * (0.1 * h + o.hat_length)),
           box(Vector3d(0.11 * h, 0.8 * kShoulderWidth * h, o.hat_length - 0.1 * h)), "cloth");
  const double head_radius = 0.5 * (1.0 - kChinHeight) * h;
  u.visual(Vector3d(0.0, 0.0, o.hat_length + (kChinHeight - kShoulderHeight) * h + head_radius),
           sphere(head_radius), "skin");
  u.line("  </link>");

  writeLeg(u, o, b, "r");
  writeLeg(u, o, b, "l");
  u.line("</robot>");
  return u.text;
}

// -------------------------------------------------------------------------- output

std::string errnoText() { return std::strerror(errno); }

// Standard output, or a temporary file beside `path` renamed onto it once complete.
void writeOutput(const std::string& path, const std::string& text) {
  if (path.empty()) {
    if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0)
      throw std::runtime_error("standard output: cannot write: " + errnoText());
    return;
  }
  struct stat existing;
  const bool exists = ::stat(path.c_str(), &existing) == 0;
  if (exists && S_ISDIR(existing.st_mode)) throw std::runtime_error(path + ": is a directory");
  const std::size_t slash = path.rfind('/');
  std::string temporary = (slash == std::string::npos ? std::string() : path.substr(0, slash + 1)) +
                          "." + path.substr(slash == std::string::npos ? 0 : slash + 1) +
                          ".tmp.XXXXXX";
  const int fd = ::mkstemp(temporary.data());
  if (fd < 0) throw std::runtime_error(path + ": cannot create a temporary file: " + errnoText());
  const mode_t mask = ::umask(0);
  ::umask(mask);
  bool ok = ::fchmod(fd, exists ? (existing.st_mode & 07777) : (0666 & ~mask)) == 0;
  for (std::size_t done = 0; ok && done < text.size();) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  ok = ok && ::fsync(fd) == 0;
  const std::string reason = errnoText();
  ok = (::close(fd) == 0) && ok;
  if (!ok || std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string why = ok ? errnoText() : reason;
    ::unlink(temporary.c_str());
    throw std::runtime_error(path + ": cannot write: " + why);
  }
}

// The segment (--segments' key) whose parameters a link of the model carries; "" none.
std::string segmentOfLink(const std::string& link) {
  static const char* const kLinkSegment[][2] = {
      {"femur_", "thigh"}, {"tibia_", "shank"}, {"foot_", "foot"}, {"pelvis", "hat"}};
  for (const auto& [prefix, segment] : kLinkSegment)
    if (link.rfind(prefix, 0) == 0) return segment;
  return "";
}

// The model as joint_loads and the node read it (the package's model check with its
// default options): one they would refuse is not written, and the message names the
// segment, its link and the violation. Their warnings are said here too.
void checkModel(const std::string& urdf, const Options& o) {
  try {
    for (const std::string& w : jle::modelFromUrdfString(urdf).warnings)
      std::fprintf(stderr, "make_body_urdf: warning: %s\n", w.c_str());
  } catch (const jle::ModelError& e) {
    const std::string what = e.what(), refused = "; joint_loads and the node refuse such a model";
    const std::string head = "link '";  // the reader's messages name the link first
    const std::size_t close =
        what.rfind(head, 0) == 0 ? what.find("': ", head.size()) : std::string::npos;
    if (close == std::string::npos) throw std::runtime_error(what + refused);
    const std::string link = what.substr(head.size(), close - head.size());
    const std::string segment = segmentOfLink(link);
    std::string where = "link '" + link + "'";
    if (!segment.empty())
      where = segment + " (" + where + (o.segments.empty() ? "" : ", " + o.segments) + ")";
    throw std::runtime_error(where + ": " + what.substr(close + 3) + refused);
  }
}

void run(const Options& o) {
  const std::string urdf = makeUrdf(o);
  checkModel(urdf, o);
  writeOutput(o.output, urdf);
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "make_body_urdf", kUsage, parseOptions, run);
}
