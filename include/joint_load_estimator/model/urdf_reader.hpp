// Builds a Model from a URDF (a file, or the string that robot_description holds).
#pragma once

#include <joint_load_estimator/model/model.hpp>

#include <stdexcept>
#include <string>
#include <vector>

namespace jle {

/// A URDF the method cannot use; the message names the link, joint or element at fault.
class ModelError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// How a URDF becomes a Model.
struct ModelOptions {
  /// Treat the URDF root link as a floating base (its pose, twist and acceleration are
  /// inputs). A URDF whose root holds a single `floating` joint floats in any case.
  bool floating_base = false;
  /// Fixed joints kept as segments of their own instead of being lumped into their
  /// parent, so that the wrench across them is an output (a force/torque sensor mount,
  /// a tool flange). Unknown or non-fixed names are an error.
  std::vector<std::string> keep_fixed_joints;
  /// A link inertia whose principal moments violate the triangle inequality by less
  /// than this fraction of the largest is accepted and reported in Model::warnings;
  /// a larger violation is refused.
  double triangle_tolerance = 0.05;
  /// Accept a link inertia that no rigid body has (not positive semi-definite, or
  /// principal moments breaking the triangle inequality beyond triangle_tolerance), as
  /// dynamic identification gives them in moments the joint torques do not depend on.
  /// Each such link is reported in Model::warnings, naming the violation and what it
  /// can and cannot affect (the efforts about the joint axes are the identified model's;
  /// the joints' full 3-D force and moment are not physical). false: refused. The one
  /// default of the setting (Settings::accept_nonphysical_inertia, the tools' flags).
  bool accept_nonphysical_inertia = false;
};

/// Parses a URDF document. Throws ModelError with the culprit's name on any defect:
/// malformed XML, a missing or non-numeric attribute, unknown links, a loop, several
/// roots, an axis of zero length, a negative mass, an inertia that is not positive
/// semi-definite or violates the triangle inequality, a zero total mass, an unsupported
/// joint type (planar), a mimic of an unknown or non-moving joint.
Model<double> modelFromUrdfString(const std::string& xml, const ModelOptions& options = {});

/// Reads and parses a URDF file; the file name is part of every error message.
Model<double> modelFromUrdfFile(const std::string& path, const ModelOptions& options = {});

}  // namespace jle
