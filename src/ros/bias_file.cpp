#include <joint_load_estimator/ros/bias_file.hpp>
#include <joint_load_estimator/ros/settings.hpp>

#include <ros/console.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace jle {
namespace {

Eigen::Vector3d readVector(const YAML::Node& node, const std::string& where) {
  if (!node || !node.IsSequence() || node.size() != 3)
    throw SettingsError(where + " must be a list of 3 numbers");
  Eigen::Vector3d v;
  try {
    for (std::size_t i = 0; i < 3; ++i) v[static_cast<int>(i)] = node[i].as<double>();
  } catch (const YAML::Exception&) {
    throw SettingsError(where + " must be a list of 3 numbers");
  }
  if (!v.allFinite()) throw SettingsError(where + " is not finite");
  return v;
}

YAML::Node loadSensors(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw SettingsError("bias_file '" + path + "': " + e.what());
  }
  const YAML::Node sensors = root["sensors"];
  if (!sensors || !sensors.IsMap())
    throw SettingsError("bias_file '" + path + "': 'sensors' must be a map");
  return sensors;
}

std::string formatVector(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out << std::setprecision(17) << "[" << v[0] << ", " << v[1] << ", " << v[2] << "]";
  return out.str();
}

}  // namespace

std::vector<SensorBias> loadBiasFile(const std::string& path,
                                     const std::vector<BiasFileSensor>& sensors) {
  std::vector<SensorBias> biases(sensors.size());
  if (path.empty()) return biases;
  if (!std::ifstream(path).good()) {
    ROS_INFO("bias_file '%s' does not exist (yet): sensor biases are zero", path.c_str());
    return biases;
  }
  for (const auto& entry : loadSensors(path)) {
    const std::string name = entry.first.as<std::string>();
    std::size_t k = sensors.size();
    for (std::size_t i = 0; i < sensors.size(); ++i)
      if (sensors[i].joint == name) k = i;
    if (k == sensors.size()) {
      ROS_WARN("bias_file '%s': sensor '%s' is not configured: ignored", path.c_str(),
               name.c_str());
      continue;
    }
    const std::string where = "bias_file '" + path + "': sensors/" + name;
    SensorBias& bias = biases[k];
    bias.force = readVector(entry.second["force"], where + "/force");
    bias.torque = readVector(entry.second["torque"], where + "/torque");
    const std::string frame = entry.second["frame"] ? entry.second["frame"].as<std::string>() : "";
    const std::string& configured = sensors[k].frame;
    if (!configured.empty() && !frame.empty() && frame != configured)
      ROS_WARN("%s: calibrated in frame '%s', configured frame is '%s'", where.c_str(),
               frame.c_str(), configured.c_str());
    ROS_INFO("sensor '%s': bias force [%g %g %g] N, torque [%g %g %g] N m from '%s'", name.c_str(),
             bias.force.x(), bias.force.y(), bias.force.z(), bias.torque.x(), bias.torque.y(),
             bias.torque.z(), path.c_str());
  }
  return biases;
}

std::string saveBiasFile(const std::string& path, const std::vector<BiasFileEntry>& entries,
                         long samples) {
  std::ostringstream out;
  out << "# Force/torque sensor offsets written by joint_load_estimator "
         "~calibrate_bias:\n"
         "# the reading minus the model's prediction, averaged while the robot "
         "was still, in\n"
         "# the sensor's frame and sign convention (moment about the frame's "
         "origin). The\n"
         "# node subtracts them from the readings when started with bias_file "
         "= this file.\n"
         "sensors:\n";
  for (const BiasFileEntry& e : entries)
    out << "  " << e.joint << ":\n"
        << "    frame: \"" << e.frame << "\"\n"
        << "    force: " << formatVector(e.bias.force) << "          # [N]\n"
        << "    torque: " << formatVector(e.bias.torque) << "         # [N m]\n"
        << "    force_stddev: " << formatVector(e.stddev.force) << "   # [N] per-sample spread\n"
        << "    torque_stddev: " << formatVector(e.stddev.torque) << "  # [N m]\n"
        << "    samples: " << samples << "\n";
  // Written beside the target and renamed: a reader never sees half a file.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream file(tmp);
    if (!(file << out.str()) || !file.flush()) return "cannot write '" + tmp + "'";
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    return "cannot rename '" + tmp + "' to '" + path + "'";
  return "";
}

void applyBiasFile(Pipeline& pipeline) {
  const Settings& settings = pipeline.settings();
  std::vector<BiasFileSensor> sensors;
  std::vector<int> inputs;
  for (std::size_t k = 0; k < settings.estimator.wrenches.size(); ++k) {
    if (settings.estimator.wrenches[k].sensor_joint.empty()) continue;
    sensors.push_back({settings.estimator.wrenches[k].sensor_joint, settings.wrenches[k].frame});
    inputs.push_back(static_cast<int>(k));
  }
  if (sensors.empty()) return;
  const std::vector<SensorBias> biases = loadBiasFile(settings.bias_file, sensors);
  for (std::size_t i = 0; i < inputs.size(); ++i)
    pipeline.setSensorBias(inputs[i], biases[i].force, biases[i].torque);
}

}  // namespace jle
