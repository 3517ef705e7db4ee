// URDF -> Model: parsing with tinyxml2 (the document order of the joints fixes the
// segment order), validation with the culprit's name, lumping of fixed joints.
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <tinyxml2.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace jle {
namespace {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Pose {
  Matrix3 R = Matrix3::Identity();
  Vector3 p = Vector3::Zero();
  Pose operator*(const Pose& o) const { return {R * o.R, p + R * o.p}; }
};

struct LinkDesc {
  std::string name;
  int line = 0;
  bool has_inertial = false;
  double mass = 0.0;
  Pose inertial_origin;               // com frame in the link frame
  Matrix3 inertia = Matrix3::Zero();  // about the com, in the inertial frame
  std::vector<int> child_joints;      // document order
  int parent_joint = -1;
};

struct JointDesc {
  std::string name;
  std::string type;
  int line = 0;
  std::string parent, child;
  Pose origin;
  Vector3 axis = Vector3::UnitX();
  bool mimic = false;
  std::string mimic_joint;
  double multiplier = 1.0, offset = 0.0;
  double damping = 0.0, friction = 0.0;  // <dynamics>
  // <limit>: none where absent (or, for velocity and effort, 0 or less)
  double lower = -kInf, upper = kInf, velocity = kInf, effort = kInf;
};

[[noreturn]] void fail(const std::string& what) { throw ModelError(what); }

std::string where(const tinyxml2::XMLElement* e) {
  return " (line " + std::to_string(e->GetLineNum()) + ")";
}

// Whitespace-separated finite numbers; `count` of them exactly.
std::vector<double> numbers(const char* text, std::size_t count, const std::string& what) {
  std::vector<double> out;
  const char* s = text;
  while (true) {
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r') ++s;
    if (*s == '\0') break;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s, &end);
    if (end == s || (*end != '\0' && *end != ' ' && *end != '\t' && *end != '\n' && *end != '\r'))
      fail(what + ": '" + text + "' is not a list of numbers");
    if (!std::isfinite(v)) fail(what + ": '" + text + "' is not finite");
    out.push_back(v);
    s = end;
  }
  if (out.size() != count)
    fail(what + ": expected " + std::to_string(count) + " numbers, got '" + text + "'");
  return out;
}

double number(const tinyxml2::XMLElement* e, const char* attribute, const std::string& what,
              bool required, double fallback) {
  const char* text = e->Attribute(attribute);
  if (!text) {
    if (required) fail(what + ": missing attribute '" + attribute + "'" + where(e));
    return fallback;
  }
  return numbers(text, 1, what + " attribute '" + attribute + "'" + where(e))[0];
}

Vector3 vector3(const tinyxml2::XMLElement* e, const char* attribute, const std::string& what,
                const Vector3& fallback) {
  const char* text = e->Attribute(attribute);
  if (!text) return fallback;
  const std::vector<double> v =
      numbers(text, 3, what + " attribute '" + attribute + "'" + where(e));
  return Vector3(v[0], v[1], v[2]);
}

Pose origin(const tinyxml2::XMLElement* parent, const std::string& what) {
  Pose pose;
  const tinyxml2::XMLElement* e = parent->FirstChildElement("origin");
  if (!e) return pose;
  pose.p = vector3(e, "xyz", what + " origin", Vector3::Zero());
  const Vector3 rpy = vector3(e, "rpy", what + " origin", Vector3::Zero());
  // URDF: fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll).
  pose.R =
      (Eigen::AngleAxisd(rpy.z(), Vector3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vector3::UnitY()) *
       Eigen::AngleAxisd(rpy.x(), Vector3::UnitX()))
          .toRotationMatrix();
  return pose;
}

std::string requiredName(const tinyxml2::XMLElement* e, const char* attribute,
                         const std::string& what) {
  const char* text = e->Attribute(attribute);
  if (!text || !*text) fail(what + ": missing attribute '" + attribute + "'" + where(e));
  return text;
}

// The child element `name` of e; a model error `message` (with e's line) without it.
const tinyxml2::XMLElement* requiredChild(const tinyxml2::XMLElement* e, const char* name,
                                          const std::string& message) {
  const tinyxml2::XMLElement* child = e->FirstChildElement(name);
  if (!child) fail(message + where(e));
  return child;
}

// A <tag> element's name and line into `desc`; returns how messages name it ("link 'a'").
template <typename Desc>
std::string nameOf(const tinyxml2::XMLElement* e, const char* tag, Desc& desc) {
  desc.name = requiredName(e, "name", std::string("<") + tag + ">");
  desc.line = e->GetLineNum();
  return std::string(tag) + " '" + desc.name + "'";
}

LinkDesc parseLink(const tinyxml2::XMLElement* e) {
  LinkDesc link;
  const std::string what = nameOf(e, "link", link);
  const tinyxml2::XMLElement* in = e->FirstChildElement("inertial");
  if (!in) return link;
  link.has_inertial = true;
  link.inertial_origin = origin(in, what + " inertial");
  const tinyxml2::XMLElement* m = requiredChild(in, "mass", what + ": <inertial> without <mass>");
  link.mass = number(m, "value", what + " mass", true, 0.0);
  const tinyxml2::XMLElement* i =
      requiredChild(in, "inertia", what + ": <inertial> without <inertia>");
  const std::string wi = what + " inertia";
  const double ixx = number(i, "ixx", wi, true, 0.0), ixy = number(i, "ixy", wi, true, 0.0),
               ixz = number(i, "ixz", wi, true, 0.0), iyy = number(i, "iyy", wi, true, 0.0),
               iyz = number(i, "iyz", wi, true, 0.0), izz = number(i, "izz", wi, true, 0.0);
  link.inertia << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  return link;
}

JointDesc parseJoint(const tinyxml2::XMLElement* e) {
  JointDesc joint;
  const std::string what = nameOf(e, "joint", joint);
  joint.type = requiredName(e, "type", what);
  const tinyxml2::XMLElement* parent = requiredChild(e, "parent", what + ": missing <parent>");
  const tinyxml2::XMLElement* child = requiredChild(e, "child", what + ": missing <child>");
  joint.parent = requiredName(parent, "link", what + " <parent>");
  joint.child = requiredName(child, "link", what + " <child>");
  joint.origin = origin(e, what);
  if (const tinyxml2::XMLElement* a = e->FirstChildElement("axis"))
    joint.axis = vector3(a, "xyz", what + " axis", Vector3::UnitX());
  if (const tinyxml2::XMLElement* m = e->FirstChildElement("mimic")) {
    joint.mimic = true;
    joint.mimic_joint = requiredName(m, "joint", what + " <mimic>");
    joint.multiplier = number(m, "multiplier", what + " mimic", false, 1.0);
    joint.offset = number(m, "offset", what + " mimic", false, 0.0);
  }
  if (const tinyxml2::XMLElement* d = e->FirstChildElement("dynamics")) {
    joint.damping = number(d, "damping", what + " dynamics", false, 0.0);
    joint.friction = number(d, "friction", what + " dynamics", false, 0.0);
  }
  if (const tinyxml2::XMLElement* l = e->FirstChildElement("limit")) {
    if (joint.type == "revolute" || joint.type == "prismatic") {
      joint.lower = number(l, "lower", what + " limit", false, -kInf);
      joint.upper = number(l, "upper", what + " limit", false, kInf);
      if (joint.lower > joint.upper)
        fail(what + ": limit lower " + std::to_string(joint.lower) + " > upper " +
             std::to_string(joint.upper) + where(l));
    }
    const double velocity = number(l, "velocity", what + " limit", false, 0.0);
    const double effort = number(l, "effort", what + " limit", false, 0.0);
    if (velocity > 0.0) joint.velocity = velocity;
    if (effort > 0.0) joint.effort = effort;
  }
  return joint;
}

// What a non-physical inertia accepted with ModelOptions::accept_nonphysical_inertia
// can and cannot affect, said after each violation.
std::string nonphysicalNote(const std::string& link) {
  return "; accepted (accept_nonphysical_inertia): no rigid body has this inertia, as "
         "identified parameter sets give it; the efforts (the torques or forces along the "
         "axes) of the joints carrying link '" +
         link +
         "' are the identified model's, but those joints' full 3-D force and moment are not "
         "physical";
}

// A link's inertia must be that of some mass distribution: symmetric positive
// semi-definite, and its principal moments must satisfy the triangle inequality.
// Violations of the triangle inequality up to `triangle_tolerance` (relative to the
// largest principal moment) are accepted with a warning: published models have them
// (Talos' gripper motors by 2.5%), and the method solves them all the same. With
// `options.accept_nonphysical_inertia` any violation is a warning (identified models).
void checkInertia(const LinkDesc& link, const ModelOptions& options,
                  std::vector<std::string>& warnings) {
  const std::string what = "link '" + link.name + "'";
  const auto refuse = [&](const std::string& violation) {
    if (!options.accept_nonphysical_inertia) fail(violation);
    warnings.push_back(violation + nonphysicalNote(link.name));
  };
  if (link.mass < 0.0) fail(what + ": negative mass " + std::to_string(link.mass));
  if (link.mass == 0.0 && !link.inertia.isZero(0.0)) {
    // Taken as given (its moments enter the loads), but no body turns without weight: a
    // CAD export's placeholder, or a mass left out.
    std::ostringstream os;
    os << what << ": mass 0 with a nonzero inertia (ixx " << link.inertia(0, 0) << ", iyy "
       << link.inertia(1, 1) << ", izz " << link.inertia(2, 2)
       << " kg m^2): taken as given; give the link its mass, or zero its inertia";
    warnings.push_back(os.str());
  }
  Eigen::SelfAdjointEigenSolver<Matrix3> eig(link.inertia, Eigen::EigenvaluesOnly);
  const Vector3 l = eig.eigenvalues();  // ascending
  // Relative tolerance: the URDFs we read print their inertias with 6 to 9 digits.
  const double tol = 1e-6 * std::max(l.cwiseAbs().maxCoeff(), 1e-300);
  if (l[0] < -tol) {
    std::ostringstream os;
    os << what << ": inertia is not positive semi-definite (principal moments " << l[0] << ", "
       << l[1] << ", " << l[2] << ")";
    refuse(os.str());
  }
  if (l[0] + l[1] < l[2] - tol) {
    std::ostringstream os;
    os << what << ": inertia violates the triangle inequality (principal moments " << l[0] << " + "
       << l[1] << " < " << l[2] << ", by " << 100.0 * (l[2] - l[0] - l[1]) / l[2] << "%)";
    if (l[0] + l[1] < l[2] * (1.0 - options.triangle_tolerance))
      refuse(os.str());
    else
      warnings.push_back(os.str());
  }
}

struct Builder {
  const std::vector<LinkDesc>& links;
  const std::vector<JointDesc>& joints;
  const ModelOptions& options;
  std::map<std::string, int> link_index;
  Model<double> model;
  // Per segment: the inertials of its links (several where fixed joints merged links),
  // each in the segment frame about its own centre of mass.
  struct Part {
    double mass;
    Vector3 com;
    Matrix3 inertia;
  };
  std::vector<std::vector<Part>> parts;

  int addSegment(int parent, JointType type, const std::string& link, const std::string& joint) {
    model.parent.push_back(parent);
    model.joint_type.push_back(type);
    model.link_name.push_back(link);
    model.joint_name.push_back(joint);
    model.parent_link_name.emplace_back();
    model.R_parent_joint.push_back(Matrix3::Identity());
    model.p_parent_joint.push_back(Vector3::Zero());
    model.R_parentsegment_parentlink.push_back(Matrix3::Identity());
    model.axis.push_back(Vector3::Zero());
    model.coordinate.push_back(-1);
    model.multiplier.push_back(1.0);
    model.offset.push_back(0.0);
    parts.emplace_back();
    model.damping.push_back(0.0);
    model.friction.push_back(0.0);
    model.lower_limit.push_back(-kInf);
    model.upper_limit.push_back(kInf);
    model.velocity_limit.push_back(kInf);
    model.effort_limit.push_back(kInf);
    return static_cast<int>(model.parent.size()) - 1;
  }

  void addLink(int link, int segment, const Pose& X_segment_link) {
    const LinkDesc& l = links[link];
    Frame<double> frame;
    frame.name = l.name;
    frame.segment = segment;
    frame.R_segment_frame = X_segment_link.R;
    frame.p_segment_frame = X_segment_link.p;
    model.frames.push_back(frame);
    if (!l.has_inertial) return;
    checkInertia(l, options, model.warnings);
    const Pose X = X_segment_link * l.inertial_origin;
    parts[segment].push_back({l.mass, X.p, X.R * l.inertia * X.R.transpose()});
  }

  // Mass, centre of mass and inertia about it of a segment's parts. The parallel-axis
  // terms use each part's offset from the common centre of mass, never from the segment
  // origin: a centre of mass D from the origin would otherwise enter as m D^2 added and
  // subtracted again, losing the inertia's digits (with one part the offset is zero and
  // the inertia is the URDF's, rotated).
  static void combine(const std::vector<Part>& parts, double& mass, Vector3& com,
                      Matrix3& inertia) {
    mass = 0.0;
    for (const Part& p : parts) mass += p.mass;
    com.setZero();
    inertia.setZero();
    if (!(mass > 0.0)) return;
    for (const Part& p : parts) com += (p.mass / mass) * p.com;
    for (const Part& p : parts) {
      const Vector3 d = p.com - com;
      inertia += p.inertia + p.mass * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose());
    }
  }

  // Depth first from `link` (already placed on `segment` at X_segment_link), children
  // in document order, with an explicit stack: a URDF thousands of links deep must not
  // exhaust the call stack.
  void visit(int link, int segment, const Pose& X_segment_link) {
    struct Pending {
      int joint;
      int segment;            // segment the joint's parent link lies on
      Pose X_segment_parent;  // the parent link's placement on it
    };
    std::vector<Pending> stack;
    auto place = [&](int l, int seg, const Pose& X) {
      addLink(l, seg, X);
      const std::vector<int>& children = links[l].child_joints;
      for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back({*it, seg, X});
    };
    place(link, segment, X_segment_link);
    while (!stack.empty()) {
      const Pending pending = stack.back();
      stack.pop_back();
      const JointDesc& joint = joints[pending.joint];
      const int child = link_index.at(joint.child);
      const std::string what = "joint '" + joint.name + "'";
      const bool keep =
          std::find(options.keep_fixed_joints.begin(), options.keep_fixed_joints.end(),
                    joint.name) != options.keep_fixed_joints.end();
      const Pose X = pending.X_segment_parent * joint.origin;
      if (joint.type == "fixed" && !keep) {
        place(child, pending.segment, X);
        continue;
      }
      JointType type;
      if (joint.type == "revolute" || joint.type == "continuous")
        type = JointType::kRevolute;
      else if (joint.type == "prismatic")
        type = JointType::kPrismatic;
      else if (joint.type == "fixed")
        type = JointType::kFixed;
      else if (joint.type == "floating")
        fail(what + ": a floating joint must be the only joint of the root link");
      else
        fail(what + ": unsupported joint type '" + joint.type + "'");
      const int s = addSegment(pending.segment, type, joint.child, joint.name);
      model.R_parent_joint[s] = X.R;
      model.p_parent_joint[s] = X.p;
      model.R_parentsegment_parentlink[s] = pending.X_segment_parent.R;
      model.parent_link_name[s] = joint.parent;
      if (isMoving(type)) {
        const double norm = joint.axis.norm();
        if (!(norm > 1e-12)) fail(what + ": axis of zero length");
        model.axis[s] = joint.axis / norm;
        model.damping[s] = joint.damping;
        model.friction[s] = joint.friction;
        model.lower_limit[s] = joint.lower;
        model.upper_limit[s] = joint.upper;
        model.velocity_limit[s] = joint.velocity;
        model.effort_limit[s] = joint.effort;
      }
      place(child, s, Pose());
    }
  }

  void resolveMimics() {
    // Leader of each moving segment: itself, or (through a chain of mimics) another.
    std::map<std::string, int> segment_of;
    std::map<std::string, const JointDesc*> desc;
    for (const JointDesc& j : joints) desc[j.name] = &j;
    for (int s = 1; s < model.nsegments(); ++s) segment_of[model.joint_name[s]] = s;
    for (int s = 1; s < model.nsegments(); ++s) {
      if (!isMoving(model.joint_type[s]) || desc.at(model.joint_name[s])->mimic) continue;
      model.coordinate[s] = model.nq++;
      model.coordinate_names.push_back(model.joint_name[s]);
    }
    for (int s = 1; s < model.nsegments(); ++s) {
      if (!isMoving(model.joint_type[s])) continue;
      double multiplier = 1.0, offset = 0.0;
      std::string name = model.joint_name[s];
      for (int hops = 0; desc.at(name)->mimic; ++hops) {
        const JointDesc* d = desc.at(name);
        if (hops > model.nsegments())
          fail("joint '" + model.joint_name[s] + "': its mimic chain is a loop");
        auto leader = segment_of.find(d->mimic_joint);
        if (leader == segment_of.end() || !isMoving(model.joint_type[leader->second]))
          fail("joint '" + d->name + "' mimics '" + d->mimic_joint +
               "', which is not a moving joint of the model");
        // q = m1 (m2 q_leader + o2) + o1
        offset = multiplier * d->offset + offset;
        multiplier *= d->multiplier;
        name = d->mimic_joint;
      }
      const int leader = segment_of.at(name);
      model.coordinate[s] = model.coordinate[leader];
      model.multiplier[s] = multiplier;
      model.offset[s] = offset;
    }
  }

  void finish() {
    for (int s = 0; s < model.nsegments(); ++s) {
      double m;
      Vector3 c;
      Matrix3 inertia;
      combine(parts[s], m, c, inertia);
      model.mass.push_back(m);
      model.com.push_back(c);
      model.inertia_com.push_back(inertia);
      if (isMoving(model.joint_type[s])) model.moving_segments.push_back(s);
    }
    if (!(model.totalMass() > 0.0))
      fail("robot: total mass is zero; no link has an <inertial> with a positive mass");
    model.analyze();
  }
};

