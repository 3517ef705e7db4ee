// Ground truth for the accuracy study and its tests: analytic joint trajectories with
// exact derivatives, analytic external wrenches, the exact joint loads they imply, and a
// model of the sensors that sample them (rate, encoder counts, noise, time-stamp
// jitter, dropped samples, force/torque sensor bias). ROS-free; part of the test support
// library joint_load_estimator_testing (test/support, not installed).
//
// Everything is deterministic from a seed, and the same with every standard library:
// the random numbers are jle::PortableRandom's (portable_random.hpp).
#pragma once

#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace jle {

/// Seed of an independent stream number `stream` derived from `seed` (SplitMix64 of
/// seed + (stream + 1) * 0x9E3779B97F4A7C15), so that the motion and each sensor draw
/// from their own streams: changing one sensor's noise leaves the others unchanged.
std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t stream);

/// Value, rate and second derivative of one coordinate at one time [rad or m, /s, /s^2].
struct CoordinateState {
  double q = 0.0;
  double qd = 0.0;
  double qdd = 0.0;
};

/// amplitude * sin(omega t + phase).
struct Sine {
  double amplitude = 0.0;  ///< [rad or m]
  double omega = 0.0;      ///< [rad/s]
  double phase = 0.0;      ///< [rad]
};

/// A rise by `height` from `start` to start + duration along the degree-7 smoothstep
/// S(s) = 35 s^4 - 84 s^5 + 70 s^6 - 20 s^7, s = (t - start) / duration (the minimum-snap
/// profile): rate, acceleration and jerk are zero at both ends, so a sequence of steps
/// is C3 and |d4q/dt4| <= 840 |height| / duration^4 everywhere, knots included.
struct SmoothStep {
  double start = 0.0;     ///< [s]
  double duration = 1.0;  ///< [s], > 0
  double height = 0.0;    ///< [rad or m]
};

/// A box of constant acceleration: q'' = accel on [start, start + duration), 0 elsewhere,
/// q and q' continuous. Its two edges are steps in acceleration (an impact: the rate
/// changes by accel * duration within `duration`); q'' is right-continuous at them.
struct AccelPulse {
  double start = 0.0;     ///< [s]
  double duration = 0.0;  ///< [s], > 0
  double accel = 0.0;     ///< [rad/s^2 or m/s^2]
};

/// One coordinate's motion, analytic with exact derivatives:
///   q(t) = p0 + p1 t + p2 t^2 + sum of sines + sum of steps + sum of pulses.
struct CoordinateMotion {
  double p0 = 0.0;  ///< [rad or m]
  double p1 = 0.0;  ///< [rad/s or m/s]
  double p2 = 0.0;  ///< [rad/s^2 or m/s^2]
  std::vector<Sine> sines;
  std::vector<SmoothStep> steps;
  std::vector<AccelPulse> pulses;

  CoordinateState at(double t) const;
};

/// The families of randomMotion(). Ranges are for revolute coordinates [rad]; those of
/// prismatic coordinates are scaled by kPrismaticScale [m/rad].
enum class MotionKind : std::uint8_t {
  /// 2 or 3 sines (equally likely): amplitude in [0.05, 0.3), frequency in [0.1, 0.6) Hz,
  /// phase in [0, 2 pi); p0 in [-0.5, 0.5).
  kSines,
  /// p0 in [-0.5, 0.5), then smooth steps back to back from t = 0 until the duration is
  /// covered, each coordinate on its own schedule: per step a duration in [0.6, 1.5) s
  /// and a target in p0 + [-0.4, 0.4) (so |height| < 0.8 and q stays within p0 +- 0.4).
  kRamps,
  /// Holds and moves alternating, shared by all coordinates (so the robot is entirely
  /// at rest during a hold): holds in [0.2, 0.8) s (the first at t = 0), moves in
  /// [0.6, 1.5) s. Per coordinate p0 as above, then a target in p0 + [-0.4, 0.4) per move.
  kStopAndGo,
  /// A quadratic: p0 in [-0.5, 0.5), p1 in [-0.5, 0.5) /s, p2 in [-0.5, 0.5) /s^2.
  kQuadratic,
  /// Swings that end in an impact, shared by all coordinates (a collision, a heel
  /// strike): a hold in [0.2, 0.8) s at t = 0, then per cycle an acceleration phase of
  /// [0.2, 0.5) s, a coast of [0.1, 0.4) s, an impact of [0.01, 0.03) s (the rate falls
  /// to 0: q'' steps to -speed / impact and back) and a hold of [0.3, 1) s, each drawn
  /// in that order while the time is below the duration. Per coordinate p0 in
  /// [-0.5, 0.5), the first direction (+ if uniform < 0.5), then per cycle a speed in
  /// [0.2, 0.8) rad/s, the direction alternating (AccelPulse: accel = speed / phase).
  kImpacts,
  /// As kStopAndGo with long still phases: holds in [2, 5) s (the first at t = 0).
  kLongHolds,
};

