// The settings reader, ROS-free: a tree of parameters (a YAML file, or the ROS parameter
// server's values converted by the ROS layer) mapped onto jle::Settings (config.hpp, which
// holds every default and the one validation). The node, process_bag, joint_loads, the
// soaks and Python read their settings through it; errors name the key.
#pragma once

#include <joint_load_estimator/settings/config.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace jle {

/// One value of a parameter tree: nothing, a boolean, an integer, a number, a string, a
/// list or a map (keys in the order given).
class ParamValue {
 public:
  enum class Type : std::uint8_t { kNone, kBool, kInt, kDouble, kString, kList, kMap };

  ParamValue() = default;
  explicit ParamValue(bool value) : type_(Type::kBool), bool_(value) {}
  explicit ParamValue(int value) : type_(Type::kInt), int_(value) {}
  explicit ParamValue(double value) : type_(Type::kDouble), double_(value) {}
  explicit ParamValue(std::string value) : type_(Type::kString), string_(std::move(value)) {}
  explicit ParamValue(const char* value) : ParamValue(std::string(value)) {}
  static ParamValue list() { return ParamValue(Type::kList); }
  static ParamValue map() { return ParamValue(Type::kMap); }

  Type type() const { return type_; }
  /// "a boolean", "an integer", "a number", "a string", "a list", "a map", "nothing".
  const char* typeName() const;
  /// The value; std::logic_error if it is of another type.
  bool asBool() const;
  int asInt() const;
  double asDouble() const;  // an integer too
  const std::string& asString() const;

  /// A list's size, a map's number of keys; 0 otherwise.
  std::size_t size() const { return values_.size(); }
  /// Element i of a list, or the value of a map's i-th key.
  const ParamValue& operator[](std::size_t i) const { return values_.at(i); }
  /// Appends to a list (a value of kNone becomes an empty list first).
  void push(ParamValue value);

  /// A map's key i.
  const std::string& key(std::size_t i) const { return keys_.at(i); }
  bool has(const std::string& key) const;
  /// The value of `key` of a map; std::out_of_range if absent.
  const ParamValue& at(const std::string& key) const;
  /// Sets `key` of a map (a value of kNone becomes an empty map first), replacing it.
  void set(const std::string& key, ParamValue value);

 private:
  explicit ParamValue(Type type) : type_(type) {}
  void need(Type type) const;

  Type type_ = Type::kNone;
  bool bool_ = false;
  int int_ = 0;
  double double_ = 0.0;
  std::string string_;
  std::vector<std::string> keys_;   // a map's, in order
  std::vector<ParamValue> values_;  // a list's elements, or a map's values
};

/// Parses the map `params` (a node's private namespace, or a YAML file's root): a key
/// absent keeps its default of Settings{}. Unknown keys are an error too: a misspelt key
/// silently ignored is a bug report later. Throws SettingsError naming the key (a wrong
/// type, an unknown key or name, or a value validate() refuses).
Settings parseSettings(const ParamValue& params);

/// A YAML document (text) or file (path) as a parameter tree, its scalars typed as
/// rosparam types them (true/false, integers, numbers, else strings; a quoted scalar is a
/// string). Throws SettingsError naming the file or saying what is wrong.
ParamValue parseYaml(const std::string& text);
ParamValue loadYaml(const std::string& path);

/// The names of the settings' choices, as config/default.yaml, the reader and
/// ~reconfigure (cfg/Estimator.cfg, checked against these by test_settings) spell them:
/// the one table of each.
template <typename Enum>
struct Named {
  const char* name;
  Enum value;
};
extern const std::array<Named<DifferentiatorType>, 4> kDifferentiatorTypes;
extern const std::array<Named<KalmanModel>, 2> kKalmanModels;
extern const std::array<Named<StalePolicy>, 3> kStalePolicies;
/// The name of `value` in `table`.
template <typename Enum, std::size_t N>
const char* nameOf(const std::array<Named<Enum>, N>& table, Enum value) {
  for (const Named<Enum>& n : table)
    if (n.value == value) return n.name;
  return "?";
}

}  // namespace jle
