// Force/torque sensors at fixed joints (WrenchInputConfig::sensor_joint): the joint
// wrench the model predicts, the measurement substituted for it in the backward pass,
// and their difference. ROS-free.
#pragma once

#include <joint_load_estimator/estimation/input_buffer.hpp>
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <vector>

namespace jle {

struct WrenchInputConfig;  // config.hpp

/// The sensor joints among the wrench inputs of one estimator, indexed like the inputs
/// (an applied wrench has no segment). A sensor measures what its joint's parent link
/// exerts on its child link (child link frame, moment about the joint origin); its input
/// is filtered in six bank channels like any input's.
class SensorJoints {
 public:
  SensorJoints() = default;
  /// For a model with `segments` segments.
  explicit SensorJoints(int segments);

  /// Input `config`, the next one, filtered in channels channel..channel+5. Returns the
  /// segment of its sensor joint, -1 for an applied wrench. Throws std::invalid_argument
  /// naming the input unless the joint is fixed, kept as a segment
  /// (keep_fixed_joints), has no other sensor, and `link` is empty or its child link.
  int add(const Model<double>& model, const WrenchInputConfig& config, int channel);

  /// Whether any input is a sensor.
  bool any() const { return any_; }
  /// Segment of input k's sensor joint, -1 for an applied wrench.
  int segment(int k) const { return inputs_[static_cast<std::size_t>(k)].segment; }
  /// Before a backward pass: whether sensor k's measurement replaces the prediction (not
  /// while it reads as zero, stale under kZero: that would claim the distal side weighs
  /// nothing).
  void setUsed(int k, bool used) { inputs_[static_cast<std::size_t>(k)].used = used; }
  /// The backward pass hook at `segment`: for a sensor's segment, keeps the predicted
  /// joint wrench and substitutes the filtered measurement (when used).
  template <typename Scalar>
  void atSegment(Data<Scalar>& data, const Model<Scalar>& model, int segment,
                 const DifferentiatorBank& bank);

  /// Sensor k's joint wrench according to the model at the last backward pass (child
  /// link frame, moment about the joint origin [N, N m]), and whether the measurement
  /// replaced it.
  const Wrench<double>& predicted(int k) const {
    return inputs_[static_cast<std::size_t>(k)].predicted;
  }
  bool used(int k) const { return inputs_[static_cast<std::size_t>(k)].used; }
  /// Measured minus predicted for sensor k, with `data` the result of the backward pass
  /// (same frame and point); zero for an applied wrench or an unused sensor.
  Wrench<double> residual(int k, const Data<double>& data) const;

 private:
  struct Input {
    int segment = -1;
    int frame = 0;    // the child link's frame
    int channel = 0;  // the first of its six bank channels
    Wrench<double> predicted;
    bool used = false;
  };
  std::vector<Input> inputs_;
  std::vector<int> sensor_of_segment_;  // per segment: the input index, or -1
  bool any_ = false;
};

template <typename Scalar>
void SensorJoints::atSegment(Data<Scalar>& data, const Model<Scalar>& model, int segment,
                             const DifferentiatorBank& bank) {
  const int k = sensor_of_segment_[static_cast<std::size_t>(segment)];
  if (k < 0) return;
  Input& input = inputs_[static_cast<std::size_t>(k)];
  input.predicted.force = data.force[segment].template cast<double>();
  input.predicted.moment = data.moment[segment].template cast<double>();
  if (!input.used) return;
  // The filtered measurement, from the child link frame (identity for the segment's own
  // link, kept general) to the segment frame about the joint origin.
  const Wrench<double> w = filteredWrench(bank, input.channel);
  const Frame<Scalar>& fr = model.frames[static_cast<std::size_t>(input.frame)];
  const Eigen::Matrix<Scalar, 3, 1> f = fr.R_segment_frame * w.force.template cast<Scalar>();
  data.force[segment] = f;
  data.moment[segment] =
      fr.R_segment_frame * w.moment.template cast<Scalar>() + fr.p_segment_frame.cross(f);
}

}  // namespace jle
