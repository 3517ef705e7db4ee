// The online estimator shared by the node, process_bag and the benchmarks: joint
// samples in, filtered kinematics, resampled and equally filtered wrenches, joint loads
// out. ROS-free.
#pragma once

#include <joint_load_estimator/estimation/base_channels.hpp>
#include <joint_load_estimator/estimation/covariance.hpp>
#include <joint_load_estimator/estimation/input_buffer.hpp>
#include <joint_load_estimator/estimation/plate_inputs.hpp>
#include <joint_load_estimator/estimation/sensor_joints.hpp>
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/force_plate.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/model/planar.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
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

/// The online estimator: joint samples in (with the wrench, plate and base-pose samples
/// between them), filtered kinematics and joint loads out. It composes the bank of
/// filters, the wrench inputs' buffers (input_buffer.hpp), the force plates
/// (plate_inputs.hpp), the sensor joints (sensor_joints.hpp), a floating base's channels
/// (base_channels.hpp), the covariance (covariance.hpp) and the planar path (planar.hpp).
/// Memory is allocated in the constructor only.
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
  /// order); base is required for a floating-base model; qd, if given, the measured
  /// velocities (nq entries; NaN: not measured at this sample), used as
  /// config().measured_velocity says (filters().velocitiesUsed()). When the result is
  /// kPublished, last().stamp() and last().data() hold the loads.
  SampleStatus addJointSample(double t, const double* q, const BasePose* base = nullptr,
                              const double* qd = nullptr);
  /// Forgets all history (a backward jump of time).
  void reset();

  /// The end of a stream: with a smoother (differentiator/lag > 0) the samples taken and
  /// not yet estimated are smoothed with the data there is; each call takes the next of
  /// them as addJointSample would have (status: kPublished, kDecimated or kStale) and
  /// returns true, false when none is left. Nothing to do for a causal filter.
  bool flush(SampleStatus& status);
  /// With a smoother: the next sample whose loads are due at the newest joint sample
  /// besides the one addJointSample took (several are where the rate drops or after a
  /// gap: the delay is differentiator/lag in seconds), taken as addJointSample would
  /// have (status as flush()); false when none is. One not taken comes with a later
  /// sample, in order.
  bool takeDue(SampleStatus& status);

  /// Live tuning (the node's ~reconfigure). `decimation` (>= 1) applies in place: the
  /// filters and the decimation phase are kept, so the loads are those of an estimator
  /// started with it (exact). A `differentiator` other than the current one replaces
  /// the bank of filters, which starts empty (its warm-up follows): one filter's state
  /// means nothing to another. The wrench and plate buffers (raw samples) are kept.
  /// Returns false when the filters were restarted. Throws std::invalid_argument
  /// naming the parameter, changing nothing, on a bad value.
  bool retune(const DifferentiatorConfig& differentiator, int decimation);

  /// A sample of force plate k at time t [s] as the plate measures it: the force [N]
  /// and moment [N m] the foot applies to the plate, plate frame, moment about the plate
  /// origin. A sample below the contact threshold is taken as zero. Samples not newer
  /// than the newest held, or non-finite, are dropped (false).
  bool addPlateSample(int k, double t, const Eigen::Vector3d& force_plate,
                      const Eigen::Vector3d& moment_plate);
  /// Sets the pose of plate k's frame in the world [m] (the root frame for a fixed base);
  /// the configured pose until then. config().plates[k] follows it.
  void setPlatePose(int k, const Eigen::Matrix3d& R_world_plate,
                    const Eigen::Vector3d& p_world_plate);

  // What comes out, in three read-only views (each a reference to this estimator, valid
  // while it lives): what the configuration computes, what the filters chose, and the
  // last published sample.
  class Layout;
  class Filters;
  class LastSample;
  Layout layout() const;
  Filters filters() const;
  LastSample last() const;

 private:
  // The views' out-of-line parts (estimator.cpp).
  int velocitiesUsed() const;
  bool velocitiesBetter() const;
  Wrench<double> appliedWrench(int k) const;
  Wrench<double> sensorResidual(int k) const;
  double effortVariance(int segment) const;

  // A wrench input: its samples (sign applied), the frame it acts at, the first of its
  // six bank channels, and whether a computed segment needs it.
  struct WrenchInput {
    InputBuffer samples;
    int frame = 0;
    int channel = 0;
    double sign = 1.0;
    bool needed = true;
  };
  // Precision::kFloat: the model, its workspace and the estimate in float.
  struct SinglePrecision {
    explicit SinglePrecision(const Model<double>& model_double);
    Model<float> model;
    Data<float> data;
    VectorX<float> q, qd, qdd;
  };

  // Construction, in order. selectSegments returns per segment whether it is computed.
  void setUpWrenchInputs();
  std::vector<char> selectSegments();
  void markNeeded(const std::vector<char>& dynamics);
  void setUpPlanar();
  // A joint sample: its checks (false: refused, and why), the bank's channels, the estimate.
  bool accept(double t, const double* q, const BasePose* base, SampleStatus& refused);
  void fillChannels(double t, const double* q, const BasePose* base, double half);
  // The sample into the filters (its inputs read within half [s] of t; 0: the newest),
  // and its estimate if one is due.
  SampleStatus feed(double t, const double* q, const BasePose* base, const double* qd, double half);
  // Layout::holdsSamples(): the sample waits (held_), and the held one is fed.
  void hold(double t, const double* q, const BasePose* base, const double* qd);
  SampleStatus feedHeld(double next_t);
  void chooseVelocities(const double* qd);
  void fillVelocityChannels(double t, const double* qd);
  SampleStatus publish();
  BaseState<double> readEstimate();
  // savings.reuse_unchanged: whether the filtered inputs are those of the last computation
  // (then recorded for the next sample).
  bool sameFilteredInputs(bool contacts_changed);
  void compute(const BaseState<double>& base_state);
  // The loads in Scalar (double, or float for Precision::kFloat): the one 6x6 path.
  template <typename Scalar>
  void computeLoads(const Model<Scalar>& model, Data<Scalar>& data, const VectorX<Scalar>& q,
                    const VectorX<Scalar>& qd, const VectorX<Scalar>& qdd,
                    const BaseState<Scalar>& base);
  void computeInFloat(const BaseState<double>& base_state);
  // The planar path for this sample; false (nothing done) when a wrench leaves the plane.
  bool computePlanar();
  void updateCovariance(const BaseState<double>& base_state);
  // The loads in double with every needed input applied (no sensor substitution), for
  // the covariance of a Precision::kFloat sample.
  void loadsPass(Data<double>& data, const BaseState<double>& base_state);

  Model<double> model_;  // flags of the disabled savings cleared
  EstimatorConfig config_;
  Data<double> data_;
  SinglePrecision single_;
  std::vector<int> kinematics_segments_;  // closed under parents
  std::vector<int> dynamics_segments_;    // closed under children
  std::vector<char> coordinate_needed_;
  std::vector<double> last_inputs_;  // the filtered inputs of the last computation
  bool have_result_ = false;
  bool reused_ = false;
  bool static_ = false;  // the last sample at rest (savings.static_velocity)
  DifferentiatorBank bank_;
  std::vector<double> channels_;  // q (nq), base (7), wrenches (6 per input), plates (6 each)
  int base_channel_ = 0;
  // The measured velocities (MeasuredVelocity): their filter, the same as the positions',
  // fed while velocity_active_ (some coordinate uses them), and its channels (nq).
  DifferentiatorBank velocity_bank_;
  std::vector<double> velocity_channels_;
  // Per coordinate: q-dot from velocity_bank_; decided at the first sample (after a
  // start, reset or retune) while velocities_open_.
  std::vector<char> velocity_used_;
  bool velocity_active_ = false;
  bool velocities_open_ = true;
  int wrench_channel_ = 0;
  std::vector<WrenchInput> inputs_;
  SensorJoints sensors_;
  PlateInputs plates_;
  VectorX<double> q_, qd_, qdd_;
  Eigen::Quaterniond last_orientation_ = Eigen::Quaterniond::Identity();
  double last_t_ = 0.0;
  bool have_last_ = false;
  // Layout::holdsSamples(): the joint sample waiting for the next one, and the one fed before it
  // (before < t; -inf: none since a start).
  struct HeldSample {
    double t = 0.0, before = 0.0;
    std::vector<double> q, qd;
    bool has_qd = false, has_base = false;
    BasePose base;
  };
  HeldSample held_;
  bool holding_ = false;
  bool hold_inputs_ = false;
  long sample_count_ = 0;
  double stamp_ = 0.0;
  CovarianceModel covariance_model_;
  CovarianceWorkspace covariance_;
  Data<double> cov_nominal_;  // the loads in double (Precision::kFloat)
  // savings.planar (planar.hpp).
  bool planar_ = false;
  bool last_planar_ = false;
  std::string planar_reason_;
  PlanarModel<double> planar_model_;
  PlanarData<double> planar_data_;
};

