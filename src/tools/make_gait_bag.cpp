// make_gait_bag: a deterministic, gait-like walking trial of a human body model over
// two force plates, as a bag, for the gait demo (docs/gait_demo.md) and its test. The
// plate signals are computed from the model's own inverse dynamics, so that the
// floating-base residual of the estimate is filter error only. The formulas are in
// kUsage and docs/gait_demo.md.
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/io/csv.hpp>
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include "bag_writing.hpp"

#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace jle::cli;  // command_line.hpp: UsageError, optionValues, the parsers
using Eigen::Matrix3d;
using Eigen::Vector3d;

const char* const kUsage =
    R"(usage: make_gait_bag --urdf BODY.urdf --output OUT.bag [--strides 3] [--noise 0]
                     [--seed 1]

Writes a bag of a body walking at 1.1 m/s, 114 steps/min, over two force plates (lanes side by side:
plate 1 under the right foot, plate 2 under the left; each foot lands on its own plate
at every step), for the gait demo (docs/gait_demo.md):
  /joint_states         sensor_msgs/JointState, 200 Hz, positions of every coordinate
                        of the URDF (the mocap's joint angles; legs: hip_flexion_s,
                        hip_adduction_s, hip_rotation_s, knee_flexion_s,
                        ankle_flexion_s, s = r, l; any other coordinate stays 0)
  /tf                   world -> pelvis (the mocap's pelvis pose), 200 Hz; world ->
                        force_plate_N_cop (where the ground reaction acts), 100 Hz
  /tf_static            world -> force_plate_1, world -> force_plate_2 (latched)
  /force_plate_N/wrench geometry_msgs/WrenchStamped, 1 kHz, frame force_plate_N: what
                        the foot applies TO the plate, moment about the plate origin
                        (the plate frame: origin at the centre of the surface, z up)
  /force_plate_N/reaction  geometry_msgs/WrenchStamped, 100 Hz, frame
                        force_plate_N_cop: the ground reaction on the foot at its centre
                        of pressure (world axes) and the free moment, for display
stamped t0 + i / rate (t0 = 1000 s); bag time = stamp for the joint states, stamp - 2
ms for the poses and the plates (a reader in time order has the pose and the plate
samples of an instant before its joint state).

The trial (gait time g = t + 0.315 s, stride T = 1.05 s, w = 2 pi / T; the right heel
strikes at g = 0, the left at T/2; stance 60 %, double support 2 x 10 %):
  pelvis  x = 1.1 g - 0.016 sin(2w (g - 0.3T)) + dx(g), y = -0.03 cos(w (g - 0.3T)) + dy(g),
          z(g), yaw = 0.07 cos(w g), roll = -0.05 sin(w g); dx, dy: Fourier series of
          period T, 20 harmonics, solved (20 fixed-point steps relaxed by 0.5, each
          harmonic scaled by the inverted pendulum's 1 / (1 + (z_com / g) (k w)^2); the
          step of the smallest miss kept) so that the centre of pressure of the model's
          inverse dynamics follows the plan below; z: fitted at each step (2 harmonics)
          to the height that gives the stance knee its planned flexion (5 deg at heel
          strike, 18 deg at 12 %, 5 deg from 40 to 50 %, 40 deg at toe off; in double
          support the two legs' heights blended by the force's split), then lowered by
          its largest excess over the height at which a stance leg's knee would
          straighten beyond 15 deg
  centre of pressure  single support: along the stance footprint from the heel (10 %)
          to 0.74 of heel -> toe (30 %) by a quintic smooth step, then there; double
          support: from the trailing foot (its point moving on to its toe as it
          unloads) to the leading heel by the split's smooth step
  feet    heel rocker (0 - 10 %: the foot turns down about the heel from 24 deg toe
          up), foot flat (10 - 35 %), forefoot rocker (35 - 60 %: the heel rises, the
          foot turns about its metatarsal heads, 0.75 of heel -> toe, to 50 deg, by
          S(s) + 3 (-4 s^3 + 7 s^4 - 3 s^5): it leaves the ground turning at 3 times
          the rocker's mean rate); the other motions quintic smooth steps
          S(s) = 10 s^3 - 15 s^4 + 6 s^5; footprints 0.5775 m apart, 5 deg toe-out,
          the heels at 0.6 times their standing distance from the midline
  joints  in stance, the leg's 5 angles that put heel_s and toe_s where the foot is
          (inverse kinematics to 1e-12 m on a 1 kHz grid); in swing (s = 0 at toe
          off .. 1 at heel strike), each angle on a quintic Hermite curve from its
          toe-off state to its heel-strike state (angle, velocity and acceleration, by
          one-sided 5-point differences of the stance's inverse kinematics 1 ms
          apart), plus A s^3 (1 - s)^k / max + B s^p (1 - s)^3 / max: hip flexion A
          16.57 deg, k 4.43, B 5.84 deg, p 7.39; knee A 29.18, k 5.65, B 10.51, p
          4.03; ankle A 83.12, k 5.51, B 4.66, p 3.56; velocities and
          accelerations by 5-point central differences on the grid
  plates  the wrench the world must apply to the pelvis for that motion (the model's
          floating-base inverse dynamics, gravity 0 0 -9.80665), on the stance foot; in
          double support split by a quintic smooth step of the force from the trailing
          to the leading foot, each foot's centre of pressure the nominal point (the
          trailing foot's, above; the leading heel) shifted by the same vector, so that
          the two sum to the whole wrench; free moment split like the force
  noise   with --noise SIGMA: Gaussian noise (Box-Muller on jle::PortableRandom(seed), the
          cosine of each pair) of SIGMA
          N on each force component, 0.01 SIGMA N m on each moment component

  --urdf PATH    the body (root link pelvis, the joints and links above, heel_s and
                 toe_s on the sole), e.g. test/data/urdf/body_75kg_175cm.urdf
  --output PATH  the bag; written beside PATH and renamed onto it on success only
  --csv PATH     also the same trial at 200 Hz as joint_loads' input (docs/joint_loads.md):
                 t, J.q, J.qd, J.qdd of every joint, base.x .. base.qw, base.vx .. base.wz,
                 base.ax .. base.alz (exact), plate@plate1.fx .. .mz, plate@plate2.fx ..
                 .mz (plate 1 under foot_r, plate 2 under foot_l; the plates' poses
                 are printed as joint_loads --plate options)
  --strides N    gait cycles covered, 1 .. 100 (default 3)
  --noise SIGMA  plate noise [N], >= 0 (default 0)
  --seed N       0 .. 4294967295 (default 1)
  --help         this text

Prints the trial's figures (duration, mass, peak vertical ground reaction, centre of
pressure along the footprint and its miss of the plan, inverse-kinematics error, the
lowest heel or toe from 10 to 35 % of the cycle after toe off, joint ranges).
Exit status: 0 success; 1 a data error (unreadable URDF, a body the trial does not fit,
unwritable bag); 2 a usage error.
)";

constexpr double kPi = 3.141592653589793;
constexpr std::int64_t kEpochNs = 1000000000000LL;  // t0 = 1000 s
constexpr double kGravity = 9.80665;
constexpr double kDeg = kPi / 180.0;

