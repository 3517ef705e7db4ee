// The online estimator shared by the node, process_bag and the benchmarks: joint
// samples in, filtered kinematics, resampled and equally filtered wrenches, joint loads
// out. ROS-free.
#pragma once

#include <joint_load_estimator/data.hpp>
#include <joint_load_estimator/differentiation.hpp>
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/model.hpp>
#include <joint_load_estimator/planar.hpp>

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

/// Arithmetic of the dynamics (the filters always run in double).
enum class Precision : std::uint8_t { kDouble, kFloat };

/// savings.planar: whether to solve the planar 3x3 system (planar.hpp).
enum class PlanarMode : std::uint8_t {
  kAuto,  ///< when the model is detected planar (exact: within 1e-12 relative of 6x6)
  kOn,    ///< always: the user asserts planarity, out-of-plane parts are dropped
  kOff,   ///< never
};

/// Work the estimator skips when a scene does not need it. Each switch exists for
/// measurement; the exact ones are on by default.
struct Savings {
  /// Compute only the segments distal to the published joints, and the kinematics
  /// they depend on.
  bool prune = true;
  /// A chain of massless, unloaded segments passes its distal wrench on unchanged.
  bool massless_chains = true;
  /// Skip the gyroscopic term where omega lies along a principal axis of inertia.
  bool gyroscopic = true;
  /// Joint velocities and accelerations whose magnitudes are all below these
  /// thresholds are taken as zero (quasi-static scene). 0 = off (the default: not exact).
  double static_velocity = 0.0;      ///< [rad/s or m/s]
  double static_acceleration = 0.0;  ///< [rad/s^2 or m/s^2]
  /// When the filtered inputs have not changed since the last computation, reuse its
  /// result instead of recomputing (exact: same inputs, same outputs).
  bool reuse_unchanged = true;
  /// With reuse_unchanged: publish the reused result with the new stamp (true) or
  /// publish nothing for an unchanged sample (false; the node's choice, not the estimator's).
  bool republish_unchanged = true;
  /// Solve the planar 3x3 system of the paper's section 6 instead of the 6x6 one when
  /// every computed joint turns about one normal n, slides across it, gravity and the
  /// inertias agree (planar.hpp states the exact conditions). The published 6-D
  /// wrenches are unchanged (within 1e-12 relative). kAuto: detected at construction,
  /// and a sample whose filtered wrench input leaves the plane takes the 6x6 path.
  /// kOn: also where detection refuses (not exact there). Precision::kFloat always
  /// keeps the 6x6 path.
  PlanarMode planar = PlanarMode::kAuto;
};

struct EstimatorConfig {
  DifferentiatorConfig differentiator;
  Precision precision = Precision::kDouble;
  Savings savings;
  /// Joints whose loads are wanted (URDF names); empty: all. With savings.prune, only
  /// what they depend on is computed.
  std::vector<std::string> joints;
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
  /// After a planar sample (lastWasPlanar()) only the loads (force, moment, effort) are
  /// updated: the planar pass has no 3-D kinematics to store.
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
  /// Segments whose loads are computed (all, or what the wanted joints need).
  const std::vector<int>& dynamicsSegments() const { return dynamics_segments_; }
  /// Whether wrench input k acts on a segment whose loads are computed.
  bool inputNeeded(int k) const { return inputs_[k].needed; }
  /// Whether coordinate i enters the computed loads.
  bool coordinateNeeded(int i) const { return coordinate_needed_[i] != 0; }
  /// How the last published sample was obtained (for the benchmarks).
  bool lastWasReused() const { return reused_; }
  bool lastWasStatic() const { return static_; }
  /// Whether the planar 3x3 path is in use (savings.planar), why not if it is not, and
  /// whether the last published sample took it.
  bool planar() const { return planar_; }
  const std::string& planarReason() const { return planar_reason_; }
  bool lastWasPlanar() const { return last_planar_; }

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
    bool needed = true;
  };
  void compute(const BaseState<double>& base_state);
  // The planar path for this sample; false (nothing done) when a wrench leaves the plane.
  bool computePlanar();
  // Value of input k at time t (linear between samples, held past the newest).
  Eigen::Matrix<double, 6, 1> sampleInput(Input& input, double t);

  Model<double> model_;  // flags of the disabled savings cleared
  EstimatorConfig config_;
  Data<double> data_;
  Model<float> model_f_;  // Precision::kFloat
  Data<float> data_f_;
  VectorX<float> q_f_, qd_f_, qdd_f_;
  std::vector<int> kinematics_segments_;  // closed under parents
  std::vector<int> dynamics_segments_;    // closed under children
  std::vector<char> coordinate_needed_;
  bool prune_ = false;
  std::vector<double> last_inputs_;  // the filtered inputs of the last computation
  bool have_result_ = false;
  bool reused_ = false;
  bool static_ = false;
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
  // savings.planar (planar.hpp).
  bool planar_ = false;
  bool last_planar_ = false;
  std::string planar_reason_;
  PlanarModel<double> planar_model_;
  PlanarData<double> planar_data_;
};

}  // namespace jle