constexpr double kPrismaticScale = 0.1;  ///< [m/rad] prismatic motion per revolute range

/// A random motion of every coordinate of `model` over [0, duration] (model order,
/// size nq). Draw order: for each coordinate in turn, the parameters in the order they
/// are listed in MotionKind (kStopAndGo draws its shared schedule first: hold, then
/// move and hold alternately while the time is below the duration).
std::vector<CoordinateMotion> randomMotion(const Model<double>& model, MotionKind kind,
                                           double duration, std::uint64_t seed);

/// A contact's stance: from `start` the wrench `peak` times
/// min(1, s / rise) sin(pi s / duration), s = t - start in [0, duration], 0 elsewhere:
/// a fast linear rise (a heel strike) into a half sine, continuous, its rate stepping.
struct Stance {
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  double start = 0.0;              ///< [s]
  double rise = 0.01;              ///< [s], > 0
  double duration = 0.2;           ///< [s], > rise
  Vector6 peak = Vector6::Zero();  ///< (force [N], moment [N m]), the link's frame
};

/// A wrench applied TO the robot at the origin of URDF link `link`, expressed in that
/// link's frame. Component c of (fx, fy, fz, mx, my, mz) is
///   mean[c] + amplitude[c] sin(omega[c] t + phase[c]) + the stances'   [N or N m].
struct WrenchMotion {
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  std::string link;
  Vector6 mean = Vector6::Zero();
  Vector6 amplitude = Vector6::Zero();
  Vector6 omega = Vector6::Zero();  ///< [rad/s]
  Vector6 phase = Vector6::Zero();  ///< [rad]
  std::vector<Stance> stances;

  /// (force [N], moment [N m]) at time t [s].
  Vector6 at(double t) const;
};

/// A random wrench at `link`: per component, in the order fx .. mz, mean in [-10, 10) N
/// and amplitude in [0, 10) N for forces ([-1, 1) and [0, 1) N m for moments), frequency
/// in [0.1, 1) Hz, phase in [0, 2 pi).
WrenchMotion randomWrench(const std::string& link, std::uint64_t seed);

/// The stream of GroundTruth::sample's bursts and gaps (beyond any wrench input's).
constexpr std::uint64_t kDefectStream = 1000;
/// The stream of the coloured position noise and the vibration line's phases.
constexpr std::uint64_t kColouredStream = 1001;