// The trial's parameters (kUsage; the sources of the normative ones in docs/gait_demo.md).
constexpr double kSpeed = 1.1;                    // [m/s]
constexpr double kStride = 1.05;                  // [s] 114 steps/min
constexpr double kStartPhase = 0.3;               // the trial starts at 30 % of the right cycle
constexpr double kHeelRocker = 0.10;              // end of the heel rocker, fraction of T
constexpr double kHeelOff = 0.35;                 // start of the forefoot rocker
constexpr double kToeOff = 0.60;                  // end of stance
constexpr double kHeelStrikePitch = 24.0 * kDeg;  // toe up at heel strike
constexpr double kToeOffPitch = -50.0 * kDeg;     // heel up at toe off
constexpr double kToeOut = 5.0 * kDeg;
constexpr double kToeOffRate = 3.0;  // the foot's pitch rate at toe off / the rocker's mean
constexpr double kEndStep = 1e-3;    // [s] spacing of the swing's end states' differences
constexpr double kKneeStraight = 15.0 * kDeg;  // the pelvis never straightens a knee more
constexpr int kHeightHarmonics = 2;            // of the pelvis height (1.9 Hz)
constexpr double kHeelAhead = 0.20;      // [m] heel ahead of the hip at heel strike (first guess)
constexpr double kSwayX = 0.016;         // [m] forward speed modulation (amplitude of x)
constexpr double kSwayY = 0.03;          // [m] lateral sway (amplitude of y)
constexpr double kStepWidthRatio = 0.6;  // footprint y / standing heel y
constexpr double kJointRate = 200.0;     // [Hz]
constexpr int kPlateDivisor = 5;         // plate samples per joint sample (1 kHz)
constexpr int kDisplayDivisor = 10;      // plate samples per display sample (100 Hz)
constexpr double kLaneWidth = 0.4;       // [m] each plate's width (y)
constexpr int kHarmonics = 20;           // of the pelvis path's correction (19 Hz)
// The metatarsal heads (the forefoot rocker's pivot), as a fraction of heel -> toe:
// Dempster's distal end of the foot (docs/body_model.md A3).
constexpr double kBall = 0.75;
constexpr double kCopArrival = 0.30;   // the centre of pressure reaches kCopEnd (of T)
constexpr double kCopEnd = 0.74;       // where it stays in single support, of heel -> toe
constexpr double kTrailToToe = 1.0;    // the trailing foot's share reaches its toe at toe off
constexpr int kPelvisIterations = 20;  // of solvePelvis
constexpr double kRelaxation = 0.5;    // of its steps

// The swing's shape (placeLeg): two bumps added to the curve of a leg coordinate,
// early * s^3 (1 - s)^tail / max and late * s^power (1 - s)^3 / max, the peaks at
// 3 / (3 + tail) and power / (power + 3) of the swing. Their values were searched
// (docs/gait_demo.md) for joint moments inside the ranges of normal walking with the
// heel and toe at least 1 cm above the floor in mid-swing.
struct SwingBump {
  int joint;           // in Leg::coordinate: 0 hip flexion, 3 knee, 4 ankle
  double early, tail;  // [deg], exponent
  double late, power;  // [deg], exponent
};
constexpr std::array<SwingBump, 3> kSwingBumps = {
    {{0, 16.57, 4.43, 5.84, 7.39}, {3, 29.18, 5.65, 10.51, 4.03}, {4, 83.12, 5.51, 4.66, 3.56}}};

struct Options {
  std::string urdf, output;
  std::string csv;  // the same trial for joint_loads; empty: none
  int strides = 3;
  double noise = 0.0;
  std::uint32_t seed = 1;
};

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v =
      optionValues(argc, argv, {"--urdf", "--output", "--csv", "--strides", "--noise", "--seed"});
  Options options;
  options.urdf = requiredValue(v, "--urdf", "BODY.urdf");
  options.output = requiredValue(v, "--output", "OUT.bag");
  if (v.count("--csv")) options.csv = v["--csv"];
  if (v.count("--strides"))
    options.strides = static_cast<int>(parseInteger("--strides", v["--strides"], 1, 100));
  if (v.count("--noise")) options.noise = parseNumber("--noise", v["--noise"], Sign::kNonNegative);
  if (v.count("--seed"))
    options.seed =
        static_cast<std::uint32_t>(parseInteger("--seed", v["--seed"], 0, 4294967295ULL));
  return options;
}

// Quintic smooth step: 0 at 0, 1 at 1, first and second derivatives 0 at both ends.
double smoothStep(double s) {
  s = std::min(1.0, std::max(0.0, s));
  return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
}

// The forefoot rocker's pitch profile: 0 at s = 0 with zero first and second derivative
// (from foot flat), 1 at s = 1 with the rate kToeOffRate (the foot leaves the ground
// turning, so that it does not linger behind the body in early swing) and no second
// derivative: the quintic S(s) + kToeOffRate (-4 s^3 + 7 s^4 - 3 s^5).
double rockerStep(double s) {
  s = std::min(1.0, std::max(0.0, s));
  return smoothStep(s) + kToeOffRate * s * s * s * (-4.0 + 7.0 * s - 3.0 * s * s);
}

// A bump over s in [0, 1]: s^p (1 - s)^r scaled to a peak of 1 (at p / (p + r)); with
// p, r >= 3 zero with its first and second derivatives at both ends.
double bump(double s, double p, double r) {
  const double peak = p / (p + r);
  return std::pow(s, p) * std::pow(1.0 - s, r) / (std::pow(peak, p) * std::pow(1.0 - peak, r));
}

// Quintic Hermite curve over a duration d [s] at s = t / d in [0, 1]: from x0 with
// velocity v0 and acceleration a0 to x1 with v1 and a1.
double hermite5(double x0, double v0, double a0, double x1, double v1, double a1, double s,
                double d) {
  const double s2 = s * s, s3 = s2 * s, s4 = s3 * s, s5 = s4 * s;
  const double h0 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5;
  const double h1 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5;
  const double h2 = 0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5;
  const double h3 = 0.5 * s3 - s4 + 0.5 * s5;
  const double h4 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5;
  return x0 * h0 + x1 * (1.0 - h0) + d * (v0 * h1 + v1 * h4) + d * d * (a0 * h2 + a1 * h3);
}

// Pelvis pose, twist and acceleration at gait time g (kUsage), world frame.
// The correction of the pelvis path, a Fourier series of period T in gait time,
// d(g) = sum_k a_k cos(k w g) + b_k sin(k w g), k = 0 .. kHarmonics: its x and y solved
// by solvePelvis so that the centre of pressure follows the planned one, its z (the
// pelvis height itself) fitted by fitHeight to the planned stance knee.
struct Correction {
  std::array<Vector3d, kHarmonics + 1> a{}, b{};
  Correction() {
    for (int k = 0; k <= kHarmonics; ++k) a[k].setZero(), b[k].setZero();
  }
  // Value, first and second derivative at gait time g.
  void at(double g, Vector3d& d, Vector3d& d1, Vector3d& d2) const {
    const double w = 2.0 * kPi / kStride;
    d = a[0];
    d1.setZero();
    d2.setZero();
    for (int k = 1; k <= kHarmonics; ++k) {
      const double wk = k * w, c = std::cos(wk * g), s = std::sin(wk * g);
      d += a[k] * c + b[k] * s;
      d1 += wk * (b[k] * c - a[k] * s);
      d2 -= wk * wk * (a[k] * c + b[k] * s);
    }
  }
};

struct Pelvis {
  double x_offset = 0.0;
  Correction correction;
  jle::BaseState<double> at(double g) const {
    const double w = 2.0 * kPi / kStride, w2 = 2.0 * w;
    const double c = g - kStartPhase * kStride;
    Vector3d d, d1, d2;
    correction.at(g, d, d1, d2);
    jle::BaseState<double> b;
    b.p_world_base = Vector3d(x_offset + kSpeed * g - kSwayX * std::sin(w2 * c),
                              -kSwayY * std::cos(w * c), 0.0) +
                     d;
    b.v_world =
        Vector3d(kSpeed - kSwayX * w2 * std::cos(w2 * c), kSwayY * w * std::sin(w * c), 0.0) + d1;
    b.a_world =
        Vector3d(kSwayX * w2 * w2 * std::sin(w2 * c), kSwayY * w * w * std::cos(w * c), 0.0) + d2;
    const double yaw = 0.07 * std::cos(w * g), yaw_d = -0.07 * w * std::sin(w * g),
                 yaw_dd = -0.07 * w * w * std::cos(w * g);
    const double roll = -0.05 * std::sin(w * g), roll_d = -0.05 * w * std::cos(w * g),
                 roll_dd = 0.05 * w * w * std::sin(w * g);
    const Matrix3d Rz = Eigen::AngleAxisd(yaw, Vector3d::UnitZ()).toRotationMatrix();
    b.R_world_base = Rz * Eigen::AngleAxisd(roll, Vector3d::UnitX()).toRotationMatrix();
    // R = Rz(yaw) Rx(roll): omega = yaw' z + roll' Rz x.
    const Vector3d x_rot = Rz * Vector3d::UnitX();
    b.omega_world = yaw_d * Vector3d::UnitZ() + roll_d * x_rot;
    b.alpha_world = yaw_dd * Vector3d::UnitZ() + roll_dd * x_rot +
                    (yaw_d * Vector3d::UnitZ()).cross(roll_d * x_rot);
    return b;
  }
};

