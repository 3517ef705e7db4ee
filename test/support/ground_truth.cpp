#include <jle_testing/ground_truth.hpp>

#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace jle {
namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kTwoPi = 6.283185307179586;

double clampAbs(double x, double limit) { return std::max(-limit, std::min(limit, x)); }

// Reading of an ideal quantiser with `resolution` per count (0: none).
double quantise(double x, double resolution) {
  return resolution > 0.0 ? resolution * std::round(x / resolution) : x;
}

// Whether coordinate c is prismatic (taken from the first segment that uses it, its leader).
std::vector<bool> prismaticCoordinates(const Model<double>& model) {
  std::vector<bool> prismatic(static_cast<std::size_t>(model.nq), false);
  std::vector<bool> seen(static_cast<std::size_t>(model.nq), false);
  for (int i = 0; i < model.nsegments(); ++i) {
    const int c = model.coordinate[i];
    if (c < 0 || seen[static_cast<std::size_t>(c)]) continue;
    seen[static_cast<std::size_t>(c)] = true;
    prismatic[static_cast<std::size_t>(c)] = model.joint_type[i] == JointType::kPrismatic;
  }
  return prismatic;
}

}  // namespace

std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + (stream + 1) * 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

CoordinateState CoordinateMotion::at(double t) const {
  CoordinateState s;
  s.q = p0 + t * (p1 + t * p2);
  s.qd = p1 + 2.0 * p2 * t;
  s.qdd = 2.0 * p2;
  for (const Sine& w : sines) {
    const double a = w.omega * t + w.phase;
    const double sn = std::sin(a), cs = std::cos(a);
    s.q += w.amplitude * sn;
    s.qd += w.amplitude * w.omega * cs;
    s.qdd -= w.amplitude * w.omega * w.omega * sn;
  }
  for (const SmoothStep& step : steps) {
    if (t <= step.start) continue;
    if (t >= step.start + step.duration) {
      s.q += step.height;
      continue;
    }
    const double x = (t - step.start) / step.duration, y = 1.0 - x;
    const double S = x * x * x * x * (35.0 - 84.0 * x + 70.0 * x * x - 20.0 * x * x * x);
    const double dS = 140.0 * x * x * x * y * y * y;
    const double ddS = 420.0 * x * x * y * y * (1.0 - 2.0 * x);
    s.q += step.height * S;
    s.qd += step.height * dS / step.duration;
    s.qdd += step.height * ddS / (step.duration * step.duration);
  }
  for (const AccelPulse& pulse : pulses) {
    if (t < pulse.start) continue;
    const double u = std::min(t - pulse.start, pulse.duration);  // time accelerated
    s.q += pulse.accel * u * (0.5 * u + (t - pulse.start - u));
    s.qd += pulse.accel * u;
    if (t - pulse.start < pulse.duration) s.qdd += pulse.accel;
  }
  return s;
}