/// What the sensors of a scene report, and how they err.
struct SensorModel {
  double rate = 1000.0;  ///< joint samples per second [Hz]; sample k at k / rate
  /// Encoder counts per revolution of revolute coordinates (reading = nearest count);
  /// 0: no quantisation. 2^17 counts: 4.79e-5 rad per count.
  double counts_per_revolution = 0.0;
  double prismatic_resolution = 0.0;  ///< [m] per count of prismatic coordinates; 0: none
  /// Standard deviation of white Gaussian noise on the positions [rad or m] (added
  /// before quantisation, as a vibrating shaft seen through an encoder) and on the
  /// velocities [rad/s or m/s] (reported, not used by the Estimator).
  double position_noise = 0.0;
  double velocity_noise = 0.0;
  /// Coloured position noise [rad or m], standard deviation: white Gaussian noise through
  /// a 2nd-order Butterworth low-pass at coloured_corner (flat below the corner, its
  /// power falling as f^-4 above), one independent sequence per coordinate at every
  /// sample instant k / rate (lost samples included), added to position_noise's.
  /// coloured_corner [Hz] at or above rate / 2: white.
  double coloured_noise = 0.0;
  double coloured_corner = 50.0;
  /// A vibration line on every position: vibration_amplitude [rad or m]
  /// sin(2 pi vibration_frequency [Hz] t + phase), the phase per coordinate uniform.
  double vibration_amplitude = 0.0;
  double vibration_frequency = 0.0;
  /// Standard deviation [s] of the sampling instants about k / rate; the stamps report
  /// the instants exactly (irregular sampling). Truncated at +-0.2 / rate.
  double sample_jitter = 0.0;
  /// Standard deviation [s] of the stamp's error against the instant the sample was
  /// taken (a stamp taken on receipt). Truncated at +-0.2 / rate, so stamps stay in order.
  double stamp_jitter = 0.0;
  double drop_probability = 0.0;  ///< probability that a joint sample is lost
  /// Bursts of stamp jitter: at each sample a burst of burst_length samples starts with
  /// probability burst_probability (unless one is running); within it the stamp error
  /// has standard deviation burst_stamp_jitter [s] instead of stamp_jitter (same
  /// truncation).
  double burst_probability = 0.0;
  int burst_length = 20;
  double burst_stamp_jitter = 0.0;
  /// Gaps: at each sample after a kept one a run of 1 .. max_gap lost samples (uniform)
  /// starts with probability gap_probability; a gap of n samples spaces the readings
  /// around it n + 1 periods apart (with drop_probability 0: gaps never join).
  double gap_probability = 0.0;
  int max_gap = 9;

  /// Force/torque inputs: samples at wrench_offset + j / wrench_rate, stamped exactly.
  double wrench_rate = 0.0;                              ///< [Hz]; 0: the joint rate
  double wrench_offset = 0.0;                            ///< [s] the first sample's time
  double force_noise = 0.0;                              ///< standard deviation per component [N]
  double moment_noise = 0.0;                             ///< standard deviation per component [N m]
  Eigen::Vector3d force_bias = Eigen::Vector3d::Zero();  ///< added to every sample [N]
  Eigen::Vector3d moment_bias = Eigen::Vector3d::Zero();  ///< [N m]
  double wrench_drop_probability = 0.0;
};

/// A joint-state sample as a sensor reports it.
struct JointReading {
  double stamp = 0.0;  ///< reported time [s]
  double time = 0.0;   ///< instant the sample was taken [s] (stamp minus its error)
  VectorX<double> q;   ///< size nq, model.coordinate_names order
  VectorX<double> qd;  ///< size nq
};

/// A force/torque sample of wrench input `input` (index into GroundTruth::wrenches()),
/// in the link's frame, applied to the robot.
struct WrenchReading {
  int input = 0;
  double stamp = 0.0;                                ///< [s]
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< [N]
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  ///< [N m]
};

/// Everything the sensors report over a run; both lists in increasing stamp order
/// (wrench readings of equal stamps by input).
struct SensorReadings {
  std::vector<JointReading> joints;
  std::vector<WrenchReading> wrenches;
};

/// A scene's truth: the model, its coordinates' motion and the applied wrenches, from
/// which the exact joint loads follow at any time.
class GroundTruth {
 public:
  /// motion has one entry per coordinate (model.nq); every wrench's link must exist
  /// (std::invalid_argument otherwise, naming it). Fixed-base models only.
  GroundTruth(Model<double> model, std::vector<CoordinateMotion> motion,
              std::vector<WrenchMotion> wrenches,
              const Eigen::Vector3d& gravity_world = Eigen::Vector3d(0.0, 0.0, -9.80665));