// A leg's coordinates and sole frames.
struct Leg {
  char side = 'r';
  double y_sign = -1.0;        // -1 right, +1 left
  double strike_offset = 0.0;  // gait time of its first heel strike in the cycle [s]
  std::array<int, 5> coordinate{};
  int heel = 0, toe = 0;                   // frame indices
  double y_footprint = 0.0;                // [m] heel's y at standing (footprints' lateral place)
  double foot_length = 0.0;                // [m] heel to toe
  Vector3d hip_pelvis = Vector3d::Zero();  // [m] hip joint centre in the pelvis frame
  double thigh = 0.0, shank = 0.0;         // [m] hip to knee, knee to ankle
  Vector3d ankle_heel = Vector3d::Zero();  // [m] ankle from the heel in footAxes
};

// Heel and toe points of a leg at gait time g, and whether it is in stance; also the
// time since its last heel strike [s].
struct FootState {
  Vector3d heel, toe;
  Vector3d print_heel, print_toe;  // in stance: the footprint's heel and toe (z = 0)
  Vector3d print_ball;             // and its metatarsal heads (kBall of heel -> toe)
  bool stance = false;
  double since_strike = 0.0;
  double strike = 0.0;  // gait time of the heel strike that started this cycle [s]
};

struct Gait {
  double hip_x = 0.0;  // hip joint's x at standing, relative to the pelvis origin
  double x_offset = 0.0;

  Vector3d direction(const Leg& leg, double pitch) const {
    const double yaw = leg.y_sign * kToeOut;
    return Vector3d(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                    std::sin(pitch));
  }
  // Heel at heel strike number n (gait time n T + offset).
  Vector3d footprint(const Leg& leg, double strike_time) const {
    return Vector3d(x_offset + kSpeed * strike_time + hip_x + kHeelAhead, leg.y_footprint, 0.0);
  }

  // The foot at gait time g: in stance its heel and toe; in swing (stance false) the
  // leg's angles come from placeLeg's curves, and heel and toe are NaN.
  FootState at(const Leg& leg, double g) const {
    const double n = std::floor((g - leg.strike_offset) / kStride);
    const double strike = n * kStride + leg.strike_offset;
    const double tau = g - strike;
    if (tau < kToeOff * kStride) return stanceAt(leg, strike, tau);
    FootState f = stanceAt(leg, strike, 0.0);
    f.heel = f.toe = Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    f.stance = false;
    f.since_strike = tau;
    return f;
  }

  // The stance foot of the cycle that started with the heel strike at gait time strike,
  // tau [s] after it, 0 <= tau <= toe off (toe off included: the swing starts from it).
  FootState stanceAt(const Leg& leg, double strike, double tau) const {
    const double T = kStride;
    const Vector3d H = footprint(leg, strike);
    const double l = leg.foot_length;
    FootState f;
    f.since_strike = tau;
    f.strike = strike;
    f.stance = true;
    f.print_heel = H;
    f.print_toe = H + l * direction(leg, 0.0);
    f.print_ball = H + kBall * l * direction(leg, 0.0);
    const double t1 = kHeelRocker * T, t2 = kHeelOff * T, t3 = kToeOff * T;
    if (tau < t1) {  // heel rocker: pitch = p_hs (1 - S(s)) about the heel
      f.heel = H;
      f.toe = H + l * direction(leg, kHeelStrikePitch * (1.0 - smoothStep(tau / t1)));
    } else if (tau < t2) {
      f.heel = H;
      f.toe = H + l * direction(leg, 0.0);
    } else {  // forefoot rocker: pitch = p_to R(s) about the metatarsal heads
      const Vector3d u =
          direction(leg, kToeOffPitch * rockerStep(std::min(1.0, (tau - t2) / (t3 - t2))));
      f.heel = f.print_ball - kBall * l * u;
      f.toe = f.print_ball + (1.0 - kBall) * l * u;
    }
    return f;
  }
};

// A foot's axes from its heel and toe points: along the sole (heel to toe), to the left
// and horizontal, and their cross product (up from the sole); as columns.
Matrix3d footAxes(const Vector3d& heel, const Vector3d& toe) {
  const Vector3d u = (toe - heel).normalized();
  const Vector3d v = Vector3d::UnitZ().cross(u).normalized();
  Matrix3d axes;
  axes << u, v, u.cross(v);
  return axes;
}

// The planned knee flexion [rad] of a leg at fraction s of its cycle since heel strike,
// stance only (J. Perry, J. M. Burnfield, Gait Analysis, 2nd ed., 2010, the knee's
// curve): about 5 deg at initial contact, 18 deg at the end of the loading response
// (12 %), 5 deg from terminal stance (40 %) to the other foot's heel strike (50 %), 40
// deg at toe off (60 %); quintic smooth steps between.
double plannedKnee(double s) {
  const double deg = kPi / 180.0;
  if (s < 0.12) return (5.0 + 13.0 * smoothStep(s / 0.12)) * deg;
  if (s < 0.40) return (18.0 - 13.0 * smoothStep((s - 0.12) / 0.28)) * deg;
  if (s < 0.50) return 5.0 * deg;
  return (5.0 + 35.0 * smoothStep((s - 0.50) / (kToeOff - 0.50))) * deg;
}

// The pelvis height [m] that bends the leg's knee to knee [rad] with its foot where foot
// has it, the pelvis horizontally where base has it and turned as base: the hip-to-ankle
// distance depends on the knee alone (the three hip axes meet at the joint centre, the
// knee's is across the thigh and the shank).
double heightForKnee(const Leg& leg, const FootState& foot, const jle::BaseState<double>& base,
                     double knee) {
  const Vector3d ankle = foot.heel + footAxes(foot.heel, foot.toe) * leg.ankle_heel;
  const Vector3d hip = Vector3d(base.p_world_base.x(), base.p_world_base.y(), 0.0) +
                       base.R_world_base * leg.hip_pelvis;
  const double reach2 =
      leg.thigh * leg.thigh + leg.shank * leg.shank + 2.0 * leg.thigh * leg.shank * std::cos(knee);
  const double flat2 = (hip - ankle).head<2>().squaredNorm();
  return ankle.z() - hip.z() + std::sqrt(std::max(reach2 - flat2, 0.0));
}

Vector3d framePosition(const jle::Model<double>& model, const jle::Data<double>& data, int frame) {
  const jle::Frame<double>& f = model.frames[static_cast<std::size_t>(frame)];
  const std::size_t s = static_cast<std::size_t>(f.segment);
  return data.p_world[s] + data.R_world[s] * f.p_segment_frame;
}

// Puts the leg's heel and toe frames on the targets (Gauss-Newton, numerical Jacobian,
// damped); q holds the start and receives the solution. Returns the remaining error [m].
double solveLegFrom(const jle::Model<double>& model, jle::Data<double>& data, const Leg& leg,
                    const jle::BaseState<double>& base, const Vector3d& heel, const Vector3d& toe,
                    jle::VectorX<double>& q) {
  const jle::VectorX<double> zero = jle::VectorX<double>::Zero(model.nq);
  const Vector3d gravity(0.0, 0.0, -kGravity);
  auto error = [&](const jle::VectorX<double>& qq) {
    jle::forwardKinematics(model, data, qq, zero, zero, gravity, base);
    Eigen::Matrix<double, 6, 1> e;
    e << framePosition(model, data, leg.heel) - heel, framePosition(model, data, leg.toe) - toe;
    return e;
  };
  double norm = 0.0;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const Eigen::Matrix<double, 6, 1> e = error(q);
    norm = e.norm();
    if (norm < 1e-13) break;
    Eigen::Matrix<double, 6, 5> J;
    for (int j = 0; j < 5; ++j) {
      jle::VectorX<double> qq = q;
      const double h = 1e-7;
      qq[leg.coordinate[static_cast<std::size_t>(j)]] += h;
      J.col(j) = (error(qq) - e) / h;
    }
    const Eigen::Matrix<double, 5, 5> A =
        J.transpose() * J + 1e-12 * Eigen::Matrix<double, 5, 5>::Identity();
    Eigen::Matrix<double, 5, 1> step = A.ldlt().solve(-J.transpose() * e);
    // A trust region: far from the solution, small steps keep the knee on its branch.
    if (step.norm() > 0.1) step *= 0.1 / step.norm();
    for (int j = 0; j < 5; ++j) q[leg.coordinate[static_cast<std::size_t>(j)]] += step[j];
    // The knee bends one way only (flexion positive): never onto the mirrored branch.
    double& knee = q[leg.coordinate[3]];
    knee = std::max(knee, 0.0);
    if (step.norm() < 1e-15) break;
  }
  return norm;
}