namespace {

// The shared schedule of stop-and-go, (start, duration) of each move: a hold in
// [hold_lo, hold_hi) at t = 0, then move and hold alternately below the duration.
std::vector<std::pair<double, double>> stopAndGoSchedule(PortableRandom& rng, double duration,
                                                         double hold_lo, double hold_hi) {
  std::vector<std::pair<double, double>> moves;
  double t = rng.uniform(hold_lo, hold_hi);
  while (t < duration) {
    const double T = rng.uniform(0.6, 1.5);
    moves.emplace_back(t, T);
    t += T + rng.uniform(hold_lo, hold_hi);
  }
  return moves;
}

// One swing of kImpacts: its acceleration phase and its impact.
struct Swing {
  double start = 0.0, accelerate = 0.0, impact_start = 0.0, impact = 0.0;
};

std::vector<Swing> impactSchedule(PortableRandom& rng, double duration) {
  std::vector<Swing> swings;
  double t = rng.uniform(0.2, 0.8);
  while (t < duration) {
    Swing s;
    s.start = t;
    s.accelerate = rng.uniform(0.2, 0.5);
    const double coast = rng.uniform(0.1, 0.4);
    s.impact = rng.uniform(0.01, 0.03);
    s.impact_start = s.start + s.accelerate + coast;
    swings.push_back(s);
    t = s.impact_start + s.impact + rng.uniform(0.3, 1.0);
  }
  return swings;
}

void drawSines(PortableRandom& rng, double scale, CoordinateMotion& m) {
  const int n = rng.uniform() < 0.5 ? 2 : 3;
  for (int j = 0; j < n; ++j) {
    Sine s;
    s.amplitude = scale * rng.uniform(0.05, 0.3);
    s.omega = kTwoPi * rng.uniform(0.1, 0.6);
    s.phase = rng.uniform(0.0, kTwoPi);
    m.sines.push_back(s);
  }
  m.p0 = scale * rng.uniform(-0.5, 0.5);
}

void drawRamps(PortableRandom& rng, double scale, double duration, CoordinateMotion& m) {
  m.p0 = scale * rng.uniform(-0.5, 0.5);
  double at = 0.0;  // offset from p0 reached so far
  for (double t = 0.0; t < duration;) {
    SmoothStep s;
    s.start = t;
    s.duration = rng.uniform(0.6, 1.5);
    const double target = scale * rng.uniform(-0.4, 0.4);
    s.height = target - at;
    at = target;
    m.steps.push_back(s);
    t += s.duration;
  }
}

void drawMoves(PortableRandom& rng, double scale,
               const std::vector<std::pair<double, double>>& moves, CoordinateMotion& m) {
  m.p0 = scale * rng.uniform(-0.5, 0.5);
  double at = 0.0;
  for (const auto& move : moves) {
    SmoothStep s;
    s.start = move.first;
    s.duration = move.second;
    const double target = scale * rng.uniform(-0.4, 0.4);
    s.height = target - at;
    at = target;
    m.steps.push_back(s);
  }
}

void drawImpacts(PortableRandom& rng, double scale, const std::vector<Swing>& swings,
                 CoordinateMotion& m) {
  m.p0 = scale * rng.uniform(-0.5, 0.5);
  double direction = rng.uniform() < 0.5 ? 1.0 : -1.0;
  for (const Swing& s : swings) {
    const double speed = direction * scale * rng.uniform(0.2, 0.8);
    m.pulses.push_back({s.start, s.accelerate, speed / s.accelerate});
    m.pulses.push_back({s.impact_start, s.impact, -speed / s.impact});
    direction = -direction;
  }
}

}  // namespace

std::vector<CoordinateMotion> randomMotion(const Model<double>& model, MotionKind kind,
                                           double duration, std::uint64_t seed) {
  if (!(duration >= 0.0)) throw std::invalid_argument("randomMotion: negative duration");
  PortableRandom rng(seed);
  const std::vector<bool> prismatic = prismaticCoordinates(model);
  // The shared schedules are drawn first.
  std::vector<std::pair<double, double>> moves;
  if (kind == MotionKind::kStopAndGo) moves = stopAndGoSchedule(rng, duration, 0.2, 0.8);
  if (kind == MotionKind::kLongHolds) moves = stopAndGoSchedule(rng, duration, 2.0, 5.0);
  std::vector<Swing> swings;
  if (kind == MotionKind::kImpacts) swings = impactSchedule(rng, duration);
  std::vector<CoordinateMotion> motion(static_cast<std::size_t>(model.nq));
  for (int c = 0; c < model.nq; ++c) {
    CoordinateMotion& m = motion[static_cast<std::size_t>(c)];
    const double scale = prismatic[static_cast<std::size_t>(c)] ? kPrismaticScale : 1.0;
    switch (kind) {
      case MotionKind::kSines: drawSines(rng, scale, m); break;
      case MotionKind::kRamps: drawRamps(rng, scale, duration, m); break;
      case MotionKind::kStopAndGo:
      case MotionKind::kLongHolds: drawMoves(rng, scale, moves, m); break;
      case MotionKind::kQuadratic:
        m.p0 = scale * rng.uniform(-0.5, 0.5);
        m.p1 = scale * rng.uniform(-0.5, 0.5);
        m.p2 = scale * rng.uniform(-0.5, 0.5);
        break;
      case MotionKind::kImpacts: drawImpacts(rng, scale, swings, m); break;
    }
  }
  return motion;
}

