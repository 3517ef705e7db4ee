// Every setting of the estimator and of its front ends (the node, process_bag, the
// command-line tools, the bindings), each with its default, once, and their one
// validation. Readers (YAML and the parameter tree in settings_reader.hpp, a command line) only
// map names onto these structures and call validate(). ROS-free.
//
// The keys named in the errors are the parameter names of config/default.yaml, with
// `/` between a map and its key and `[i]` for a list's element: 'wrenches[0]/sign'.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/force_plate.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/settings/differentiator_config.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace jle {

/// A setting that is missing where required, of the wrong type or out of range; the
/// message names the parameter ("parameter 'decimation' must be >= 1, it is 0").
/// Derived from std::invalid_argument, which the Estimator's callers catch.
class SettingsError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

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
  /// URDF link the wrench acts on; samples are given in its frame. Required, but for a
  /// sensor input (sensor_joint), whose link defaults to the joint's child link.
  std::string link;
  double sign = 1.0;     ///< +1: the load on the robot (F/T sensor); -1: the load the robot applies
                         ///< (force plate)
  double timeout = 0.1;  ///< [s] > 0; older than this at a joint sample = stale
  /// What a stale input reads as: zero by default (a dead sensor's last reading no longer
  /// enters the loads); the records it enters are flagged (LoadsRecord::status).
  StalePolicy stale_policy = StalePolicy::kZero;
  /// [s] >= 0, with stale_policy hold: how long past its timeout the last reading is
  /// held; zero after that.
  double max_hold = 1.0;
  /// Non-empty: the input is a force/torque sensor mounted at this FIXED joint of the
  /// URDF (kept as its own segment; `link` must be empty or the joint's child link). It
  /// measures the joint wrench: what the proximal side (the joint's parent link) exerts
  /// on the distal side (its child link); samples are given like any input's, in the
  /// child link frame, moment about its origin (the joint origin). It is not applied as
  /// an external load: the joint's wrench is predicted from the model of the distal
  /// subtree and the other inputs (predictedWrench), and the measurement replaces the
  /// prediction before it is passed on, so the joints proximal to the sensor carry the
  /// measured wrench (the sensor knows about unmodelled payloads and contacts).
  std::string sensor_joint;
  /// Standard deviation of each sample's components, for the covariance of the loads
  /// (UncertaintyConfig): force [N] and moment [N m], per component, white.
  double force_noise = 0.0;
  double moment_noise = 0.0;
};

/// The uncertainty of the inputs, propagated to the covariance of every computed joint
/// wrench (Estimator::LastSample::covariance; docs/studies/uncertainty.md). All standard deviations
/// are 1 sigma; the errors are taken as independent, zero-mean and (for the sensors) white.
struct UncertaintyConfig {
  bool enabled = false;
  bool diagonal_only = false;  ///< only the 6 variances per joint (off-diagonal terms left 0)
  /// [rad or m] noise of each joint position sample (an encoder of step D: D / sqrt(12)).
  double position_noise = 0.0;
  double mass_fraction = 0.0;     ///< relative, per link
  double com_offset = 0.0;        ///< [m] per axis, per link
  double inertia_fraction = 0.0;  ///< relative (the whole tensor scaled), per link
  /// Include the (linearised) dependence on q and q-dot; false: only the q-ddot, wrench
  /// and inertial-parameter parts, which are exact and cheaper.
  bool linearize_state = true;
  /// [s] The covariance is computed for a published sample whose stamp is at least
  /// `period` after the last computed one (and for the first three after a start, a
  /// reset, a filter restart or a gap of more than 3 periods); the samples in between
  /// get the quadratic through the last three computed ones at their actual times
  /// (variances clamped at 0). 0: computed for every published sample. The error depends
  /// on the period, not on the joint-state rate. docs/studies/uncertainty.md measures the cost
  /// and the error. 0.018: the propagation costs at most as much as the loads at 1 kHz
  /// (Panda, Talos), worst sigma error 2.7%.
  double period = 0.018;
  /// With period > 0: an extrapolated sample is computed instead when the filter's noise
  /// gain (the covariance of the estimated q, q-dot, q-ddot per unit measurement
  /// variance) is more than this fraction away from the gain of any of the three computed
  /// samples the extrapolation would use (irregular stamps: the gain changes with every
  /// spacing; a Kalman filter settling after a start, a gap or a reset: its gain moves
  /// from one node to the next). 0.02 bounds the sigma error from that source to ~1%.
  double gain_tolerance = 0.02;
};