// solveLegFrom from q; where that stalls (a knee gone straight has no gradient to bend
// it again), once more from the knee bent by 0.5 rad, keeping the better solution.
double solveLeg(const jle::Model<double>& model, jle::Data<double>& data, const Leg& leg,
                const jle::BaseState<double>& base, const Vector3d& heel, const Vector3d& toe,
                jle::VectorX<double>& q) {
  jle::VectorX<double> start = q;
  const double norm = solveLegFrom(model, data, leg, base, heel, toe, q);
  if (norm < 1e-10) return norm;
  start[leg.coordinate[3]] = 0.5;
  const double again = solveLegFrom(model, data, leg, base, heel, toe, start);
  if (again >= norm) return norm;
  q = start;
  return again;
}

// A leg's 5 coordinates at one instant, with their first two time derivatives.
struct LegState {
  Eigen::Matrix<double, 5, 1> q, qd, qdd;
};

// The leg at an end of a stance phase: at its toe off (side -1, from the stance's last 5
// instants) or at its heel strike (side +1, from the first 5), the inverse kinematics at
// instants kEndStep apart and one-sided 5-point differences. q: the start of the first
// solution (not changed).
LegState stanceEnd(const jle::Model<double>& model, jle::Data<double>& data, const Leg& leg,
                   const Gait& gait, const Pelvis& pelvis, double strike, double side,
                   jle::VectorX<double> q) {
  const double tau0 = side < 0.0 ? kToeOff * kStride : 0.0;
  std::array<Eigen::Matrix<double, 5, 1>, 5> x;
  for (int k = 0; k < 5; ++k) {
    const double tau = tau0 + side * k * kEndStep;
    const FootState foot = gait.stanceAt(leg, strike, tau);
    solveLeg(model, data, leg, pelvis.at(strike + tau), foot.heel, foot.toe, q);
    for (int j = 0; j < 5; ++j) x[k][j] = q[leg.coordinate[static_cast<std::size_t>(j)]];
  }
  const double h = kEndStep;
  LegState e;
  e.q = x[0];
  e.qd = side * (-25.0 * x[0] + 48.0 * x[1] - 36.0 * x[2] + 16.0 * x[3] - 3.0 * x[4]) / (12.0 * h);
  e.qdd = (35.0 * x[0] - 104.0 * x[1] + 114.0 * x[2] - 56.0 * x[3] + 11.0 * x[4]) / (12.0 * h * h);
  return e;
}

// A leg's swing: its ends, from the stance phases either side (stanceEnd), for the swing
// that follows the heel strike at gait time strike.
struct Swing {
  double strike = std::numeric_limits<double>::quiet_NaN();
  LegState off, on;
};

// Puts a leg where the gait has it at gait time g, in q: in stance its heel and toe on
// the foot's (the inverse kinematics; returns its error [m]); in swing each coordinate on
// a quintic Hermite curve from the toe off's state to the next heel strike's (position,
// velocity and acceleration, so that the motion is smooth to the second derivative at
// both), plus kSwingBumps (returns 0). swing caches the ends for one swing; its
// pelvis path must stay that of the first call.
double placeLeg(const jle::Model<double>& model, jle::Data<double>& data, const Leg& leg,
                const Gait& gait, const Pelvis& pelvis, double g, Swing& swing,
                jle::VectorX<double>& q) {
  const FootState foot = gait.at(leg, g);
  if (foot.stance) return solveLeg(model, data, leg, pelvis.at(g), foot.heel, foot.toe, q);
  if (!(swing.strike == foot.strike)) {
    swing.strike = foot.strike;
    swing.off = stanceEnd(model, data, leg, gait, pelvis, foot.strike, -1.0, q);
    swing.on = stanceEnd(model, data, leg, gait, pelvis, foot.strike + kStride, 1.0, q);
  }
  const double d = (1.0 - kToeOff) * kStride;
  const double s = (foot.since_strike - kToeOff * kStride) / d;
  for (int j = 0; j < 5; ++j)
    q[leg.coordinate[static_cast<std::size_t>(j)]] =
        hermite5(swing.off.q[j], swing.off.qd[j], swing.off.qdd[j], swing.on.q[j], swing.on.qd[j],
                 swing.on.qdd[j], s, d);
  for (const SwingBump& b : kSwingBumps)
    q[leg.coordinate[static_cast<std::size_t>(b.joint)]] +=
        kDeg * (b.early * bump(s, 3.0, b.tail) + b.late * bump(s, b.power, 3.0));
  return 0.0;
}

int coordinateIndex(const jle::Model<double>& model, const std::string& name,
                    const std::string& urdf) {
  for (std::size_t i = 0; i < model.coordinate_names.size(); ++i)
    if (model.coordinate_names[i] == name) return static_cast<int>(i);
  throw std::runtime_error(urdf + ": no joint '" + name +
                           "' (make_gait_bag needs the body model of docs/gait_demo.md)");
}

int frameIndex(const jle::Model<double>& model, const std::string& name, const std::string& urdf) {
  for (std::size_t i = 0; i < model.frames.size(); ++i)
    if (model.frames[i].name == name) return static_cast<int>(i);
  throw std::runtime_error(urdf + ": no link '" + name +
                           "' (make_gait_bag needs the body model of docs/gait_demo.md)");
}

geometry_msgs::TransformStamped transform(const std::string& child, const ros::Time& stamp,
                                          const Vector3d& p, const Matrix3d& R) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = "world";
  t.child_frame_id = child;
  t.transform.translation.x = p.x();
  t.transform.translation.y = p.y();
  t.transform.translation.z = p.z();
  const Eigen::Quaterniond o(R);
  t.transform.rotation.x = o.x();
  t.transform.rotation.y = o.y();
  t.transform.rotation.z = o.z();
  t.transform.rotation.w = o.w();
  return t;
}

// One foot's share of the ground reaction: force [N] at the centre of pressure [m] on
// the ground (z = 0), free moment [N m] about z.
struct Share {
  bool contact = false;
  Vector3d force = Vector3d::Zero();
  Vector3d cop = Vector3d::Zero();
  double free_moment = 0.0;
};

// The trailing foot's nominal centre of pressure in double support, as the leading foot
// takes the share w_lead of the force: from its metatarsal heads towards its toes
// (kTrailToToe of the way at toe off), where the unloading foot pushes off last.
Vector3d trailingPoint(const FootState& f, double w_lead) {
  const Vector3d end = f.print_heel + kCopEnd * (f.print_toe - f.print_heel);
  return end + kTrailToToe * w_lead * (f.print_toe - end);
}

// The planned centre of pressure (ground, x y) for the feet at one instant: in single
// support along the stance footprint from the heel (at the end of the heel rocker) to
// the toe (at kCopArrival of the cycle, before the heel rises fully), by a quintic smooth
// step, then at the toe; in double support from the trailing toe to the leading heel by
// the smooth step of the force's split, so that each foot's share sits at its nominal
// point.
Eigen::Vector2d plannedCop(const std::array<FootState, 2>& feet) {
  Vector3d p;
  if (feet[0].stance && feet[1].stance) {
    const int lead = feet[0].since_strike < feet[1].since_strike ? 0 : 1;
    const double w_lead =
        smoothStep(feet[static_cast<std::size_t>(lead)].since_strike / ((kToeOff - 0.5) * kStride));
    p = (1.0 - w_lead) * trailingPoint(feet[static_cast<std::size_t>(1 - lead)], w_lead) +
        w_lead * feet[static_cast<std::size_t>(lead)].print_heel;
  } else {
    const FootState& f = feet[0].stance ? feet[0] : feet[1];
    const double u = smoothStep((f.since_strike - kHeelRocker * kStride) /
                                ((kCopArrival - kHeelRocker) * kStride));
    p = f.print_heel + u * kCopEnd * (f.print_toe - f.print_heel);
  }
  return p.head<2>();
}

