// The node's parameters: one parser for the parameter server (the node) and for a
// YAML file (process_bag), both seen as an XmlRpc struct, with errors naming the key.
#pragma once

#include <joint_load_estimator/estimator.hpp>

#include <xmlrpcpp/XmlRpcValue.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace jle {

/// A parameter that is missing where required, of the wrong type or out of range.
class SettingsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One measured wrench topic as configured (the estimator's WrenchInputConfig plus
/// where the message comes from and which frame it is expressed in).
struct WrenchTopicSettings {
  WrenchInputConfig input;
  std::string topic;
  std::string frame;  ///< expressed-in frame; empty: the message's header.frame_id
  /// Sensor inputs (input.sensor_joint set): the residual (measured - predicted) above
  /// either threshold is a diagnostic warning.
  double force_threshold = 5.0;   ///< [N]
  double moment_threshold = 0.5;  ///< [N m]
};

/// One force plate as configured (force_plates[i]).
struct PlateTopicSettings {
  PlateInputConfig input;  ///< input.plate.name, .link, surface_height, contact_threshold, pose
  std::string topic;
  std::string frame;           ///< tf2 frame of the plate; empty: the message's header.frame_id
  bool pose_configured = false;  ///< position/orientation given: no tf2 look-up
};

struct NodeSettings {
  std::string robot_description = "robot_description";  ///< parameter holding the URDF
  std::string joint_states_topic = "joint_states";
  std::vector<std::string> joints;  ///< joints to publish; empty: every moving joint
  bool publish_wrench_topics = true;  ///< advertise ~wrench/<joint>
  bool floating_base = false;
  std::string world_frame = "world";  ///< tf2 frame of the world (floating base)
  std::string base_frame;             ///< tf2 frame of the base; empty: the URDF root link
  double time_jump_threshold = 1.0;   ///< [s] a stamp older than this is a jump back: reset
  std::vector<WrenchTopicSettings> wrenches;
  std::vector<std::string> keep_fixed_joints;  ///< sensor joints are added by the parser
  /// Floating base: a residual force above this fraction of the total weight is a
  /// diagnostic warning.
  double base_residual_threshold = 0.1;
  /// ~calibrate_bias: the robot is still while every estimated |q-dot| stays below this.
  double still_velocity = 0.02;  ///< [rad/s or m/s]
  /// YAML file of the sensor biases: loaded at start if it exists, written by
  /// ~calibrate_bias. Empty: not loaded, and calibrate_bias writes none.
  std::string bias_file;
  EstimatorConfig estimator;
  std::vector<PlateTopicSettings> force_plates;  ///< also in estimator.plates
  /// [kg] effort_per_kg = effort / body_mass; 0: not published; -1: the URDF's total mass.
  double body_mass = 0.0;
};

/// The node's differentiator when the parameters name none (see docs/accuracy.md).
DifferentiatorConfig nodeDefaultDifferentiator();

/// Parses the struct `params` (a node's private namespace, or a YAML file's root).
/// Unknown keys are an error too: a misspelt key silently ignored is a bug report later.
NodeSettings parseSettings(const XmlRpc::XmlRpcValue& params);

/// Loads a YAML file into an XmlRpc struct (process_bag; the node gets the same file
/// through rosparam). Throws SettingsError naming the file.
XmlRpc::XmlRpcValue loadYaml(const std::string& path);

}  // namespace jle
