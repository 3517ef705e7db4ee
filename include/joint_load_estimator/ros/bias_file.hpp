// The bias file (bias_file): every force/torque sensor's offset as ~calibrate_bias
// stores it, read back by the node (and by the offline tools) to subtract it from the
// readings. YAML:
//   sensors:
//     <sensor_joint>: {frame: "...", force: [x, y, z], torque: [x, y, z],
//                      force_stddev: [...], torque_stddev: [...], samples: N}
// in the sensor's frame and sign convention, moment about the frame's origin.
#pragma once

#include <joint_load_estimator/estimation/sensor_bias.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <string>
#include <vector>

namespace jle {

/// One configured sensor, as the bias file is matched against it.
struct BiasFileSensor {
  std::string joint;  ///< sensor_joint: the key under 'sensors'
  std::string frame;  ///< the configured frame of its readings ("" : the messages')
};

/// The biases that the file at `path` holds for `sensors`, one per sensor in their order
/// (zero for a sensor the file does not name). An empty `path`, or one that does not
/// exist yet, gives zeros (logged). A sensor in the file that is not configured is
/// ignored with a warning, as is a calibration frame that differs from the configured
/// one. Throws SettingsError naming the file and the key when the file is not YAML,
/// 'sensors' is not a map, or a force or torque is not a list of 3 finite numbers.
std::vector<SensorBias> loadBiasFile(const std::string& path,
                                     const std::vector<BiasFileSensor>& sensors);

/// Loads the pipeline's settings().bias_file (as loadBiasFile) and hands every sensor
/// input its bias: the node at start-up and process_bag do the same.
void applyBiasFile(Pipeline& pipeline);

/// One sensor's entry of the bias file, as ~calibrate_bias estimated it.
struct BiasFileEntry {
  std::string joint;  ///< sensor_joint
  std::string frame;  ///< frame of the readings the bias was estimated in
  SensorBias bias;    ///< the mean offset [N, N m]
  SensorBias stddev;  ///< per-sample standard deviation of the offset [N, N m]
};

/// Writes `entries`, estimated from `samples` samples, to `path` (written beside it and
/// renamed: a reader never sees half a file). Returns "" on success, else what failed.
std::string saveBiasFile(const std::string& path, const std::vector<BiasFileEntry>& entries,
                         long samples);

}  // namespace jle