// Velocities and accelerations at point c of a grid of positions (spacing h [s]) by
// 5-point central differences.
void fivePoint(const std::vector<jle::VectorX<double>>& grid, std::size_t c, double h,
               jle::VectorX<double>& qd, jle::VectorX<double>& qdd) {
  for (int j = 0; j < qd.size(); ++j) {
    const double m2 = grid[c - 2][j], m1 = grid[c - 1][j], p1 = grid[c + 1][j], p2 = grid[c + 2][j],
                 z = grid[c][j];
    qd[j] = (m2 - 8.0 * m1 + 8.0 * p1 - p2) / (12.0 * h);
    qdd[j] = (-m2 + 16.0 * m1 - 30.0 * z + 16.0 * p1 - p2) / (12.0 * h * h);
  }
}

// What the world must apply to the pelvis for the motion (the model's floating-base
// inverse dynamics): force F [N] and moment M [N m] in world axes, about the world origin.
void pelvisWrench(const jle::Model<double>& model, jle::Data<double>& data,
                  const jle::VectorX<double>& q, const jle::VectorX<double>& qd,
                  const jle::VectorX<double>& qdd, const jle::BaseState<double>& base, Vector3d& F,
                  Vector3d& M) {
  jle::forwardKinematics(model, data, q, qd, qdd, Vector3d(0.0, 0.0, -kGravity), base);
  jle::inverseDynamics(model, data);
  F = base.R_world_base * data.force[0];
  M = base.R_world_base * data.moment[0] + base.p_world_base.cross(F);
}

// One step of solvePelvis: the harmonics of the error (on the stride's grid from gait
// time g0, step h) corrected by the inverted pendulum's response.
void correctPelvis(const std::vector<Eigen::Vector2d>& error, double g0, double h, double z_com,
                   Pelvis& pelvis) {
  const double w = 2.0 * kPi / kStride;
  const int n = static_cast<int>(error.size());
  for (int m = 0; m <= kHarmonics; ++m) {
    Eigen::Vector2d A = Eigen::Vector2d::Zero(), B = Eigen::Vector2d::Zero();
    for (int k = 0; k < n; ++k) {
      const double g = g0 + k * h;
      A += error[static_cast<std::size_t>(k)] * std::cos(m * w * g);
      B += error[static_cast<std::size_t>(k)] * std::sin(m * w * g);
    }
    const double response = 1.0 + z_com / kGravity * (m * w) * (m * w);
    pelvis.correction.a[m].head<2>() += kRelaxation * (m == 0 ? 1.0 : 2.0) / n * A / response;
    pelvis.correction.b[m].head<2>() += kRelaxation * (m == 0 ? 0.0 : 2.0) / n * B / response;
  }
}

// The pelvis height wanted over the stride's grid (gait times g0 + k h, k = 0 .. n - 1)
// for the planned knee (plannedKnee): in single support the stance leg's, in double
// support the two legs' heights blended by the force's split (the trailing leg's at
// first, the leading leg's at the end); and the cap: the height that bends a stance
// leg's knee to kKneeStraight only, above which it no longer reaches its foot (the
// swing leg's angles follow their own curves, placeLeg).
void heightTargets(const std::array<Leg, 2>& legs, const Gait& gait, const Pelvis& pelvis,
                   double g0, double h, std::vector<double>& target, std::vector<double>& cap) {
  for (std::size_t k = 0; k < target.size(); ++k) {
    const double g = g0 + static_cast<double>(k) * h;
    const jle::BaseState<double> base = pelvis.at(g);
    const std::array<FootState, 2> feet = {gait.at(legs[0], g), gait.at(legs[1], g)};
    const auto height = [&](int i, double knee) {
      return heightForKnee(legs[static_cast<std::size_t>(i)], feet[static_cast<std::size_t>(i)],
                           base, knee);
    };
    const auto planned = [&](int i) {
      return height(i, plannedKnee(feet[static_cast<std::size_t>(i)].since_strike / kStride));
    };
    cap[k] = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 2; ++i)
      if (feet[static_cast<std::size_t>(i)].stance)
        cap[k] = std::min(cap[k], height(i, kKneeStraight));
    if (feet[0].stance && feet[1].stance) {
      const int lead = feet[0].since_strike < feet[1].since_strike ? 0 : 1;
      const double w_lead = smoothStep(feet[static_cast<std::size_t>(lead)].since_strike /
                                       ((kToeOff - 0.5) * kStride));
      target[k] = (1.0 - w_lead) * planned(1 - lead) + w_lead * planned(lead);
    } else {
      target[k] = planned(feet[0].stance ? 0 : 1);
    }
    target[k] = std::min(target[k], cap[k]);
  }
}

// Fits the pelvis height (the z of the correction) to heightTargets over the stride's
// grid of n points: its harmonics up to kHeightHarmonics (a smooth path: the vertical
// ground reaction is the body's vertical acceleration), then the whole path down by its
// largest overshoot of the cap, so that both legs reach their feet everywhere.
void fitHeight(const std::array<Leg, 2>& legs, const Gait& gait, double g0, double h, int n,
               Pelvis& pelvis) {
  std::vector<double> target(static_cast<std::size_t>(n)), cap(target.size());
  heightTargets(legs, gait, pelvis, g0, h, target, cap);
  const double w = 2.0 * kPi / kStride;
  for (int m = 0; m <= kHarmonics; ++m) {
    double A = 0.0, B = 0.0;
    for (std::size_t k = 0; m <= kHeightHarmonics && k < target.size(); ++k) {
      const double g = g0 + static_cast<double>(k) * h;
      A += target[k] * std::cos(m * w * g);
      B += target[k] * std::sin(m * w * g);
    }
    pelvis.correction.a[m].z() = (m == 0 ? 1.0 : 2.0) / n * A;
    pelvis.correction.b[m].z() = m == 0 ? 0.0 : 2.0 / n * B;
  }
  double overshoot = 0.0;
  for (std::size_t k = 0; k < target.size(); ++k)
    overshoot =
        std::max(overshoot, pelvis.at(g0 + static_cast<double>(k) * h).p_world_base.z() - cap[k]);
  if (overshoot > 0.0) pelvis.correction.a[0].z() -= overshoot + 1e-4;
}

// Puts the feet of both legs where the gait has them at every point of a grid (gait
// times g0 + k h, k = first .. first + grid.size() - 1); each point starts from its own
// q, or with warm from the previous point's solution.
void solveGridLegs(const jle::Model<double>& model, jle::Data<double>& data,
                   const std::array<Leg, 2>& legs, const Gait& gait, const Pelvis& pelvis,
                   double g0, double h, int first, bool warm,
                   std::vector<jle::VectorX<double>>& grid) {
  std::array<Swing, 2> swings;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const double g = g0 + (first + static_cast<int>(i)) * h;
    if (warm && i > 0) grid[i] = grid[i - 1];
    for (std::size_t l = 0; l < legs.size(); ++l)
      placeLeg(model, data, legs[l], gait, pelvis, g, swings[l], grid[i]);
  }
}

// Solves the pelvis path's horizontal correction so that the whole-body centre of
// pressure (from the model's floating-base inverse dynamics, as the plates get it)
// follows plannedCop over a stride. The trial repeats every stride (translated), so the
// problem is periodic: on the stride's 1 kHz grid the error e = planned - actual is
// expanded in the correction's harmonics and each is corrected by the linear inverted
// pendulum's response, a shift d of the pelvis moving the centre of pressure by
// d - (z_com / g) d'' (harmonic k: (1 + (z_com / g) (k w)^2) d_k). Returns the largest
// error [m] of the last evaluation.
double solvePelvis(const jle::Model<double>& model, jle::Data<double>& data,
                   const std::array<Leg, 2>& legs, const Gait& gait, Pelvis& pelvis,
                   const jle::VectorX<double>& q_start, int iterations) {
  const double h = 1.0 / (kJointRate * kPlateDivisor);
  const int n = static_cast<int>(std::lround(kStride / h));
  const double g0 = kStartPhase * kStride;
  const double mass = model.totalMass();
  std::vector<jle::VectorX<double>> grid(static_cast<std::size_t>(n + 4), q_start);
  std::vector<Eigen::Vector2d> error(static_cast<std::size_t>(n));
  jle::VectorX<double> qd(model.nq), qdd(model.nq);
  double largest = 0.0, best_error = 1e300;
  Pelvis best = pelvis;  // the path of the smallest error
  for (int iteration = 0;; ++iteration) {
    fitHeight(legs, gait, g0, h, n, pelvis);
    // Warm start: from the last solution (first: the previous sample's).
    solveGridLegs(model, data, legs, gait, pelvis, g0, h, -2, iteration == 0, grid);
    largest = 0.0;
    double z_com = 0.0;
    for (int k = 0; k < n; ++k) {
      const std::size_t c = static_cast<std::size_t>(k + 2);
      fivePoint(grid, c, h, qd, qdd);
      const double g = g0 + k * h;
      Vector3d F, M;
      pelvisWrench(model, data, grid[c], qd, qdd, pelvis.at(g), F, M);
      const Eigen::Vector2d cop(-M.y() / F.z(), M.x() / F.z());
      const std::array<FootState, 2> feet = {gait.at(legs[0], g), gait.at(legs[1], g)};
      error[static_cast<std::size_t>(k)] = plannedCop(feet) - cop;
      largest = std::max(largest, error[static_cast<std::size_t>(k)].norm());
      for (std::size_t i = 0; i < model.com.size(); ++i)
        z_com += model.mass[i] * jle::comWorld(model, data, static_cast<int>(i)).z() / (mass * n);
    }
    if (largest < best_error) best_error = largest, best = pelvis;
    if (iteration == iterations) break;
    correctPelvis(error, g0, h, z_com, pelvis);
  }
  pelvis = best;
  return best_error;
}