/// What an Estimator computes, fixed by its configuration at construction.
class Estimator::Layout {
 public:
  explicit Layout(const Estimator& e) : e_(&e) {}
  /// Segments whose loads are computed (all, or what the wanted joints need).
  const std::vector<int>& dynamicsSegments() const { return e_->dynamics_segments_; }
  /// Whether coordinate i enters the computed loads.
  bool coordinateNeeded(int i) const { return e_->coordinate_needed_[ix(i)] != 0; }
  /// Whether wrench input k acts on a segment whose loads are computed.
  bool inputNeeded(int k) const { return e_->inputs_[ix(k)].needed; }
  /// Whether plate k's foot is on a segment whose loads are computed.
  bool plateNeeded(int k) const { return e_->plates_.needed(k); }
  /// Segment of sensor input k's joint (WrenchInputConfig::sensor_joint), -1 for an
  /// applied wrench.
  int sensorSegment(int k) const { return e_->sensors_.segment(k); }
  /// Whether each joint sample waits for the next one before it enters the filters: a
  /// smoother (lag > 0) with wrench or plate inputs, which are then read around the
  /// sample's stamp from the samples on both sides of it (InputBuffer::centredAt), as
  /// the offline zero-phase path reads them, instead of the newest one held (a delay of
  /// up to an F/T period) or one noisy point between slower F/T samples. The smoothed
  /// stream's delay grows by one joint-state interval.
  bool holdsSamples() const { return e_->hold_inputs_; }
  /// Whether the planar 3x3 path is in use (savings.planar), and why not if it is not.
  bool planar() const { return e_->planar_; }
  const std::string& planarReason() const { return e_->planar_reason_; }

