// The ROS side of the settings reader (settings_reader.hpp, ROS-free): the parameter
// server's values, an XmlRpc struct, as a parameter tree.
#pragma once

#include <joint_load_estimator/settings/config.hpp>
#include <joint_load_estimator/settings/settings_reader.hpp>

#include <xmlrpcpp/XmlRpcValue.h>

#include <string>

namespace jle {

/// The XmlRpc value `value` (a node's private namespace) as a parameter tree; a type
/// XmlRpc has and the tree has not (a date, binary data) throws SettingsError.
ParamValue fromXmlRpc(const XmlRpc::XmlRpcValue& value);

/// parseSettings(fromXmlRpc(params)).
Settings parseSettings(const XmlRpc::XmlRpcValue& params);

/// Whether ~robot_description holds the URDF itself (robot_state_publisher's habit:
/// `_robot_description:="$(cat robot.urdf)"`, a <param textfile=...> in the node) rather
/// than the name of the parameter that holds it: a name has no '<'.
inline bool isUrdfText(const std::string& robot_description) {
  return robot_description.find('<') != std::string::npos;
}

}  // namespace jle