// The links and joints of a <robot>, each name once, linked into a tree (parent_joint,
// child_joints).
struct Description {
  std::vector<LinkDesc> links;
  std::vector<JointDesc> joints;
  std::map<std::string, int> link_index, joint_index;
};

// Every <tag> child of `robot`, parsed, into `out`; its name into `index`.
template <typename Desc, typename Parse>
void parseElements(const tinyxml2::XMLElement* robot, const char* tag, Parse parse,
                   std::vector<Desc>& out, std::map<std::string, int>& index) {
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement(tag); e;
       e = e->NextSiblingElement(tag)) {
    out.push_back(parse(e));
    if (!index.emplace(out.back().name, static_cast<int>(out.size()) - 1).second)
      fail(std::string(tag) + " '" + out.back().name + "' is defined twice" + where(e));
  }
}

// Each joint's links: known, and every link the child of one joint at most.
void linkJoints(Description& d) {
  for (int j = 0; j < static_cast<int>(d.joints.size()); ++j) {
    const JointDesc& joint = d.joints[j];
    for (const std::string* l : {&joint.parent, &joint.child})
      if (!d.link_index.count(*l))
        fail("joint '" + joint.name + "': unknown link '" + *l + "' (line " +
             std::to_string(joint.line) + ")");
    LinkDesc& child = d.links[d.link_index[joint.child]];
    if (child.parent_joint >= 0)
      fail("link '" + child.name + "' is the child of two joints, '" +
           d.joints[child.parent_joint].name + "' and '" + joint.name + "' (a loop)");
    child.parent_joint = j;
    d.links[d.link_index[joint.parent]].child_joints.push_back(j);
  }
}

