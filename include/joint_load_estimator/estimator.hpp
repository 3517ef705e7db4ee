// The online estimator shared by the node, process_bag and the benchmarks: joint
// samples in, filtered kinematics, resampled and equally filtered wrenches, joint loads
// out. ROS-free.
#pragma once

#include <joint_load_estimator/data.hpp>
#include <joint_load_estimator/differentiation.hpp>
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/model.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace jle {

/// What to do with a wrench input that has not been heard from for longer than its
/// timeout.
enum class StalePolicy : std::uint8_t {
  kHold,  ///< keep using its last value
  kZero,  ///< take it as zero (the contact has ended)
  kStop,  ///< publish no loads while it is stale
};

/// One measured wrench acting on the robot.
struct WrenchInputConfig {
  std::string name;  ///< for messages (the topic)
  std::string link;  ///< URDF link the wrench acts on; samples are given in its frame
  double sign = 1.0;  ///< +1: the load on the robot (F/T sensor); -1: the load the robot applies (force plate)
  double timeout = 0.1;  ///< [s] older than this at a joint sample = stale
  StalePolicy stale_policy = StalePolicy::kHold;
};

struct EstimatorConfig {
  DifferentiatorConfig differentiator;
  Eigen::Vector3d gravity_world{0.0, 0.0, -9.80665};  ///< [m/s^2]
  std::vector<WrenchInputConfig> wrenches;
  /// Loads are computed for every n-th joint sample (the filters see every sample).
  int decimation = 1;
};

/// What became of a joint sample.
enum class SampleStatus : std::uint8_t {
  kPublished,   ///< loads computed for stamp()
  kWarmingUp,   ///< the filters need more samples
  kDecimated,   ///< filtered, no loads computed for it
  kDuplicate,   ///< same stamp as the previous sample: dropped
  kOutOfOrder,  ///< older than the previous sample: dropped
  kNonFinite,   ///< a NaN or infinite value: dropped
  kStale,       ///< a wrench input with the kStop policy is stale: no loads
};

const char* toString(SampleStatus status);

/// Pose of a floating base at a sample (world frame).
struct BasePose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

class Estimator {
 public:
  /// Throws std::invalid_argument naming the bad field or link.
  Estimator(const Model<double>& model, const EstimatorConfig& config);

  const Model<double>& model() const { return model_; }
  const EstimatorConfig& config() const { return config_; }

  /// A sample of wrench input k at time t [s]: force [N] and moment [N m] about the
  /// origin of the input's link, in that link's frame, as the sensor reports it (the
  /// sign is applied here). Samples older than the newest held are dropped (false).
  bool addWrench(int k, double t, const Eigen::Vector3d& force, const Eigen::Vector3d& moment);

  /// A joint sample at time t [s]: q has model().nq entries (model().coordinate_names
  /// order); base is required for a floating-base model. When the result is
  /// kPublished, stamp() and data() hold the loads.
  SampleStatus addJointSample(double t, const double* q, const BasePose* base = nullptr);

  /// Forgets all history (a backward jump of time).
  void reset();

  /// Time the last published loads describe [s] (the newest joint sample minus the
  /// filter's delay).
  double stamp() const { return stamp_; }
  /// Kinematics and loads of the last published sample (dynamics.hpp conventions).
  const Data<double>& data() const { return data_; }
  /// The estimated coordinates of the last published sample.
  const VectorX<double>& q() const { return q_; }
  const VectorX<double>& qd() const { return qd_; }
  const VectorX<double>& qdd() const { return qdd_; }
  /// Whether wrench input k was stale at the last joint sample.
  bool stale(int k) const { return inputs_[k].stale; }
  /// The filtered wrench of input k applied at the last published sample (sign
  /// applied, link frame).
  Wrench<double> appliedWrench(int k) const;
  /// Nominal delay of the estimate behind the newest sample, in samples.
  int delaySamples() const { return bank_.config().delay; }

 private:
  struct Input {
    WrenchInputConfig config;
    int frame = 0;
    // Ring of the latest samples: time and the 6 components (force, moment).
    std::vector<double> times;
    std::vector<Eigen::Matrix<double, 6, 1>> values;
    int head = 0;
    int count = 0;
    bool stale = true;
  };
  // Value of input k at time t (linear between samples, held past the newest).
  Eigen::Matrix<double, 6, 1> sampleInput(Input& input, double t);

  Model<double> model_;
  EstimatorConfig config_;
  Data<double> data_;
  DifferentiatorBank bank_;
  std::vector<Input> inputs_;
  std::vector<double> channels_;  // q (nq), base (7), wrenches (6 per input)
  int base_channel_ = 0;
  int wrench_channel_ = 0;
  VectorX<double> q_, qd_, qdd_;
  Eigen::Quaterniond last_orientation_ = Eigen::Quaterniond::Identity();
  double last_t_ = 0.0;
  bool have_last_ = false;
  long sample_count_ = 0;
  double stamp_ = 0.0;
};

}  // namespace jle