// The legs' coordinates and sole frames (the body model of docs/gait_demo.md).
std::array<Leg, 2> findLegs(const jle::Model<double>& model, const std::string& urdf) {
  std::array<Leg, 2> legs;
  const char* names[5] = {"hip_flexion_", "hip_adduction_", "hip_rotation_", "knee_flexion_",
                          "ankle_flexion_"};
  for (int k = 0; k < 2; ++k) {
    Leg& leg = legs[static_cast<std::size_t>(k)];
    leg.side = k == 0 ? 'r' : 'l';
    leg.y_sign = k == 0 ? -1.0 : 1.0;
    leg.strike_offset = k == 0 ? 0.0 : 0.5 * kStride;
    const std::string s(1, leg.side);
    for (int j = 0; j < 5; ++j)
      leg.coordinate[static_cast<std::size_t>(j)] = coordinateIndex(model, names[j] + s, urdf);
    leg.heel = frameIndex(model, "heel_" + s, urdf);
    leg.toe = frameIndex(model, "toe_" + s, urdf);
  }
  return legs;
}

// The standing body (q = 0, pelvis at the origin): each foot's length and footprint, its
// hip joint centre, thigh and shank lengths and its ankle's place on the foot.
void measureFeet(const jle::Model<double>& model, jle::Data<double>& data, std::array<Leg, 2>& legs,
                 const std::string& urdf) {
  const jle::VectorX<double> zero = jle::VectorX<double>::Zero(model.nq);
  jle::forwardKinematics(model, data, zero, zero, zero, Vector3d(0.0, 0.0, -kGravity));
  for (Leg& leg : legs) {
    const Vector3d heel = framePosition(model, data, leg.heel);
    const Vector3d toe = framePosition(model, data, leg.toe);
    leg.foot_length = (toe - heel).norm();
    leg.y_footprint = kStepWidthRatio * heel.y();
    const std::string s(1, leg.side);
    const auto joint = [&](const char* name) {
      return data.p_world[static_cast<std::size_t>(model.segmentOfJoint(name + s))];
    };
    const Vector3d hip = joint("hip_flexion_"), knee = joint("knee_flexion_"),
                   ankle = joint("ankle_flexion_");
    leg.hip_pelvis = hip;
    leg.thigh = (knee - hip).norm();
    leg.shank = (ankle - knee).norm();
    leg.ankle_heel = footAxes(heel, toe).transpose() * (ankle - heel);
    if (!(leg.foot_length > 0.05))
      throw std::runtime_error(urdf + ": heel_" + std::string(1, leg.side) + " and toe_" +
                               std::string(1, leg.side) + " are less than 5 cm apart");
  }
}

// The whole trial: the body, its legs, their gait, the pelvis path.
struct Trial {
  std::array<Leg, 2> legs;
  Gait gait;
  Pelvis pelvis;
  double cop_error = 0.0;  // [m] solvePelvis's
};

Trial planTrial(const jle::Model<double>& model, jle::Data<double>& data, const std::string& urdf,
                jle::VectorX<double>& q) {
  Trial trial;
  trial.legs = findLegs(model, urdf);
  measureFeet(model, data, trial.legs, urdf);
  const int hip_segment = model.segmentOfJoint("hip_flexion_r");
  trial.gait.hip_x = data.p_world[static_cast<std::size_t>(hip_segment)].x();
  trial.gait.x_offset = trial.pelvis.x_offset = 0.0;
  // Knees slightly bent: the inverse kinematics stays on the bent-knee branch.
  q = jle::VectorX<double>::Zero(model.nq);
  for (const Leg& leg : trial.legs) q[leg.coordinate[3]] = 0.3;
  trial.cop_error =
      solvePelvis(model, data, trial.legs, trial.gait, trial.pelvis, q, kPelvisIterations);
  return trial;
}

// The joint positions of the trial on the 1 kHz grid, with two points either side for
// the 5-point differences: point c = k + 2 is gait time g0 + k h.
struct Grid {
  double h = 1.0 / (kJointRate * kPlateDivisor);
  double g0 = kStartPhase * kStride;
  long long samples = 0;  // k = 0 .. samples - 1
  std::vector<jle::VectorX<double>> q;
  double ik_error = 0.0;   // [m]
  double clearance = 1e9;  // [m] the lowest heel or toe from 10 to 35 % of T after toe off
};

Grid solveGrid(const jle::Model<double>& model, jle::Data<double>& data, const Trial& trial,
               int strides, jle::VectorX<double> q, const std::string& urdf) {
  Grid grid;
  grid.samples = std::llround(strides * kStride / grid.h);
  grid.q.reserve(static_cast<std::size_t>(grid.samples + 4));
  const jle::VectorX<double> zero = jle::VectorX<double>::Zero(model.nq);
  std::array<Swing, 2> swings;
  for (long long k = -2; k < grid.samples + 2; ++k) {
    const double g = grid.g0 + static_cast<double>(k) * grid.h;
    for (std::size_t l = 0; l < trial.legs.size(); ++l)
      grid.ik_error = std::max(grid.ik_error, placeLeg(model, data, trial.legs[l], trial.gait,
                                                       trial.pelvis, g, swings[l], q));
    jle::forwardKinematics(model, data, q, zero, zero, Vector3d(0.0, 0.0, -kGravity),
                           trial.pelvis.at(g));
    for (const Leg& leg : trial.legs) {
      // fraction of T into the swing
      const double swing = trial.gait.at(leg, g).since_strike / kStride - kToeOff;
      if (swing > 0.1 && swing < 0.35)
        grid.clearance = std::min({grid.clearance, framePosition(model, data, leg.heel).z(),
                                   framePosition(model, data, leg.toe).z()});
    }
    grid.q.push_back(q);
  }
  if (grid.ik_error > 1e-6)
    throw std::runtime_error(urdf +
                             ": the legs cannot follow the trial (the inverse "
                             "kinematics misses the feet by " +
                             std::to_string(grid.ik_error) + " m)");
  return grid;
}

// Two plates side by side along x, covering every footprint.
struct Plates {
  double length = 0.0, x_centre = 0.0;  // [m]
  std::array<Vector3d, 2> p_world;      // centres of their surfaces
};

Plates layPlates(const Trial& trial, const Grid& grid) {
  double x_min = 1e9, x_max = -1e9;
  for (long long k = 0; k < grid.samples; ++k)
    for (const Leg& leg : trial.legs) {
      const FootState foot = trial.gait.at(leg, grid.g0 + static_cast<double>(k) * grid.h);
      if (!foot.stance) continue;
      x_min = std::min({x_min, foot.heel.x(), foot.toe.x()});
      x_max = std::max({x_max, foot.heel.x(), foot.toe.x()});
    }
  Plates plates;
  plates.length = std::ceil((x_max - x_min + 0.4) * 10.0) / 10.0;
  plates.x_centre = std::round(500.0 * (x_min + x_max)) / 1000.0;  // to the mm
  plates.p_world = {Vector3d(plates.x_centre, -0.5 * kLaneWidth, 0.0),
                    Vector3d(plates.x_centre, 0.5 * kLaneWidth, 0.0)};
  return plates;
}