Description parseRobot(const std::string& xml, const ModelOptions& options) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS)
    fail(std::string("malformed XML: ") + doc.ErrorStr());
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) fail("no <robot> element");
  Description d;
  parseElements(robot, "link", parseLink, d.links, d.link_index);
  parseElements(robot, "joint", parseJoint, d.joints, d.joint_index);
  if (d.links.empty()) fail("robot has no <link>");
  for (const std::string& name : options.keep_fixed_joints) {
    auto it = d.joint_index.find(name);
    if (it == d.joint_index.end()) fail("keep_fixed_joints: unknown joint '" + name + "'");
    if (d.joints[it->second].type != "fixed")
      fail("keep_fixed_joints: joint '" + name + "' is not fixed");
  }
  linkJoints(d);
  return d;
}

// The one link without a parent joint.
int rootLink(const Description& d) {
  std::vector<int> roots;
  for (int l = 0; l < static_cast<int>(d.links.size()); ++l)
    if (d.links[l].parent_joint < 0) roots.push_back(l);
  if (roots.empty()) fail("no root link: every link has a parent joint (a loop)");
  if (roots.size() > 1) {
    std::string names;
    for (int r : roots) names += (names.empty() ? "'" : ", '") + d.links[r].name + "'";
    fail("several root links: " + names + "; a URDF is a single tree");
  }
  return roots[0];
}