/// One force plate (force_plate.hpp): what the foot applies to the plate, in the plate
/// frame, moment about the plate origin; its reaction acts on `plate.link`.
/// The plate's six components are resampled and filtered at the joint stamps like a
/// wrench input's, every sample as measured. The contact threshold acts on the raw
/// signal at the estimate's stamp: at or above it the plate is in contact and the applied
/// reaction is the filtered wrench, decoded (COP, free moment) and carried to the foot;
/// below it the raw wrench at the stamp acts, without a COP (so the filters' memory of a
/// stance never loads a swinging foot, and the reaction has no step at heel strike or
/// toe-off; docs/biomechanics.md, "Force plates").
struct PlateInputConfig {
  ForcePlateConfig plate;
  double timeout = 0.1;  ///< [s] > 0; older than this at a joint sample = stale
  StalePolicy stale_policy = StalePolicy::kZero;
};

/// Where a coordinate's q-dot and q-ddot come from when the joint states carry velocities
/// (measured_velocity). From the velocities: q-dot is the filtered velocity and q-ddot its
/// rate, the velocity filtered as the positions are (same filter, same delay); q stays the
/// filtered position. A sample whose velocity is missing or not finite feeds that filter
/// its own prediction instead (DifferentiatorBank::predict; counted by the Pipeline).
enum class MeasuredVelocity : std::uint8_t {
  /// Per coordinate: from the velocities when the first joint sample after a start, a reset
  /// or a retune carries a finite one for it; from the positions otherwise. From the
  /// positions for every coordinate while uncertainty/enabled (its propagation models the
  /// positions' noise only).
  kAuto,
  kAlways,  ///< every coordinate from the velocities (refused with uncertainty/enabled)
  kNever,   ///< from the positions only (the velocities are ignored)
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

/// The immediate stream's filter by default: the constant-jerk Kalman filter (process
/// noise 1e4: 12 Hz at 1 kHz), its bandwidth raised, never lowered (auto_bandwidth), up to
/// max_bandwidth (50 Hz, at most 0.45 of the rate): the positions' where their spectrum
/// shows no noise floor, the measured velocities' where theirs meets its floor higher up.
/// Measured on the accuracy study's scenes (docs/studies/accuracy.md, "The defaults against the
/// best of the study"), where 12 Hz smeared the strikes: arm_impact_1khz 8.55 -> 6.66 N m
/// (2.32x -> 0.21x the best at its delay, which fell from 12.0 to 5.3 ms),
/// leg_running_200hz 4.08 -> 1.27 N m (7.07x -> 1.00x), arm_impact_200hz 3.08 -> 3.00;
/// every other scene within 2 %. Up to 1 kHz instead: 6.08, 1.57 and 3.04 N m. Lowered as
/// well (the smoother's rule), panda went 0.049 -> 0.19 N m.
inline DifferentiatorConfig defaultDifferentiator() {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kKalman;
  c.kalman_model = KalmanModel::kConstantJerk;
  c.auto_bandwidth = true;
  return c;
}

/// The estimator's settings (the keys of config/default.yaml that the Estimator reads).
struct EstimatorConfig {
  /// The filter of the joint positions and of the inputs (the node's default: the
  /// accuracy study's constant-jerk Kalman filter, docs/studies/accuracy.md:
  /// defaultDifferentiator).
  DifferentiatorConfig differentiator = defaultDifferentiator();
  MeasuredVelocity measured_velocity = MeasuredVelocity::kAuto;
  Precision precision = Precision::kDouble;
  Savings savings;
  /// Joints whose loads are wanted and published (URDF names of moving joints, or of
  /// fixed joints kept as segments); empty: every moving joint. With savings.prune, only
  /// what they depend on is computed.
  std::vector<std::string> joints;
  Eigen::Vector3d gravity_world{0.0, 0.0, -9.80665};  ///< [m/s^2]
  std::vector<WrenchInputConfig> wrenches;
  /// Loads are computed for every n-th joint sample (>= 1; the filters see every sample).
  int decimation = 1;
  UncertaintyConfig uncertainty;
  /// Force plates (after the wrench inputs in the filter bank).
  std::vector<PlateInputConfig> plates;
};

/// One measured wrench topic of a front end (wrenches[k]): where the messages come
/// from. Pairs with EstimatorConfig::wrenches[k], which holds the input itself (link,
/// sign, timeout, sensor_joint, noises): validate() refuses a `name` that is not that
/// input's (lists in different orders).
struct WrenchTopicSettings {
  /// The name of the input these settings are for (WrenchInputConfig::name: the settings
  /// reader names an input by its topic and sets both). Empty (settings made in code): the
  /// input at the same index.
  std::string name;
  std::string topic;  ///< required
  std::string frame;  ///< expressed-in frame; empty: the message's header.frame_id
  /// Sensor inputs (sensor_joint set): the residual (measured - predicted) above either
  /// threshold is a diagnostic warning.
  double force_threshold = 5.0;   ///< [N], > 0
  double moment_threshold = 0.5;  ///< [N m], > 0
};

/// One force plate topic of a front end (force_plates[k]). Pairs with
/// EstimatorConfig::plates[k], which holds the plate itself (name, link, surface_height,
/// contact_threshold, pose, timeout, stale_policy): validate() refuses a `name` that is not
/// that plate's.
struct PlateTopicSettings {
  /// The name of the plate these settings are for (ForcePlateConfig::name); the settings
  /// reader sets it. Empty (settings made in code): the plate at the same index.
  std::string name;
  std::string topic;  ///< required
  std::string frame;  ///< tf2 frame of the plate; empty: the message's header.frame_id
  /// The pose (position, orientation) was configured: the estimator holds it, no tf2
  /// look-up. False: the front end finds it with tf2.
  bool pose_configured = false;
};

/// The friction term of the motor effort (friction.hpp), from the URDF's
/// <dynamics damping friction> of each joint; off by default.
struct FrictionConfig {
  /// JointLoads.motor_effort = effort + damping qd + friction tanh(qd / velocity_scale);
  /// false: motor_effort is empty.
  bool enabled = false;
  /// [rad/s or m/s] > 0: the width of the smooth sign of the Coulomb term.
  double velocity_scale = 0.01;
};

/// Which estimate of the external joint efforts drives the contact detection and the
/// contact wrenches (external_effort.hpp; docs/external_loads.md, "External torques and contact
/// wrenches").
enum class ExternalMethod : std::uint8_t {
  kObserver,  ///< the momentum observer: no q-ddot, a first-order lag of cut-off observer_cutoff
  kResidual,  ///< predicted minus measured effort: uses the filtered q-ddot (the loads' delay)
};

/// A link where a contact is estimated (external_effort/contacts[k]).
struct ContactLinkConfig {
  std::string link;  ///< URDF link; required
  /// The contact point in the link frame [m]: the force acts there; the published moment
  /// is about the link origin (the WrenchStamped convention).
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// true: a point contact, a force only (3 unknowns; needs >= 3 joints above the link);
  /// false: a full wrench at the point (6 unknowns; >= 6 joints).
  bool force_only = false;
};

/// The external joint efforts, contact detection and contact wrenches from the measured
/// efforts (JointState.effort), external_effort/...; off by default.
struct ExternalEffortConfig {
  bool enabled = false;
  ExternalMethod method = ExternalMethod::kObserver;
  /// [Hz] > 0: cut-off of the momentum observer (gain K = 2 pi observer_cutoff [1/s]).
  double observer_cutoff = 10.0;
  /// [N m or N] >= 0: 1-sigma white noise of each measured effort, for the covariance of
  /// the external efforts and wrenches (with uncertainty/enabled).
  double effort_noise = 0.0;
  /// Damped least squares of the contact wrench: the damping lambda [m] >= 0 grows from 0
  /// to `damping` as the smallest singular value of the Jacobian falls from
  /// singular_threshold to 0 (exact away from singularities).
  double damping = 0.01;
  double singular_threshold = 0.01;  ///< [m or 1] > 0
  std::vector<ContactLinkConfig> contacts;
  /// Contact detection: a joint is in contact while |tau_ext| exceeds its threshold,
  /// max(threshold, noise_multiple * sigma), sigma = 1.4826 median |tau_ext| of the joint
  /// (the RMS of Gaussian noise, unmoved by a few outliers) over calibration_time that
  /// starts settle_time after a start or a reset (the robot free). 0 = that part unused;
  /// both 0: no detection.
  double threshold = 0.0;         ///< [N m or N] >= 0, every joint
  double noise_multiple = 0.0;    ///< >= 0
  double calibration_time = 1.0;  ///< [s] > 0
  /// [s] >= 0: the filters' start-up transient left out of the calibration (the default
  /// filter's reaches 150 N m on the Panda's joint 2 within 50 ms at 1e-4 rad of position
  /// noise); the observer's own settling, 5 / (2 pi observer_cutoff), when longer.
  double settle_time = 0.2;
  /// [s] >= 0: the contact's joint is the most distal one loaded (over its threshold,
  /// until below release_fraction of it) at any sample of the last link_window (a joint
  /// near its threshold does not flicker).
  double link_window = 0.02;
  /// Per-joint thresholds [N m or N] (joint name, value) that replace `threshold`.
  std::vector<std::pair<std::string, double>> joint_thresholds;
  /// A contact ends when every joint is below this fraction (0, 1] of its threshold.
  double release_fraction = 0.5;
};

/// Checks the model-independent settings of external_effort/...; throws SettingsError
/// naming the key (external_effort.cpp).
void validate(const ExternalEffortConfig& config);

/// How the message stamps of the joint-state stream become the estimator's times
/// (docs/node.md, "Time stamps").
enum class StampRegularize : std::uint8_t {
  /// A periodic stream whose stamps jitter about a lattice (stamps taken at reception)
  /// is detected, and its samples' instants are estimated from the stamps (SampleClock);
  /// an irregular stream, and a periodic one with exact stamps, keep their stamps.
  kAuto,
  kOff,  ///< the stamps are the instants
};

/// The joint-state stream's time base and its rogue stamps (stamps/...).
struct StampSettings {
  StampRegularize regularize = StampRegularize::kOff;
  /// Consecutive joint states on a new timeline (each more than time_jump_threshold
  /// from the last taken stamp, back or forward, in order among themselves) that confirm
  /// a jump of time (>= 1); fewer are dropped as rogue stamps. The clock going back
  /// confirms a jump back at once.
  int jump_confirm = 3;
  /// [s] >= 0: joint states of several publishers (each a subset of the joints) whose
  /// stamps lie within this of each other are merged into one sample (Pipeline, docs/node.md
  /// "Never silently wrong"); a sample waits for every needed joint until a message of a
  /// later instant comes. 5 ms: two drivers of one robot stamping one cycle up to 200 Hz;
  /// a joint repeated closes an instant anyway, so a faster stream loses nothing by it.
  double merge_window = 0.005;
};

/// The smoothed stream's filter by default: the constant-jerk Kalman smoother, lag 0.2 s,
/// its bandwidth set from the data (auto_bandwidth): where the positions' spectrum meets
/// its noise floor, at least 7 Hz (kLagFloor / lag), and where it shows no floor (data
/// without noise: the running leg) up to max_bandwidth (1 kHz: 0.45 of the rate);
/// process noise 400 (8 Hz at 1 kHz; at least the lag's floor at any rate) until the first
/// choice (4 s; data without noise: 0.5 s): a fifth to half of a recording is before it,
/// and 1e3 (9 Hz at 1 kHz, 6.7 Hz at 100 Hz) cost talos 1.41, panda_4khz 1.39, panda_sines
/// 1.32 times the offline result (now 1.27, 1.27, 1.26); 7 Hz from the start cost ur5 1.53
/// (1.23) and random_tree 1.33 (1.13), whose motion is faster. Measured on the
/// accuracy study's scenes: docs/studies/accuracy.md, "The defaults against the best of the
/// study"; docs/how_it_works.md, "Two streams". The same filter at the study's other lags
/// (0.1, 0.25 s) are its rows `KS-CJ auto lag=...`. A zero-phase Butterworth at a fixed delay
/// (its backward pass over blocks from the newest sample) was prototyped against it: at 6 Hz it
/// needs about 0.45 s of delay to come within 1.1x of the offline result, where this smoother
/// (whose response with a long lag is the same |H|^2) needs about 0.25 s.
/// With the joint states' velocities, their filter (the same, raised only:
/// DifferentiatorBank::raiseOnly) also runs at 1.5 times its bandwidth while its innovations
/// are correlated from sample to sample beyond what the noise floor predicts
/// (DifferentiatorBank::kMissedMotionBoost): a move faster than the 2 s blocks so far show. On
/// arm_noise_1e-3 the velocities' spectrum chose 8.8 Hz from the slow moves of 2-4 s, and a
/// fast move at 5.6 s, before the 4-6 s block raised it to 12.5 Hz, cost 0.068 N m RMS over
/// 5.5-6 s (0.032 at 12 Hz); with the boost the scene's error is 0.0194 -> 0.0165 N m, 1.56x ->
/// 1.33x the best at its delay (KS-CJ q=1e4 + velocities, 12 Hz), arm_jitter_1khz 1.14x ->
/// 1.00x, arm_noise_1e-4 1.07x -> 1.02x, arm_jitter_100hz 1.27x -> 1.32x, the coloured and gait
/// scenes unchanged. The positions' bandwidth is not the cause there (7 to 12 Hz with the
/// velocities' at 12 Hz: 0.0122 to 0.0124 N m); a fixed floor for the velocities' filter (1e4:
/// 12 Hz at 1 kHz) gave arm_noise_1e-3 0.97x but arm_coloured_200hz 2.12x and panda_4khz 1.58x,
/// and the same boost from the innovations' energy instead of their correlation (which stamp
/// jitter raises during moves) arm_jitter_100hz 1.43x and arm_coloured_200hz 1.47x.
inline DifferentiatorConfig defaultSmoother() {
  DifferentiatorConfig c;
  c.type = DifferentiatorType::kKalman;
  c.kalman_model = KalmanModel::kConstantJerk;
  c.process_noise = 400.0;
  c.lag = 0.2;
  c.auto_bandwidth = true;
  c.max_bandwidth = 1e3;
  return c;
}

/// The smoothed stream (smoothed/...): the loads of the same samples, through the same
/// pipeline, estimated by a smoother `differentiator.lag` seconds behind the newest sample,
/// beside the immediate (causal) stream of `estimator.differentiator`. For monitoring,
/// rviz and bag replay; control loops take the immediate stream.
struct SmoothedStreamSettings {
  bool enabled = true;
  /// A smoother: type kalman or adaptive, lag > 0 [s].
  DifferentiatorConfig differentiator = defaultSmoother();
};

/// Every setting of the node and of the offline front ends (process_bag), with the
/// parameter names of config/default.yaml (docs/node.md, "Parameters").
/// What an input may be before it is refused at the door (Pipeline; docs/node.md "Never
/// silently wrong"): a finite absurd value must not reach the filters.
struct PlausibilityConfig {
  /// [rad or m] >= 0: a position beyond its joint's URDF limits by more than this is
  /// refused (the message dropped, counted 'implausible'). 1: a recording a little
  /// beyond its URDF's limits (a calibration offset, a simulated trajectory) is taken;
  /// what no joint reaches (100 rad, 1e300) is not.
  double position_margin = 1.0;
  /// [rad or m] >= 0, and >= 1: a position moving from the last sample by more than
  /// step_margin plus velocity_factor times its joint's URDF velocity limit (max_velocity
  /// where the URDF has none) times the interval is refused, unless stamps/jump_confirm
  /// joint states in a row agree with it: then the filters restart from it. Measured
  /// velocities beyond velocity_factor times the limit are not used (as a non-finite one).
  double step_margin = 0.1;
  double velocity_factor = 3.0;
  double max_velocity = 100.0;  ///< [rad/s or m/s] > 0, where the URDF gives no limit
  /// [N], [N m] > 0: a wrench or plate reading whose force or moment is larger is refused.
  double max_force = 1e5, max_moment = 1e4;
  /// >= 1: an effort beyond this times its joint's URDF effort limit flags the record
  /// implausible.
  double effort_factor = 3.0;
  /// [s] >= 0: the records of the first this-many seconds after the filters (re)start (a
  /// start, a jump of time, a gap, a retune) are flagged settling.
  double settle_time = 0.05;
  /// [rad or m] >= 0: a mimic joint's published position farther than this from what its
  /// leader's (in the same message) gives contradicts the model: counted and warned (the
  /// model's value is used).
  double mimic_tolerance = 0.01;
};

struct Settings {
  std::string robot_description = "robot_description";  ///< parameter holding the URDF
  std::string joint_states_topic = "joint_states";
  bool publish_wrench_topics = true;  ///< advertise ~wrench/<joint>
  bool floating_base = false;
  std::string world_frame = "world";  ///< tf2 frame of the world (floating base)
  std::string base_frame;             ///< tf2 frame of the base; empty: the URDF root link
  /// [s] >= 0, the node only: a transform the loads need (the floating base's pose, a
  /// wrench's frame) that is late, its stamp newer than tf2's newest by at most this, is
  /// waited for up to this long (wall time) before the message is dropped (counted). 0:
  /// no wait. Offline tools fill tf2 in the bag's order and never wait.
  double tf_wait = 0.05;
  /// [s] > 0; a joint-state stamp this far from the last one taken (back, or forward
  /// beyond 10 periods too, unless the clock moved as far) is a rogue stamp, or,
  /// confirmed (stamps.jump_confirm), a jump of time: reset.
  double time_jump_threshold = 1.0;
  StampSettings stamps;
  /// Fixed joints kept as their own segments (their wrench is published). The joints of
  /// the sensor inputs (estimator.wrenches[k].sensor_joint) are kept too, without being
  /// listed here (modelOptions()).
  std::vector<std::string> keep_fixed_joints;
  /// Accept a robot model whose link inertias no rigid body has (identified parameter
  /// sets), with a warning per link; default: refused (ModelOptions holds the default).
  bool accept_nonphysical_inertia = ModelOptions().accept_nonphysical_inertia;
  /// Floating base: a residual force above this fraction (> 0) of the total weight is a
  /// diagnostic warning.
  double base_residual_threshold = 0.1;
  PlausibilityConfig plausibility;
  /// ~calibrate_bias: the robot is still while every estimated |q-dot| stays below this.
  double still_velocity = 0.02;  ///< [rad/s or m/s], > 0
  /// YAML file of the sensor biases: loaded at start if it exists, written by
  /// ~calibrate_bias. Empty: not loaded, and calibrate_bias writes none.
  std::string bias_file;
  /// [s] > 0: period of the node's diagnostics timer (/diagnostics), a wall-clock timer:
  /// its rate holds through sim-time jumps and while no input arrives.
  double diagnostic_period = 1.0;
  /// For the nodelet beside a driver in the same manager: the input callbacks (joint
  /// states, wrenches, plates) run at once in the thread that delivers the message (the
  /// driver's publishing thread) instead of being queued for the manager's worker
  /// threads: one thread hand-over less per sample, at the price of the estimate running
  /// in the publisher's thread. Joint states from another process (TCP) are then
  /// dropped with an error (docs/studies/speed.md "Latency: nodelet or TCP").
  bool inline_callbacks = false;
  /// The node: when the ROS master it registered with is replaced by another (a restarted
  /// roscore, which knows none of its topics), shut down (ros::requestShutdown) so that a
  /// launch file's respawn="true" starts it again, registered. False: only said (an error).
  bool exit_on_master_restart = false;
  /// [kg] effort_per_kg = effort / body_mass; 0: not published; -1: the URDF's total mass.
  double body_mass = 0.0;
  FrictionConfig friction;
  ExternalEffortConfig external_effort;
  /// The estimator's settings (the immediate stream's); estimator.joints are the joints
  /// whose loads are published.
  EstimatorConfig estimator;
  SmoothedStreamSettings smoothed;
  /// Pair by index with estimator.wrenches and estimator.plates, and by name (checked).
  std::vector<WrenchTopicSettings> wrenches;
  std::vector<PlateTopicSettings> force_plates;
};

/// Checks every model-independent setting of `config` (the differentiator, decimation,
/// gravity, savings, uncertainty, each wrench input and plate); throws SettingsError
/// naming the key. What needs the model (links and joints that exist) is checked by the
/// Estimator.
void validate(const EstimatorConfig& config);

/// The smoothed stream's estimator settings: `estimator` with the smoothed stream's filter.
EstimatorConfig smoothedEstimatorConfig(const Settings& settings);

void validate(const PlausibilityConfig& config);

/// Checks `settings`: validate(settings.estimator), the front end's own settings, and
/// that wrenches and force_plates pair with estimator.wrenches and estimator.plates (as
/// many, and element k of each names the same input or plate).
/// Throws SettingsError naming the key.
void validate(const Settings& settings);

}  // namespace jle