 private:
  static std::size_t ix(int k) { return static_cast<std::size_t>(k); }
  const Estimator* e_;
};

/// What an Estimator's filters chose from the data so far.
class Estimator::Filters {
 public:
  explicit Filters(const Estimator& e) : e_(&e) {}
  /// Whether coordinate i's q-dot and q-ddot come from the measured velocities (decided at
  /// the first sample after a start, a reset or a retune: MeasuredVelocity).
  bool velocityUsed(int i) const { return e_->velocity_used_[static_cast<std::size_t>(i)] != 0; }
  /// How many coordinates take their q-dot from the measured velocities.
  int velocitiesUsed() const { return e_->velocitiesUsed(); }
  /// Whether the measured velocities are the better evidence of the rates: true but where
  /// a smoother (lag > 0) sets its bandwidth from the data (differentiator.auto_bandwidth,
  /// the smoothed stream); there, where the velocities' noise floor is below the
  /// positions' times (2 pi f)^2, f the positions' bandwidth (at f, the velocities' share
  /// of noise is the smaller), the floors of both spectra once both have chosen, before
  /// that of both probes (0.5 s blocks; true where a probe finds no floor), and before
  /// the probes' first choice false (the positions). Where it is false, the coordinates of
  /// velocityUsed() take q-dot and q-ddot from the positions too (accuracy study: the
  /// Panda scenes' velocities, 1e-3 rad/s, are worse evidence than their positions;
  /// the coloured-noise scenes' much better).
  bool velocitiesBetter() const { return e_->velocitiesBetter(); }
  /// The positions' filter's bandwidth [Hz] where it is set from the data
  /// (DifferentiatorBank::bandwidth: auto_bandwidth); 0 for a filter without one.
  double bandwidth() const {
    return e_->bank_.config().auto_bandwidth ? e_->bank_.bandwidth() : 0.0;
  }
  /// auto_bandwidth: the positions' spectrum's last choice [Hz] before the lag's floor (0
  /// before the first), and its noise floor [unit^2] (0 where none was found).
  double spectralCutoff() const { return e_->bank_.spectralCutoff(); }
  double noiseFloor() const { return e_->bank_.noiseFloor(); }
  /// Samples taken and not yet estimated (a smoother's; flush()), the held one included.
  int pendingSamples() const { return e_->bank_.pending() + (e_->holding_ ? 1 : 0); }
  /// Delay of the estimate behind the newest sample, in samples (a smoother's: its
  /// pending samples, an upper bound of the delay of any estimate still to come:
  /// DifferentiatorBank::delaySamples()).
  int delaySamples() const { return e_->bank_.delaySamples() + (e_->holding_ ? 1 : 0); }

