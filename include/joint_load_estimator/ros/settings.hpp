// The parameter reader: one for the parameter server (the node) and for a YAML file
// (process_bag), both seen as an XmlRpc struct. It maps the keys onto jle::Settings
// (config.hpp, which holds every default and the one validation) and calls validate();
// errors name the key.
#pragma once

#include <joint_load_estimator/config.hpp>

#include <xmlrpcpp/XmlRpcValue.h>

#include <string>

namespace jle {

/// Parses the struct `params` (a node's private namespace, or a YAML file's root): a key
/// absent keeps its default of Settings{}. Unknown keys are an error too: a misspelt key
/// silently ignored is a bug report later. Throws SettingsError naming the key (a wrong
/// type, an unknown key or name, or a value validate() refuses).
Settings parseSettings(const XmlRpc::XmlRpcValue& params);

/// Loads a YAML file into an XmlRpc struct (process_bag; the node gets the same file
/// through rosparam). Throws SettingsError naming the file.
XmlRpc::XmlRpcValue loadYaml(const std::string& path);

}  // namespace jle