// Figures of the trial for the report.
struct Figures {
  double peak_fz = 0.0, peak_fz_foot = 0.0, max_residual_split = 0.0;
  double cop_min = 1e9, cop_max = -1e9, cop_side = 0.0, cop_shift = 0.0;
  std::vector<double> q_min, q_max;
};

// The ground reaction at one instant: the whole wrench the world applies (F, M about the
// world origin), its centre of pressure on z = 0 and free moment, and each foot's share.
struct Reaction {
  Vector3d F, M, cop;
  double free_moment = 0.0;
  std::array<Share, 2> share;
};

// Double support: the force moves from the trailing to the leading foot by a smooth
// step, each foot's centre of pressure at its nominal point shifted by the same vector.
void splitDoubleSupport(const std::array<FootState, 2>& feet, Reaction& r, Figures& figures) {
  const int lead = feet[0].since_strike < feet[1].since_strike ? 0 : 1;
  const int trail = 1 - lead;
  const double w_lead = smoothStep(feet[lead].since_strike / ((kToeOff - 0.5) * kStride));
  const Vector3d a = trailingPoint(feet[static_cast<std::size_t>(trail)], w_lead);
  const Vector3d b(feet[lead].heel.x(), feet[lead].heel.y(), 0.0);
  const Vector3d e = r.cop - ((1.0 - w_lead) * a + w_lead * b);
  figures.cop_shift = std::max(figures.cop_shift, e.norm());
  r.share[static_cast<std::size_t>(trail)] = {true, (1.0 - w_lead) * r.F, a + e,
                                              (1.0 - w_lead) * r.free_moment};
  r.share[static_cast<std::size_t>(lead)] = {true, w_lead * r.F, b + e, w_lead * r.free_moment};
}

// Single support: all on the stance foot; where the centre of pressure lies on its
// footprint, heel 0 .. toe 1, and beside the heel-toe line, for the figures.
void placeSingleSupport(const std::array<FootState, 2>& feet, Reaction& r, Figures& figures) {
  const int stance = feet[0].stance ? 0 : 1;
  if (!feet[static_cast<std::size_t>(stance)].stance)
    throw std::runtime_error("internal: no foot on the ground");
  r.share[static_cast<std::size_t>(stance)] = {true, r.F, r.cop, r.free_moment};
  const FootState& f = feet[static_cast<std::size_t>(stance)];
  const Vector3d along = f.print_toe - f.print_heel;
  const double u = (r.cop - f.print_heel).dot(along) / along.squaredNorm();
  figures.cop_min = std::min(figures.cop_min, u);
  figures.cop_max = std::max(figures.cop_max, u);
  const Vector3d lateral = Vector3d::UnitZ().cross(along).normalized();
  figures.cop_side = std::max(figures.cop_side, std::abs((r.cop - f.print_heel).dot(lateral)));
}

// The ground reaction for the motion at grid point k (with qd, qdd) and its split
// between the feet, checked: the two shares make the whole wrench.
Reaction groundReaction(const jle::Model<double>& model, jle::Data<double>& data,
                        const Trial& trial, const jle::VectorX<double>& q,
                        const jle::VectorX<double>& qd, const jle::VectorX<double>& qdd, double g,
                        Figures& figures) {
  Reaction r;
  pelvisWrench(model, data, q, qd, qdd, trial.pelvis.at(g), r.F, r.M);
  if (!(r.F.z() > 0.0))
    throw std::runtime_error(
        "the trial needs the body pulled down (vertical ground "
        "reaction " +
        std::to_string(r.F.z()) + " N)");
  r.cop = Vector3d(-r.M.y() / r.F.z(), r.M.x() / r.F.z(), 0.0);
  r.free_moment = r.M.z() - (r.cop.x() * r.F.y() - r.cop.y() * r.F.x());
  const std::array<FootState, 2> feet = {trial.gait.at(trial.legs[0], g),
                                         trial.gait.at(trial.legs[1], g)};
  if (feet[0].stance && feet[1].stance)
    splitDoubleSupport(feet, r, figures);
  else
    placeSingleSupport(feet, r, figures);
  Vector3d F_sum = Vector3d::Zero(), M_sum = Vector3d::Zero();
  for (const Share& s : r.share) {
    F_sum += s.force;
    M_sum += s.cop.cross(s.force) + Vector3d(0, 0, s.free_moment);
  }
  figures.max_residual_split =
      std::max({figures.max_residual_split, (F_sum - r.F).norm(), (M_sum - r.M).norm() / 1.0});
  figures.peak_fz = std::max(figures.peak_fz, r.F.z());
  return r;
}

// The bag and the CSV of the trial, their messages allocated once.
class TrialWriter {
 public:
  TrialWriter(const jle::Model<double>& model, const Options& options, const Plates& plates)
      : model_(model),
        options_(options),
        plates_(plates),
        random_(options.seed),
        bag_(options.output) {
    joints_.name = model.coordinate_names;
    joints_.position.resize(joints_.name.size());
    pose_msg_.transforms.resize(1);
    cop_msg_.transforms.resize(2);
    for (int i = 0; i < 2; ++i) {
      const std::string n = std::to_string(i + 1);
      plate_topic_[i] = "/force_plate_" + n + "/wrench";
      reaction_topic_[i] = "/force_plate_" + n + "/reaction";
      plate_frame_[i] = "force_plate_" + n;
      cop_frame_[i] = "force_plate_" + n + "_cop";
      plate_msg_[i].header.frame_id = plate_frame_[i];
      reaction_msg_[i].header.frame_id = cop_frame_[i];
      last_cop_[i] = plates.p_world[i];
    }
    if (!options.csv.empty()) {
      csv_ = std::make_unique<jle::CsvWriter>(options.csv);
      jle::ExtraStateInputs extra;
      extra.floating_base = true;
      extra.plates = {"plate1", "plate2"};
      const std::vector<std::string> names = jle::stateColumnNames(model, {}, extra);
      csv_->writeHeader(names);
      csv_row_.resize(names.size());
    }
  }

  // The plates' poses, latched.
  void writePlatePoses() {
    const ros::Time stamp = jle_tools::stampOf(kEpochNs);
    tf2_msgs::TFMessage static_msg;
    for (int i = 0; i < 2; ++i)
      static_msg.transforms.push_back(
          transform(plate_frame_[i], stamp, plates_.p_world[i], Matrix3d::Identity()));
    // A connection header of our own (for "latching") must also name the type.
    auto header = boost::make_shared<ros::M_string>();
    (*header)["type"] = ros::message_traits::datatype(static_msg);
    (*header)["md5sum"] = ros::message_traits::md5sum(static_msg);
    (*header)["message_definition"] = ros::message_traits::definition(static_msg);
    (*header)["callerid"] = "/make_gait_bag";
    (*header)["latching"] = "1";
    bag_.bag().write("/tf_static", stamp - ros::Duration(0, 3000000), static_msg, header);
  }

  // Plate sample k (1 kHz): the plates, and at their rates the display and the joints.
  void write(long long k, const Reaction& r, const jle::BaseState<double>& base,
             const jle::VectorX<double>& q, const jle::VectorX<double>& qd,
             const jle::VectorX<double>& qdd, Figures& figures) {
    const std::int64_t ns = kEpochNs + k * 1000000LL;
    const ros::Time stamp = jle_tools::stampOf(ns);
    const ros::Time early = stamp - ros::Duration(0, 2000000);
    writePlates(r, stamp, early, figures);
    if (k % kDisplayDivisor == 0) writeDisplay(r, stamp, early);
    if (k % kPlateDivisor == 0) {
      pose_msg_.transforms[0] = transform("pelvis", stamp, base.p_world_base, base.R_world_base);
      bag_.bag().write("/tf", early, pose_msg_);
      joints_.header.stamp = stamp;
      joints_.header.seq = static_cast<std::uint32_t>(k / kPlateDivisor);
      for (int j = 0; j < model_.nq; ++j) joints_.position[static_cast<std::size_t>(j)] = q[j];
      bag_.bag().write("/joint_states", stamp, joints_);
      if (csv_) writeCsvRow(static_cast<double>(ns - kEpochNs) * 1e-9, base, q, qd, qdd);
    }
  }

  void commit() {
    bag_.commit();
    if (csv_) csv_->commit();
  }