 private:
  const Estimator* e_;
};

/// An Estimator's last published sample (after addJointSample, flush or takeDue returned
/// kPublished).
class Estimator::LastSample {
 public:
  explicit LastSample(const Estimator& e) : e_(&e) {}
  /// Time the loads describe [s] (the newest joint sample minus the filter's delay).
  double stamp() const { return e_->stamp_; }
  /// Kinematics and loads (dynamics.hpp conventions). After a planar sample (planar())
  /// only the loads (force, moment, effort) are updated: the planar pass has no 3-D
  /// kinematics to store. World poses (R_world, p_world) beyond the root's are computed
  /// only with force plates, which need them: jle::worldPoses() on a copy fills them
  /// otherwise.
  const Data<double>& data() const { return e_->data_; }
  /// The estimated coordinates (q-dot and q-ddot from the measured velocities where
  /// Filters::velocityUsed()).
  const VectorX<double>& q() const { return e_->q_; }
  const VectorX<double>& qd() const { return e_->qd_; }
  const VectorX<double>& qdd() const { return e_->qdd_; }
  /// Whether wrench input k was stale at the last joint sample.
  bool stale(int k) const { return e_->inputs_[static_cast<std::size_t>(k)].samples.stale(); }
  /// The filtered wrench of input k applied (sign applied, link frame).
  Wrench<double> appliedWrench(int k) const { return e_->appliedWrench(k); }
  /// For a sensor input k: the joint wrench its joint would transmit according to the
  /// model (child link frame, moment about the joint origin), and whether the measurement
  /// was used (false while a sensor with the kZero policy is stale: then the proximal
  /// joints carry the prediction).
  const Wrench<double>& predictedWrench(int k) const { return e_->sensors_.predicted(k); }
  bool sensorUsed(int k) const { return e_->sensors_.used(k); }
  /// Measured minus predicted for sensor input k (same frame and point): the load the
  /// distal side exerts on its surroundings beyond what the model and the other inputs
  /// explain (e.g. a tool pushing on a surface), or a sensor bias. Zero when unused.
  Wrench<double> sensorResidual(int k) const { return e_->sensorResidual(k); }
  /// Plate k as applied: contact, COP (plate frame), free moment, reaction on the foot.
  /// No contact: nothing was applied.
  const PlateReading& plateReading(int k) const { return e_->plates_.reading(k); }
  /// Whether plate k was stale at the last joint sample.
  bool plateStale(int k) const { return e_->plates_.stale(k); }
  /// Covariance of data().force/moment[segment]: child frame, (fx fy fz mx my mz), moment
  /// about the joint origin [N^2, N^2 m, N^2 m^2]. Valid when config().uncertainty.enabled,
  /// for the segments of Layout::dynamicsSegments(); with diagonal_only its off-diagonal
  /// terms are zero.
  const Eigen::Matrix<double, 6, 6>& covariance(int segment) const {
    return e_->covariance_.covariance[static_cast<std::size_t>(segment)];
  }
  /// Variance of data().effort[segment] [N^2 m^2 or N^2] (0 for a joint that does not
  /// move), from covariance(segment) (clamped at 0: an extrapolated matrix may be
  /// indefinite).
  double effortVariance(int segment) const { return e_->effortVariance(segment); }
  /// How it was obtained: the previous computation reused (savings.reuse_unchanged), or
  /// the planar 3x3 path taken.
  bool reused() const { return e_->reused_; }
  bool planar() const { return e_->last_planar_; }

 private:
  const Estimator* e_;
};

inline Estimator::Layout Estimator::layout() const { return Layout(*this); }
inline Estimator::Filters Estimator::filters() const { return Filters(*this); }
inline Estimator::LastSample Estimator::last() const { return LastSample(*this); }

}  // namespace jle
