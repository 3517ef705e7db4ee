// The online estimator shared by the node, process_bag and the benchmarks: joint
// samples in, filtered kinematics, resampled and equally filtered wrenches, joint loads
// out. ROS-free.
#pragma once

#include <joint_load_estimator/config.hpp>
#include <joint_load_estimator/data.hpp>
#include <joint_load_estimator/differentiation.hpp>
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/force_plate.hpp>
#include <joint_load_estimator/model.hpp>
#include <joint_load_estimator/planar.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace jle {

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

  /// A sample of force plate k at time t [s] as the plate measures it: the force [N]
  /// and moment [N m] the foot applies to the plate, plate frame, moment about the plate
  /// origin. A sample below the contact threshold is taken as zero. Samples not newer
  /// than the newest held, or non-finite, are dropped (false).
  bool addPlateSample(int k, double t, const Eigen::Vector3d& force_plate,
                      const Eigen::Vector3d& moment_plate);
  /// Sets the pose of plate k's frame in the world [m] (the root frame for a fixed base);
  /// the configured pose until then.
  void setPlatePose(int k, const Eigen::Matrix3d& R_world_plate, const Eigen::Vector3d& p_world_plate);
  const PlateInputConfig& plateConfig(int k) const { return plates_[k].config; }
  /// Plate k as applied at the last published sample: contact, COP (plate frame), free
  /// moment, reaction on the foot. No contact: nothing was applied.
  const PlateReading& plateReading(int k) const { return plates_[k].reading; }
  /// Whether plate k was stale at the last joint sample.
  bool plateStale(int k) const { return plates_[k].input.stale; }
  /// Whether plate k's foot is on a segment whose loads are computed.
  bool plateNeeded(int k) const { return plates_[k].input.needed; }

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
  /// Segment of sensor input k's joint (WrenchInputConfig::sensor_joint), -1 for an
  /// applied wrench.
  int sensorSegment(int k) const { return inputs_[k].sensor_segment; }
  /// For a sensor input k at the last published sample: the joint wrench its joint
  /// would transmit according to the model (child link frame, moment about the joint
  /// origin), and whether the measurement was used (false while a sensor with the
  /// kZero policy is stale: then the proximal joints carry the prediction).
  const Wrench<double>& predictedWrench(int k) const { return inputs_[k].predicted; }
  bool sensorUsed(int k) const { return inputs_[k].used; }
  /// Measured minus predicted for sensor input k (same frame and point): the load the
  /// distal side exerts on its surroundings beyond what the model and the other inputs
  /// explain (e.g. a tool pushing on a surface), or a sensor bias. Zero when unused.
  Wrench<double> sensorResidual(int k) const;
  /// Nominal delay of the estimate behind the newest sample, in samples.
  int delaySamples() const { return bank_.config().delay; }
  /// Segments whose loads are computed (all, or what the wanted joints need).
  const std::vector<int>& dynamicsSegments() const { return dynamics_segments_; }
  /// Whether wrench input k acts on a segment whose loads are computed.
  bool inputNeeded(int k) const { return inputs_[k].needed; }
  /// Whether coordinate i enters the computed loads.
  bool coordinateNeeded(int i) const { return coordinate_needed_[i] != 0; }
  /// Covariance of data().force/moment[segment] of the last published sample: child
  /// frame, (fx fy fz mx my mz), moment about the joint origin [N^2, N^2 m, N^2 m^2].
  /// Valid after kPublished when config().uncertainty.enabled, for the segments of
  /// dynamicsSegments(); with diagonal_only its off-diagonal terms are zero.
  const Eigen::Matrix<double, 6, 6>& covariance(int segment) const {
    return covariance_[static_cast<std::size_t>(segment)];
  }
  /// Variance of data().effort[segment] [N^2 m^2 or N^2] (0 for a joint that does not move),
  /// from covariance(segment) (clamped at 0: an extrapolated matrix may be indefinite).
  double effortVariance(int segment) const;
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
    int sensor_segment = -1;  // sensor input: the segment of its joint
    Wrench<double> predicted;  // sensor input: prediction at the last computation
    bool used = false;         // sensor input: its measurement replaced the prediction
  };
  // The backward pass hook of a sensor's segment: keeps the prediction, substitutes
  // the measurement.
  template <typename Scalar>
  void atSensor(Data<Scalar>& data, const Model<Scalar>& model, int segment);
  void compute(const BaseState<double>& base_state);
  // Covariance of the loads just computed (src/core/covariance.cpp).
  void setUpCovariance();
  void computeCovariance(const BaseState<double>& base_state);
  void loadsPass(Data<double>& data, const VectorX<double>& q, const VectorX<double>& qd,
                 const BaseState<double>& base_state);
  template <bool kState>
  void sweepCoordinate(int j, const Data<double>& nom, const Eigen::Matrix<double, 3, kState ? 3 : 1>& F);
  struct Plate {
    PlateInputConfig config;
    ForcePlateConfig filtered;  // config.plate with a zero threshold (for the filtered wrench)
    Input input;                // samples (zero below the threshold); input.frame: the foot
    bool contact = false;       // raw signal in contact at the estimate's stamp
    PlateReading reading;
  };
  // Contact of every plate at the estimate's stamp (raw signal); true if any changed.
  bool updatePlateContacts();
  void applyPlates();
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
  std::vector<int> sensor_of_segment_;  // per segment: sensor input index, or -1
  bool have_sensors_ = false;
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
  std::vector<Plate> plates_;
  int plate_channel_ = 0;
  VectorX<double> q_, qd_, qdd_;
  Eigen::Quaterniond last_orientation_ = Eigen::Quaterniond::Identity();
  double last_t_ = 0.0;
  bool have_last_ = false;
  long sample_count_ = 0;
  double stamp_ = 0.0;

  // Covariance workspace, sized in setUpCovariance() (src/core/covariance.cpp).
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  std::vector<Matrix6> covariance_;     // per segment: the result
  std::vector<Matrix6> local_;          // per segment: covariance of its own terms, then subtree
  // Per segment: tangents of one coordinate's sweep (columns: the noise directions):
  // omega, alpha, origin acceleration, then force and moment (segment frame).
  std::vector<Eigen::Matrix3d> t_w_, t_al_, t_acc_, t_f_, t_n_;
  std::vector<Eigen::Matrix<double, 6, 3>> jacobian_;  // per segment: ancestors of a mimic's sweep
  std::vector<int> subtree_end_;        // per segment: its subtree is [i, subtree_end_[i])
  std::vector<char> in_dynamics_;       // per segment
  std::vector<char> in_kinematics_;     // per segment
  std::vector<int> sweep_mark_;         // per segment: the coordinate being swept + 1, or 0
  std::vector<std::vector<int>> sweep_;            // per coordinate: subtrees of its segments
  std::vector<std::vector<int>> sweep_ancestors_;  // per coordinate, several roots: their ancestors
  std::vector<char> single_root_;                  // per coordinate
  Data<double> cov_nominal_;  // the loads in double (Precision::kFloat)
  // uncertainty.period: the last three computed covariances (newest first), per segment,
  // their stamps, and how many of them are valid (0 after a start, reset or gap).
  std::vector<Matrix6> cov_last_, cov_prev_, cov_prev2_;
  double cov_time_[3] = {0.0, 0.0, 0.0};
  Eigen::Matrix3d cov_gain_ = Eigen::Matrix3d::Zero();  // noise gain of the last computed
  int cov_history_ = 0;
  void extrapolateCovariance(double t);
  // savings.planar (planar.hpp).
  bool planar_ = false;
  bool last_planar_ = false;
  std::string planar_reason_;
  PlanarModel<double> planar_model_;
  PlanarData<double> planar_data_;
};

}  // namespace jle