 private:
  // Box-Muller, the cosine of each pair (kUsage).
  double gaussian() {
    const double u1 = 1.0 - random_.uniform(), u2 = random_.uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }

  // What each foot applies to its plate (the reaction reversed), plate frame (axes of
  // the world), moment about the plate origin; with noise.
  void writePlates(const Reaction& r, const ros::Time& stamp, const ros::Time& early,
                   Figures& figures) {
    for (std::size_t i = 0; i < 2; ++i) {
      const Share& share = r.share[i];
      figures.peak_fz_foot = std::max(figures.peak_fz_foot, share.force.z());
      const Vector3d arm = share.cop - plates_.p_world[i];
      Vector3d f_plate = -share.force;
      Vector3d m_plate = -(arm.cross(share.force) + Vector3d(0, 0, share.free_moment));
      if (options_.noise > 0.0) {
        for (int j = 0; j < 3; ++j) f_plate[j] += options_.noise * gaussian();
        for (int j = 0; j < 3; ++j) m_plate[j] += 0.01 * options_.noise * gaussian();
      }
      plate_msg_[i].header.stamp = stamp;
      jle_tools::setWrench(plate_msg_[i], f_plate, m_plate);
      bag_.bag().write(plate_topic_[i], early, plate_msg_[i]);
      if (share.contact) last_cop_[i] = share.cop;
      plate_row_[i] << f_plate, m_plate;
    }
  }

  // Where the ground reaction acts and what it is, for display.
  void writeDisplay(const Reaction& r, const ros::Time& stamp, const ros::Time& early) {
    for (std::size_t i = 0; i < 2; ++i) {
      cop_msg_.transforms[i] = transform(cop_frame_[i], stamp, last_cop_[i], Matrix3d::Identity());
      reaction_msg_[i].header.stamp = stamp;
      jle_tools::setWrench(reaction_msg_[i], r.share[i].force,
                           Vector3d(0, 0, r.share[i].free_moment));
    }
    bag_.bag().write("/tf", early, cop_msg_);
    for (std::size_t i = 0; i < 2; ++i)
      bag_.bag().write(reaction_topic_[i], stamp, reaction_msg_[i]);
  }

  // t, J.q, J.qd, J.qdd, base.x .. base.alz, plate@plate1.fx .. plate@plate2.mz.
  void writeCsvRow(double t, const jle::BaseState<double>& base, const jle::VectorX<double>& q,
                   const jle::VectorX<double>& qd, const jle::VectorX<double>& qdd) {
    double* o = csv_row_.data();
    *o++ = t;
    for (int j = 0; j < model_.nq; ++j) {
      *o++ = q[j];
      *o++ = qd[j];
      *o++ = qdd[j];
    }
    const Eigen::Quaterniond orientation(base.R_world_base);
    for (int i = 0; i < 3; ++i) *o++ = base.p_world_base[i];
    for (const double x : {orientation.x(), orientation.y(), orientation.z(), orientation.w()})
      *o++ = x;
    for (const Vector3d* v : {&base.v_world, &base.omega_world, &base.a_world, &base.alpha_world})
      for (int i = 0; i < 3; ++i) *o++ = (*v)[i];
    for (const auto& row : plate_row_)
      for (int j = 0; j < 6; ++j) *o++ = row[j];
    csv_->writeRow(csv_row_.data(), csv_row_.size());
  }

  const jle::Model<double>& model_;
  const Options& options_;
  const Plates& plates_;
  jle::PortableRandom random_;
  jle_tools::PartialBag bag_;
  std::unique_ptr<jle::CsvWriter> csv_;
  std::vector<double> csv_row_;
  sensor_msgs::JointState joints_;
  tf2_msgs::TFMessage pose_msg_, cop_msg_;
  std::array<geometry_msgs::WrenchStamped, 2> plate_msg_, reaction_msg_;
  std::array<std::string, 2> plate_topic_, reaction_topic_, plate_frame_, cop_frame_;
  std::array<Eigen::Matrix<double, 6, 1>, 2> plate_row_;  // the plates' samples for the CSV
  std::array<Vector3d, 2> last_cop_;
};

void printReport(const jle::Model<double>& model, const Options& options, const Trial& trial,
                 const Grid& grid, const Plates& plates, const Figures& figures) {
  const double weight = model.totalMass() * kGravity;
  std::printf(
      "make_gait_bag: %d strides, %.3f s, %lld joint states (200 Hz), %lld plate "
      "samples per plate (1 kHz) -> %s\n",
      options.strides, static_cast<double>(grid.samples) * grid.h, (grid.samples + 4) / 5,
      grid.samples, options.output.c_str());
  std::printf(
      "  body %.2f kg (weight %.1f N); plates %.1f m x %.1f m, centres x %.3f m, "
      "y -/+%.2f m\n",
      model.totalMass(), weight, plates.length, kLaneWidth, plates.x_centre, 0.5 * kLaneWidth);
  std::printf(
      "  joint_loads: --plate plate1=foot_r,%.3f,%.3f,0 --plate plate2=foot_l,%.3f,%.3f,0\n",
      plates.x_centre, -0.5 * kLaneWidth, plates.x_centre, 0.5 * kLaneWidth);
  std::printf("  vertical ground reaction: peak %.2f BW (both feet), %.2f BW (one foot)\n",
              figures.peak_fz / weight, figures.peak_fz_foot / weight);
  std::printf(
      "  single support: centre of pressure from %.2f to %.2f of heel->toe, up to "
      "%.3f m beside that line\n",
      figures.cop_min, figures.cop_max, figures.cop_side);
  std::printf(
      "  double support: each foot's centre of pressure within %.3f m of its nominal "
      "point (leading heel, trailing forefoot)\n",
      figures.cop_shift);
  std::printf("  centre of pressure: planned path missed by %.3f m at most\n", trial.cop_error);
  std::printf(
      "  inverse kinematics error %.1e m, split error %.1e, lowest heel or toe in "
      "mid-swing %.3f m\n",
      grid.ik_error, figures.max_residual_split, grid.clearance);
  for (const Leg& leg : trial.legs)
    for (int j : leg.coordinate)
      std::printf("  %-18s %7.1f .. %6.1f deg\n",
                  model.coordinate_names[static_cast<std::size_t>(j)].c_str(),
                  figures.q_min[static_cast<std::size_t>(j)] * 180.0 / kPi,
                  figures.q_max[static_cast<std::size_t>(j)] * 180.0 / kPi);
}

void run(const Options& options) {
  jle::ModelOptions model_options;
  model_options.floating_base = true;
  const jle::Model<double> model = jle::modelFromUrdfFile(options.urdf, model_options);
  if (model.link_name[0] != "pelvis")
    throw std::runtime_error(options.urdf + ": the root link is '" + model.link_name[0] +
                             "', make_gait_bag needs 'pelvis'");
  jle::Data<double> data(model);
  jle::VectorX<double> q;
  const Trial trial = planTrial(model, data, options.urdf, q);
  const Grid grid = solveGrid(model, data, trial, options.strides, q, options.urdf);
  const Plates plates = layPlates(trial, grid);

  Figures figures;
  figures.q_min.assign(static_cast<std::size_t>(model.nq), 1e9);
  figures.q_max.assign(static_cast<std::size_t>(model.nq), -1e9);
  TrialWriter writer(model, options, plates);
  writer.writePlatePoses();
  jle::VectorX<double> qd(model.nq), qdd(model.nq);
  for (long long k = 0; k < grid.samples; ++k) {
    const std::size_t c = static_cast<std::size_t>(k + 2);
    fivePoint(grid.q, c, grid.h, qd, qdd);
    for (std::size_t j = 0; j < figures.q_min.size(); ++j) {
      figures.q_min[j] = std::min(figures.q_min[j], grid.q[c][static_cast<int>(j)]);
      figures.q_max[j] = std::max(figures.q_max[j], grid.q[c][static_cast<int>(j)]);
    }
    const double g = grid.g0 + static_cast<double>(k) * grid.h;
    const Reaction r = groundReaction(model, data, trial, grid.q[c], qd, qdd, g, figures);
    writer.write(k, r, trial.pelvis.at(g), grid.q[c], qd, qdd, figures);
  }
  writer.commit();
  printReport(model, options, trial, grid, plates, figures);
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "make_gait_bag", kUsage, parseOptions, run);
}
