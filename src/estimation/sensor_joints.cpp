#include <joint_load_estimator/estimation/sensor_joints.hpp>

#include <joint_load_estimator/estimation/estimator.hpp>  // WrenchInputConfig

#include <stdexcept>
#include <string>

namespace jle {

SensorJoints::SensorJoints(int segments)
    : sensor_of_segment_(static_cast<std::size_t>(segments), -1) {}

int SensorJoints::add(const Model<double>& model, const WrenchInputConfig& config, int channel) {
  Input input;
  input.channel = channel;
  if (!config.sensor_joint.empty()) {
    const std::string what =
        "wrench input '" + config.name + "': sensor_joint '" + config.sensor_joint + "'";
    int s = -1;
    try {
      s = model.segmentOfJoint(config.sensor_joint);
    } catch (const std::invalid_argument&) {
      throw std::invalid_argument(what + " is not a joint kept as a segment (keep_fixed_joints)");
    }
    if (model.joint_type[s] != JointType::kFixed)
      throw std::invalid_argument(what + " is not a fixed joint");
    if (!config.link.empty() && config.link != model.link_name[s])
      throw std::invalid_argument(what + ": link must be its child link '" + model.link_name[s] +
                                  "', not '" + config.link + "'");
    if (sensor_of_segment_[s] >= 0) throw std::invalid_argument(what + " has two sensor inputs");
    input.segment = s;
    input.frame = model.frameIndex(model.link_name[s]);
    sensor_of_segment_[s] = static_cast<int>(inputs_.size());
    any_ = true;
  }
  inputs_.push_back(input);
  return input.segment;
}

Wrench<double> SensorJoints::residual(int k, const Data<double>& data) const {
  const Input& input = inputs_.at(static_cast<std::size_t>(k));
  Wrench<double> r;
  if (input.segment < 0 || !input.used) return r;
  r.force = data.force[input.segment] - input.predicted.force;
  r.moment = data.moment[input.segment] - input.predicted.moment;
  return r;
}

}  // namespace jle