// Segment 0 and the tree below it. A root whose only joint floats (world --floating-->
// base) is left out: the base link is segment 0 and its pose is an input. Returns
// whether the root was left out so.
bool buildTree(Builder& b, const Description& d, int root) {
  const LinkDesc& root_link = d.links[root];
  const bool root_floats =
      root_link.child_joints.size() == 1 && d.joints[root_link.child_joints[0]].type == "floating";
  if (root_floats) {
    const JointDesc& j = d.joints[root_link.child_joints[0]];
    if (root_link.has_inertial && root_link.mass != 0.0)
      fail("link '" + root_link.name + "': the parent of floating joint '" + j.name +
           "' must be massless");
    b.model.floating_base = true;
    b.addSegment(-1, JointType::kFloating, j.child, "");
    b.visit(d.link_index.at(j.child), 0, Pose());
  } else {
    b.model.floating_base = b.options.floating_base;
    b.addSegment(-1, b.options.floating_base ? JointType::kFloating : JointType::kRoot,
                 root_link.name, "");
    b.visit(root, 0, Pose());
  }
  return root_floats;
}

// Every link placed (the tree from the root reaches them all).
void checkReached(const Builder& b, const Description& d, int root, bool root_left_out) {
  const std::size_t reached = b.model.frames.size() + (root_left_out ? 1 : 0);
  if (reached == d.links.size()) return;
  const LinkDesc& root_link = d.links[root];
  std::string names;
  for (const LinkDesc& l : d.links) {
    bool seen = root_left_out && l.name == root_link.name;
    for (const Frame<double>& f : b.model.frames) seen = seen || f.name == l.name;
    if (!seen) names += (names.empty() ? "'" : ", '") + l.name + "'";
  }
  fail("links " + names + " are not reachable from the root '" + root_link.name + "' (a loop)");
}

}  // namespace

Model<double> modelFromUrdfString(const std::string& xml, const ModelOptions& options) {
  const Description d = parseRobot(xml, options);
  const int root = rootLink(d);
  Builder b{d.links, d.joints, options, d.link_index, {}, {}};
  const bool root_left_out = buildTree(b, d, root);
  checkReached(b, d, root, root_left_out);
  b.resolveMimics();
  b.finish();
  return b.model;
}

Model<double> modelFromUrdfFile(const std::string& path, const ModelOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ModelError(path + ": cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  try {
    return modelFromUrdfString(text.str(), options);
  } catch (const ModelError& e) {
    throw ModelError(path + ": " + e.what());
  }
}

}  // namespace jle