  const Model<double>& model() const { return model_; }
  const std::vector<CoordinateMotion>& motion() const { return motion_; }
  const std::vector<WrenchMotion>& wrenches() const { return wrenches_; }
  const Eigen::Vector3d& gravity() const { return gravity_world_; }

  /// Exact q, qd, qdd at time t (resized to nq).
  void coordinates(double t, VectorX<double>& q, VectorX<double>& qd, VectorX<double>& qdd) const;

  /// Exact loads at time t into data (which must be built from model()): the core's
  /// forwardKinematics with the exact q, qd, qdd, every wrench through addExternalWrench
  /// (link frame), then inverseDynamics. data.force/moment/effort are the truth.
  void loads(double t, Data<double>& data) const;

  /// The readings of `sensor` over [0, duration] [s]. Draw order, joint stream
  /// (deriveSeed(seed, 0)): per sample k, the drop draw (uniform), the sample jitter and
  /// the stamp jitter (gaussians), then per coordinate the position and velocity noise
  /// (gaussians); all drawn whether or not used. Wrench input i draws from stream i + 1:
  /// per sample, the drop draw, then the six noises fx .. mz. Bursts and gaps draw from
  /// stream kDefectStream, per sample: the burst start (uniform), the gap start
  /// (uniform), the gap length (index) and the burst's stamp error (gaussian); so a scene
  /// without them reads as before they existed. Coloured noise and the vibration line draw
  /// from stream kColouredStream: the phases (one uniform per coordinate), then per
  /// coordinate its gaussians (a warm-up of the shaping filter first, then one per sample).
  SensorReadings sample(const SensorModel& sensor, double duration, std::uint64_t seed) const;

 private:
  std::vector<JointReading> sampleJoints(const SensorModel& sensor, double duration,
                                         std::uint64_t seed) const;
  std::vector<WrenchReading> sampleWrenches(const SensorModel& sensor, double duration,
                                            std::uint64_t seed) const;

  Model<double> model_;
  std::vector<CoordinateMotion> motion_;
  std::vector<WrenchMotion> wrenches_;
  std::vector<int> wrench_frames_;
  std::vector<bool> prismatic_;  // per coordinate
  Eigen::Vector3d gravity_world_;
};

/// A planar arm: links base, link1, link2, link3, tip; revolute joints joint1..joint3,
/// all about y; link lengths 0.5, 0.4, 0.3 m along x; thin rods of 3, 2, 1 kg with their
/// centre of mass at mid-length; tip fixed at the end of link3. With gravity along -z
/// and loads in the x-z plane (forces in x and z, moments about y) everything stays in
/// that plane: the joint forces have no y component and the moments only a y component.
std::string planarArmUrdf();

/// A planar leg hanging from a fixed pelvis: links pelvis, thigh, shank, foot; revolute
/// joints hip, knee, ankle, all about y; thigh 0.42 m and 7 kg, shank 0.42 m and 3.2 kg
/// (thin rods along -z, centre of mass at 43% of the length from the proximal joint),
/// foot 1.1 kg with its centre of mass 0.05 m ahead (+x) of the ankle and
/// I_yy = 0.004 kg m^2. Loads in the x-z plane keep everything in that plane.
std::string planarLegUrdf();

/// A random tree of `links` moving links (link1..linkN, under the massive root link0),
/// seeded: each link's parent is uniform among the links before it (so linkN is a
/// leaf), its joint revolute (7 in 8) or prismatic, about a uniformly random axis, with
/// a random origin (xyz in [-0.3, 0.3) m, rpy in [-pi, pi)). One link in 6 is massless;
/// the others are boxes of mass [0.2, 5) kg and sides [0.05, 0.4) m, centre of mass at
/// xyz in [-0.15, 0.15) m, principal axes at random rpy.
std::string randomTreeUrdf(std::uint64_t seed, int links);

}  // namespace jle