WrenchMotion::Vector6 WrenchMotion::at(double t) const {
  Vector6 w;
  for (int c = 0; c < 6; ++c) w[c] = mean[c] + amplitude[c] * std::sin(omega[c] * t + phase[c]);
  for (const Stance& stance : stances) {
    const double s = t - stance.start;
    if (s < 0.0 || s > stance.duration) continue;
    w += std::min(1.0, s / stance.rise) * std::sin(kPi * s / stance.duration) * stance.peak;
  }
  return w;
}

WrenchMotion randomWrench(const std::string& link, std::uint64_t seed) {
  PortableRandom rng(seed);
  WrenchMotion w;
  w.link = link;
  for (int c = 0; c < 6; ++c) {
    const double scale = c < 3 ? 10.0 : 1.0;
    w.mean[c] = rng.uniform(-scale, scale);
    w.amplitude[c] = rng.uniform(0.0, scale);
    w.omega[c] = kTwoPi * rng.uniform(0.1, 1.0);
    w.phase[c] = rng.uniform(0.0, kTwoPi);
  }
  return w;
}

GroundTruth::GroundTruth(Model<double> model, std::vector<CoordinateMotion> motion,
                         std::vector<WrenchMotion> wrenches, const Eigen::Vector3d& gravity_world)
    : model_(std::move(model)),
      motion_(std::move(motion)),
      wrenches_(std::move(wrenches)),
      gravity_world_(gravity_world) {
  if (model_.floating_base)
    throw std::invalid_argument("GroundTruth: floating-base models are not supported");
  if (static_cast<int>(motion_.size()) != model_.nq)
    throw std::invalid_argument(
        "GroundTruth: " + std::to_string(motion_.size()) +
        " coordinate motions for a model with nq = " + std::to_string(model_.nq));
  for (const WrenchMotion& w : wrenches_) wrench_frames_.push_back(model_.frameIndex(w.link));
  prismatic_ = prismaticCoordinates(model_);
}

void GroundTruth::coordinates(double t, VectorX<double>& q, VectorX<double>& qd,
                              VectorX<double>& qdd) const {
  q.resize(model_.nq);
  qd.resize(model_.nq);
  qdd.resize(model_.nq);
  for (int c = 0; c < model_.nq; ++c) {
    const CoordinateState s = motion_[static_cast<std::size_t>(c)].at(t);
    q[c] = s.q;
    qd[c] = s.qd;
    qdd[c] = s.qdd;
  }
}

void GroundTruth::loads(double t, Data<double>& data) const {
  VectorX<double> q, qd, qdd;
  coordinates(t, q, qd, qdd);
  forwardKinematics(model_, data, q, qd, qdd, gravity_world_);
  for (std::size_t k = 0; k < wrenches_.size(); ++k) {
    const WrenchMotion::Vector6 w = wrenches_[k].at(t);
    addExternalWrench(model_, data, wrench_frames_[k], Eigen::Vector3d(w.head<3>()),
                      Eigen::Vector3d(w.tail<3>()), WrenchFrame::kLocal);
  }
  inverseDynamics(model_, data);
}

namespace {

// The bursts and gaps of a sensor, drawn per sample from their own stream.
class SensorDefects {
 public:
  SensorDefects(const SensorModel& sensor, std::uint64_t seed)
      : sensor_(sensor), rng_(deriveSeed(seed, kDefectStream)) {}

  // Sample k's draws: whether it is lost to a gap, whether it is in a burst, and the
  // burst's gaussian for its stamp error.
  bool next(bool& in_burst, double& g) {
    const bool burst_start = rng_.uniform() < sensor_.burst_probability;
    const bool gap_start = rng_.uniform() < sensor_.gap_probability;
    const int gap_length = 1 + rng_.index(std::max(1, sensor_.max_gap));
    g = rng_.gaussian();
    if (burst_left_ == 0 && burst_start) burst_left_ = sensor_.burst_length;
    in_burst = burst_left_ > 0;
    if (burst_left_ > 0) --burst_left_;
    // A gap starts at a sample after a kept one: two gaps never join.
    if (gap_left_ == 0 && gap_start && !lost_) gap_left_ = gap_length;
    lost_ = gap_left_ > 0;
    if (lost_) --gap_left_;
    return lost_;
  }

 private:
  const SensorModel& sensor_;
  PortableRandom rng_;
  int burst_left_ = 0, gap_left_ = 0;
  bool lost_ = false;  // the previous sample was lost to a gap
};

// Coloured noise and the vibration line of every coordinate at samples 0 .. samples - 1
// (samples x nq), from stream kColouredStream; zero when the sensor has neither.
Eigen::MatrixXd colouredNoise(const SensorModel& sensor, long samples, int nq, std::uint64_t seed) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(samples, nq);
  if (!(sensor.coloured_noise > 0.0) && !(sensor.vibration_amplitude > 0.0)) return out;
  PortableRandom rng(deriveSeed(seed, kColouredStream));
  std::vector<double> phase(static_cast<std::size_t>(nq));
  for (double& p : phase) p = rng.uniform(0.0, kTwoPi);
  // 2nd-order Butterworth by the bilinear transform (prewarped), unit DC gain.
  const double w = sensor.coloured_corner / sensor.rate;
  const bool white = !(w < 0.5);
  const double k = white ? 0.0 : std::tan(0.5 * kTwoPi * w),
               norm = 1.0 + std::sqrt(2.0) * k + k * k;
  const double b0 = k * k / norm, b1 = 2.0 * b0, b2 = b0;
  const double a1 = 2.0 * (k * k - 1.0) / norm, a2 = (1.0 - std::sqrt(2.0) * k + k * k) / norm;
  // The output's variance for unit white input: the impulse response's energy.
  double energy = 1.0;
  const long warm_up = white ? 0 : static_cast<long>(std::ceil(20.0 / w));
  if (!white) {
    energy = 0.0;
    double z1 = 0.0, z2 = 0.0;
    for (long i = 0; i < 4 * warm_up + 100; ++i) {
      const double x = i == 0 ? 1.0 : 0.0, y = b0 * x + z1;
      z1 = b1 * x - a1 * y + z2;
      z2 = b2 * x - a2 * y;
      energy += y * y;
    }
  }
  const double scale = sensor.coloured_noise / std::sqrt(energy);
  for (int c = 0; c < nq; ++c) {
    double z1 = 0.0, z2 = 0.0;
    for (long i = -warm_up; i < samples; ++i) {
      const double x = rng.gaussian();
      double y = x;
      if (!white) {
        y = b0 * x + z1;
        z1 = b1 * x - a1 * y + z2;
        z2 = b2 * x - a2 * y;
      }
      if (i < 0) continue;
      out(i, c) = scale * y +
                  sensor.vibration_amplitude * std::sin(kTwoPi * sensor.vibration_frequency *
                                                            static_cast<double>(i) / sensor.rate +
                                                        phase[static_cast<std::size_t>(c)]);
    }
  }
  return out;
}

}  // namespace

std::vector<JointReading> GroundTruth::sampleJoints(const SensorModel& sensor, double duration,
                                                    std::uint64_t seed) const {
  const int nq = model_.nq;
  std::vector<double> resolution(static_cast<std::size_t>(nq));
  for (int c = 0; c < nq; ++c)
    resolution[static_cast<std::size_t>(c)] =
        prismatic_[static_cast<std::size_t>(c)]
            ? sensor.prismatic_resolution
            : (sensor.counts_per_revolution > 0.0 ? kTwoPi / sensor.counts_per_revolution : 0.0);
  PortableRandom rng(deriveSeed(seed, 0));
  SensorDefects defects(sensor, seed);
  const double jitter_limit = 0.2 / sensor.rate;
  const long samples = static_cast<long>(std::floor(duration * sensor.rate + 1e-9)) + 1;
  const Eigen::MatrixXd coloured = colouredNoise(sensor, samples, nq, seed);
  std::vector<JointReading> out;
  out.reserve(static_cast<std::size_t>(samples));
  VectorX<double> noise_q(nq), noise_qd(nq);
  for (long k = 0; k < samples; ++k) {
    const bool dropped = rng.uniform() < sensor.drop_probability;
    const double dt_sample = clampAbs(sensor.sample_jitter * rng.gaussian(), jitter_limit);
    double dt_stamp = clampAbs(sensor.stamp_jitter * rng.gaussian(), jitter_limit);
    for (int c = 0; c < nq; ++c) {
      noise_q[c] = rng.gaussian();
      noise_qd[c] = rng.gaussian();
    }
    bool in_burst = false;
    double burst_g = 0.0;
    const bool in_gap = defects.next(in_burst, burst_g);
    if (in_burst) dt_stamp = clampAbs(sensor.burst_stamp_jitter * burst_g, jitter_limit);
    if (dropped || in_gap) continue;
    JointReading r;
    r.time = static_cast<double>(k) / sensor.rate + dt_sample;
    r.stamp = r.time + dt_stamp;
    r.q.resize(nq);
    r.qd.resize(nq);
    for (int c = 0; c < nq; ++c) {
      const CoordinateState s = motion_[static_cast<std::size_t>(c)].at(r.time);
      r.q[c] = quantise(s.q + sensor.position_noise * noise_q[c] + coloured(k, c),
                        resolution[static_cast<std::size_t>(c)]);
      r.qd[c] = s.qd + sensor.velocity_noise * noise_qd[c];
    }
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<WrenchReading> GroundTruth::sampleWrenches(const SensorModel& sensor, double duration,
                                                       std::uint64_t seed) const {
  std::vector<WrenchReading> out;
  const double wrench_rate = sensor.wrench_rate > 0.0 ? sensor.wrench_rate : sensor.rate;
  for (std::size_t i = 0; i < wrenches_.size(); ++i) {
    PortableRandom wrng(deriveSeed(seed, i + 1));
    for (long j = 0;; ++j) {
      const double t = sensor.wrench_offset + static_cast<double>(j) / wrench_rate;
      if (t > duration + 1e-12) break;
      const bool dropped = wrng.uniform() < sensor.wrench_drop_probability;
      double noise[6];
      for (double& n : noise) n = wrng.gaussian();
      if (dropped) continue;
      const WrenchMotion::Vector6 w = wrenches_[i].at(t);
      WrenchReading r;
      r.input = static_cast<int>(i);
      r.stamp = t;
      for (int c = 0; c < 3; ++c) {
        r.force[c] = w[c] + sensor.force_bias[c] + sensor.force_noise * noise[c];
        r.moment[c] = w[c + 3] + sensor.moment_bias[c] + sensor.moment_noise * noise[c + 3];
      }
      out.push_back(r);
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const WrenchReading& a, const WrenchReading& b) {
    return a.stamp < b.stamp || (a.stamp == b.stamp && a.input < b.input);
  });
  return out;
}

SensorReadings GroundTruth::sample(const SensorModel& sensor, double duration,
                                   std::uint64_t seed) const {
  if (!(sensor.rate > 0.0)) throw std::invalid_argument("SensorModel: rate must be positive");
  if (!(duration >= 0.0)) throw std::invalid_argument("GroundTruth::sample: negative duration");
  if (sensor.burst_length < 1 || sensor.max_gap < 1)
    throw std::invalid_argument("SensorModel: burst_length and max_gap must be at least 1");
  SensorReadings out;
  out.joints = sampleJoints(sensor, duration, seed);
  out.wrenches = sampleWrenches(sensor, duration, seed);
  return out;
}

std::string planarArmUrdf() {
  std::ostringstream x;
  x << "<?xml version=\"1.0\"?>\n<robot name=\"planar_arm\">\n"
    << "  <link name=\"base\">\n"
    << "    <inertial><origin xyz=\"0 0 0\"/><mass value=\"5\"/>"
    << "<inertia ixx=\"0.05\" ixy=\"0\" ixz=\"0\" iyy=\"0.05\" iyz=\"0\" "
       "izz=\"0.05\"/></inertial>\n"
    << "  </link>\n";
  const double length[3] = {0.5, 0.4, 0.3}, mass[3] = {3.0, 2.0, 1.0};
  for (int i = 0; i < 3; ++i) {
    const double I = mass[i] * length[i] * length[i] / 12.0;  // thin rod about its centre
    x << std::setprecision(17) << "  <link name=\"link" << i + 1 << "\">\n"
      << "    <inertial><origin xyz=\"" << 0.5 * length[i] << " 0 0\"/><mass value=\"" << mass[i]
      << "\"/><inertia ixx=\"1e-4\" ixy=\"0\" ixz=\"0\" iyy=\"" << I << "\" iyz=\"0\" izz=\"" << I
      << "\"/></inertial>\n  </link>\n"
      << "  <joint name=\"joint" << i + 1 << "\" type=\"revolute\">\n"
      << "    <parent link=\"" << (i == 0 ? std::string("base") : "link" + std::to_string(i))
      << "\"/><child link=\"link" << i + 1 << "\"/>\n"
      << "    <origin xyz=\"" << (i == 0 ? 0.0 : length[i - 1]) << " 0 " << (i == 0 ? 0.2 : 0.0)
      << "\" rpy=\"0 0 0\"/><axis xyz=\"0 1 0\"/>\n"
      << "    <limit effort=\"1000\" velocity=\"100\" lower=\"-10\" upper=\"10\"/>\n  </joint>\n";
  }
  x << "  <link name=\"tip\"/>\n"
    << "  <joint name=\"tip_joint\" type=\"fixed\"><parent link=\"link3\"/><child link=\"tip\"/>"
    << "<origin xyz=\"0.3 0 0\" rpy=\"0 0 0\"/></joint>\n</robot>\n";
  return x.str();
}

std::string planarLegUrdf() {
  std::ostringstream x;
  x << std::setprecision(17) << "<?xml version=\"1.0\"?>\n<robot name=\"planar_leg\">\n"
    << "  <link name=\"pelvis\"/>\n";
  const char* names[3] = {"thigh", "shank", "foot"};
  const char* joints[3] = {"hip", "knee", "ankle"};
  const double length[2] = {0.42, 0.42}, mass[3] = {7.0, 3.2, 1.1};
  for (int i = 0; i < 3; ++i) {
    x << "  <link name=\"" << names[i] << "\">\n    <inertial><origin xyz=\"";
    if (i < 2) {
      const double I = mass[i] * length[i] * length[i] / 12.0;  // thin rod about its centre
      x << "0 0 " << -0.43 * length[i] << "\"/><mass value=\"" << mass[i] << "\"/><inertia ixx=\""
        << I << "\" ixy=\"0\" ixz=\"0\" iyy=\"" << I << "\" iyz=\"0\" izz=\"1e-4\"/>";
    } else {
      x << "0.05 0 -0.03\"/><mass value=\"" << mass[i]
        << "\"/><inertia ixx=\"1e-3\" ixy=\"0\" ixz=\"0\" iyy=\"0.004\" iyz=\"0\" izz=\"0.004\"/>";
    }
    x << "</inertial>\n  </link>\n"
      << "  <joint name=\"" << joints[i] << "\" type=\"revolute\">\n    <parent link=\""
      << (i == 0 ? "pelvis" : names[i - 1]) << "\"/><child link=\"" << names[i] << "\"/>\n"
      << "    <origin xyz=\"0 0 " << (i == 0 ? 0.0 : -length[i - 1])
      << "\" rpy=\"0 0 0\"/><axis xyz=\"0 1 0\"/>\n"
      << "    <limit effort=\"1000\" velocity=\"100\" lower=\"-10\" upper=\"10\"/>\n  </joint>\n";
  }
  x << "</robot>\n";
  return x.str();
}

std::string randomTreeUrdf(std::uint64_t seed, int links) {
  if (links < 1) throw std::invalid_argument("randomTreeUrdf: at least one link");
  PortableRandom rng(seed);
  std::ostringstream x;
  x << std::setprecision(17);
  x << "<?xml version=\"1.0\"?>\n<robot name=\"random_tree_" << seed << "\">\n"
    << "  <link name=\"link0\">\n"
    << "    <inertial><origin xyz=\"0 0 0\"/><mass value=\"2\"/>"
    << "<inertia ixx=\"0.02\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" "
       "izz=\"0.02\"/></inertial>\n"
    << "  </link>\n";
  auto triple = [&](double lo, double hi) {
    const double a = rng.uniform(lo, hi), b = rng.uniform(lo, hi), c = rng.uniform(lo, hi);
    std::ostringstream s;
    s << std::setprecision(17) << a << ' ' << b << ' ' << c;
    return s.str();
  };
  for (int i = 1; i <= links; ++i) {
    const int parent = rng.index(i);
    const bool prismatic = rng.index(8) == 0;
    Eigen::Vector3d axis;
    do {
      axis << rng.gaussian(), rng.gaussian(), rng.gaussian();
    } while (axis.norm() < 1e-3);
    axis.normalize();
    const std::string xyz = triple(-0.3, 0.3), rpy = triple(-kPi, kPi);
    x << "  <link name=\"link" << i << "\">\n";
    if (rng.index(6) != 0) {
      const double m = rng.uniform(0.2, 5.0);
      const double a = rng.uniform(0.05, 0.4), b = rng.uniform(0.05, 0.4),
                   c = rng.uniform(0.05, 0.4);
      const std::string com = triple(-0.15, 0.15), axes = triple(-kPi, kPi);
      x << "    <inertial><origin xyz=\"" << com << "\" rpy=\"" << axes << "\"/><mass value=\"" << m
        << "\"/><inertia ixx=\"" << m * (b * b + c * c) / 12.0 << "\" ixy=\"0\" ixz=\"0\" iyy=\""
        << m * (a * a + c * c) / 12.0 << "\" iyz=\"0\" izz=\"" << m * (a * a + b * b) / 12.0
        << "\"/></inertial>\n";
    }
    x << "  </link>\n"
      << "  <joint name=\"joint" << i << "\" type=\"" << (prismatic ? "prismatic" : "revolute")
      << "\">\n    <parent link=\"link" << parent << "\"/><child link=\"link" << i << "\"/>\n"
      << "    <origin xyz=\"" << xyz << "\" rpy=\"" << rpy << "\"/><axis xyz=\"" << axis.x() << ' '
      << axis.y() << ' ' << axis.z() << "\"/>\n"
      << "    <limit effort=\"1000\" velocity=\"100\" lower=\"-10\" upper=\"10\"/>\n  </joint>\n";
  }
  x << "</robot>\n";
  return x.str();
}

}  // namespace jle
