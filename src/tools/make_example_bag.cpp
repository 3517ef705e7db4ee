// make_example_bag: a deterministic example bag of an arm with a wrist force/torque
// sensor, for the demo and for process_bag's tests and benchmarks. The formulas are in
// kUsage and docs/demo.md.
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include "bag_writing.hpp"

#include <geometry_msgs/WrenchStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/JointState.h>

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace jle::cli;  // command_line.hpp: UsageError, optionValues, the parsers

const char* const kUsage =
    R"(usage: make_example_bag --urdf ROBOT.urdf --output OUT.bag [--duration 10] [--rate 1000]
                        [--samples N] [--seed 1] [--effort] [--sensor-frame panda_link8]
                        [--tcp-frame panda_hand_tcp]

Writes a bag of an arm moving along an analytic trajectory while a wrist
force/torque sensor measures a payload and a push:
  /joint_states     sensor_msgs/JointState, every moving joint of the URDF (mimic
                    joints included), positions only; with --effort also the exact
                    joint efforts (inverse dynamics with the exact derivatives and the
                    exact wrench), for comparison with the estimate
  /ft_sensor/wrench geometry_msgs/WrenchStamped, header.frame_id = SENSOR (a URDF
                    link), the wrench applied TO the robot, moment about SENSOR's
                    origin, in SENSOR's frame
both at RATE, stamped t0 + i / RATE (t0 = 1000 s, i = 0 .. N-1, N = round(DURATION *
RATE) or --samples). Bag time = stamp for the joint states, stamp - 1 us for the
wrenches: whoever reads the bag in time order (rosbag play, process_bag) gets the
wrench of an instant before the joint state of that instant (at equal bag times the
order of rosbag's reader is not defined).

Trajectory: each coordinate k (model.coordinate_names order)
  q_k(t) = c_k + A_k sin(w_k t + p_k),  w_k = 2 pi f_k,  t = stamp - t0
with c_k the Panda's "ready" pose for panda_joint1..7 (0, -pi/4, 0, -3 pi/4, 0, pi/2,
pi/4), 0.02 m for panda_finger_joint1 and 0 for any other joint; A_k in [0.15, 0.45)
rad (revolute) or [0.005, 0.015) m (prismatic); f_k in [0.1, 0.4) Hz; p_k in [0, 2 pi).
Wrench: a point payload of mass m in [0.5, 2) kg held at the origin of TCP, and a
horizontal push at the same point,
  F_world(t) = P sin(w_p t + p_p) (cos b, sin b, 0),  P in [5, 15) N,
  w_p = 2 pi f_p, f_p in [0.2, 0.6) Hz, p_p in [0, 2 pi), b in [0, 2 pi);
the payload applies -m (a - g) to the robot, a its acceleration (exact, from the
trajectory), g = (0, 0, -9.80665) m/s^2. The wrench is their sum at TCP, moved to
SENSOR's origin and frame.

Random numbers: std::mt19937 seeded with SEED; u = (a * 2^26 + b) / 2^53 with
a = (first draw) >> 5, b = (second draw) >> 6, in [0, 1); a number in [lo, hi) is
lo + (hi - lo) u. Draw order: A_k, f_k, p_k for each coordinate, then m, P, f_p, p_p, b.
So the bag is the same with every standard library (and bit for bit wherever sin and
cos are, e.g. glibc).

  --urdf PATH          the robot (a fixed base), e.g. test/data/urdf/panda_demo.urdf
  --output PATH        the bag; written beside PATH and renamed onto it on success only
  --duration S         seconds covered, > 0 (default 10)
  --rate HZ            samples per second, > 0 (default 1000)
  --samples N          number of samples instead of DURATION * RATE (benchmarks)
  --seed N             0 .. 4294967295 (default 1)
  --effort             add the exact efforts to the joint states
  --sensor-frame LINK  the sensor's frame (default panda_link8)
  --tcp-frame LINK     where the payload and the push act (default panda_hand_tcp)
  --help               this text

Exit status: 0 success; 1 a data error (unreadable URDF, unwritable bag); 2 a usage
error (unknown, missing or repeated option, bad value, unknown LINK).
)";

constexpr double kTwoPi = 6.283185307179586;
constexpr double kPi = 3.141592653589793;
constexpr std::int64_t kEpochNs = 1000000000000LL;  // t0 = 1000 s

struct Options {
  std::string urdf, output;
  std::string sensor_frame = "panda_link8", tcp_frame = "panda_hand_tcp";
  double duration = 10.0;
  double rate = 1000.0;
  long long samples = -1;
  std::uint32_t seed = 1;
  bool effort = false;
};

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v =
      optionValues(argc, argv,
                   {"--urdf", "--output", "--duration", "--rate", "--samples", "--seed",
                    "--sensor-frame", "--tcp-frame"},
                   {"--effort"});
  Options options;
  options.urdf = requiredValue(v, "--urdf", "ROBOT.urdf");
  options.output = requiredValue(v, "--output", "OUT.bag");
  options.effort = v.count("--effort") > 0;
  if (v.count("--sensor-frame")) options.sensor_frame = v["--sensor-frame"];
  if (v.count("--tcp-frame")) options.tcp_frame = v["--tcp-frame"];
  if (v.count("--duration")) options.duration = parseNumber("--duration", v["--duration"]);
  if (v.count("--rate")) options.rate = parseNumber("--rate", v["--rate"]);
  if (!(options.duration > 0.0)) throw UsageError("--duration: must be > 0");
  if (!(options.rate > 0.0)) throw UsageError("--rate: must be > 0");
  if (v.count("--samples")) {
    if (v.count("--duration")) throw UsageError("--samples and --duration exclude each other");
    options.samples =
        static_cast<long long>(parseInteger("--samples", v["--samples"], 1, 1000000000));
  } else {
    if (options.duration * options.rate > 1e9) throw UsageError("--duration * --rate: over 1e9");
    options.samples = std::max(1LL, std::llround(options.duration * options.rate));
  }
  if (v.count("--seed"))
    options.seed =
        static_cast<std::uint32_t>(parseInteger("--seed", v["--seed"], 0, 4294967295ULL));
  return options;
}

double homePosition(const std::string& joint) {
  static const std::map<std::string, double> kReady = {
      {"panda_joint1", 0.0},          {"panda_joint2", -kPi / 4},   {"panda_joint3", 0.0},
      {"panda_joint4", -3 * kPi / 4}, {"panda_joint5", 0.0},        {"panda_joint6", kPi / 2},
      {"panda_joint7", kPi / 4},      {"panda_finger_joint1", 0.02}};
  const auto it = kReady.find(joint);
  return it == kReady.end() ? 0.0 : it->second;
}

int frameOf(const jle::Model<double>& model, const std::string& option, const std::string& link,
            const std::string& urdf) {
  for (std::size_t i = 0; i < model.frames.size(); ++i)
    if (model.frames[i].name == link) return static_cast<int>(i);
  throw UsageError(option + ": no link '" + link + "' in " + urdf);
}

// The sensor's and the TCP's frames (indices into model.frames), checked: the payload is
// rigid to the sensor.
struct SensorFrames {
  int sensor = -1, tcp = -1;
};

SensorFrames sensorFrames(const jle::Model<double>& model, const Options& options) {
  SensorFrames frames;
  frames.sensor = frameOf(model, "--sensor-frame", options.sensor_frame, options.urdf);
  frames.tcp = frameOf(model, "--tcp-frame", options.tcp_frame, options.urdf);
  if (model.frames[static_cast<std::size_t>(frames.sensor)].segment !=
      model.frames[static_cast<std::size_t>(frames.tcp)].segment)
    throw UsageError("--tcp-frame: '" + options.tcp_frame + "' moves relative to '" +
                     options.sensor_frame + "'; the payload must be rigid to the sensor");
  return frames;
}

// The trajectory, the payload and the push, drawn in the documented order (kUsage).
struct Scenario {
  std::vector<double> home, amplitude, omega, phase;  // per coordinate
  double payload_mass = 0.0, push = 0.0, push_omega = 0.0, push_phase = 0.0;
  Eigen::Vector3d push_direction = Eigen::Vector3d::Zero();
};

Scenario randomScenario(const jle::Model<double>& model, std::uint32_t seed) {
  jle::PortableRandom random(seed);
  const std::size_t nq = static_cast<std::size_t>(model.nq);
  Scenario out;
  out.home.resize(nq);
  out.amplitude.resize(nq);
  out.omega.resize(nq);
  out.phase.resize(nq);
  for (std::size_t k = 0; k < nq; ++k) {
    const std::string& name = model.coordinate_names[k];
    const int s = model.segmentOfJoint(name);
    const bool prismatic =
        model.joint_type[static_cast<std::size_t>(s)] == jle::JointType::kPrismatic;
    out.home[k] = homePosition(name);
    out.amplitude[k] = prismatic ? random.uniform(0.005, 0.015) : random.uniform(0.15, 0.45);
    out.omega[k] = kTwoPi * random.uniform(0.1, 0.4);
    out.phase[k] = random.uniform(0.0, kTwoPi);
  }
  out.payload_mass = random.uniform(0.5, 2.0);
  out.push = random.uniform(5.0, 15.0);
  out.push_omega = kTwoPi * random.uniform(0.2, 0.6);
  out.push_phase = random.uniform(0.0, kTwoPi);
  const double push_bearing = random.uniform(0.0, kTwoPi);
  out.push_direction = Eigen::Vector3d(std::cos(push_bearing), std::sin(push_bearing), 0.0);
  return out;
}

// Positions, velocities and accelerations of the coordinates at t [s].
void coordinatesAt(const Scenario& scenario, double t, jle::VectorX<double>& q,
                   jle::VectorX<double>& qd, jle::VectorX<double>& qdd) {
  for (std::size_t k = 0; k < scenario.home.size(); ++k) {
    const double angle = scenario.omega[k] * t + scenario.phase[k];
    const double sin = std::sin(angle), cos = std::cos(angle);
    const double a = scenario.amplitude[k], w = scenario.omega[k];
    q[static_cast<int>(k)] = scenario.home[k] + a * sin;
    qd[static_cast<int>(k)] = a * w * cos;
    qdd[static_cast<int>(k)] = -a * w * w * sin;
  }
}

// What the payload and the push apply to the robot at t, at the sensor (its frame,
// moment about its origin), after forwardKinematics.
void sensorWrench(const jle::Model<double>& model, const jle::Data<double>& data,
                  const SensorFrames& frames, const Scenario& scenario, double t,
                  Eigen::Vector3d& f_sensor, Eigen::Vector3d& m_sensor) {
  const jle::Frame<double>& sensor = model.frames[static_cast<std::size_t>(frames.sensor)];
  const std::size_t s = static_cast<std::size_t>(sensor.segment);
  // TCP in the segment frame; the sensor's pose in the segment frame.
  const Eigen::Vector3d& r_tcp = model.frames[static_cast<std::size_t>(frames.tcp)].p_segment_frame;
  const Eigen::Matrix3d& R_segment_sensor = sensor.R_segment_frame;
  const Eigen::Vector3d& p_segment_sensor = sensor.p_segment_frame;
  // The payload's acceleration minus gravity at the TCP, segment frame (data.acc is the
  // origin's, gravity included as an upward acceleration of the base).
  const Eigen::Vector3d& w = data.omega[s];
  const Eigen::Vector3d a_minus_g =
      data.acc[s] + data.alpha[s].cross(r_tcp) + w.cross(w.cross(r_tcp));
  const Eigen::Vector3d f_segment =
      -scenario.payload_mass * a_minus_g +
      data.R_world[s].transpose() *
          (scenario.push * std::sin(scenario.push_omega * t + scenario.push_phase) *
           scenario.push_direction);
  f_sensor = R_segment_sensor.transpose() * f_segment;
  m_sensor = R_segment_sensor.transpose() * (r_tcp - p_segment_sensor).cross(f_segment);
}

// The joint-state message of every moving joint, sized once.
sensor_msgs::JointState jointStateMessage(const jle::Model<double>& model, bool effort) {
  sensor_msgs::JointState joints;
  for (int s : model.moving_segments)
    joints.name.push_back(model.joint_name[static_cast<std::size_t>(s)]);
  joints.position.resize(joints.name.size());
  if (effort) joints.effort.resize(joints.name.size());
  return joints;
}

void fillJointState(const jle::Model<double>& model, const jle::Data<double>& data, long long i,
                    const ros::Time& stamp, sensor_msgs::JointState& joints) {
  joints.header.stamp = stamp;
  joints.header.seq = static_cast<std::uint32_t>(i);
  for (std::size_t j = 0; j < model.moving_segments.size(); ++j) {
    const std::size_t seg = static_cast<std::size_t>(model.moving_segments[j]);
    joints.position[j] = data.q[seg];
    if (!joints.effort.empty()) joints.effort[j] = data.effort[seg];
  }
}

void run(const Options& options) {
  const jle::Model<double> model = jle::modelFromUrdfFile(options.urdf);
  if (model.floating_base)
    throw std::runtime_error(options.urdf +
                             ": a floating-base model; make_example_bag moves "
                             "fixed-base arms only");
  const SensorFrames frames = sensorFrames(model, options);
  const Scenario scenario = randomScenario(model, options.seed);
  const Eigen::Vector3d gravity_world(0.0, 0.0, -9.80665);

  // Everything the loop touches is allocated here, once.
  jle::Data<double> data(model);
  jle::VectorX<double> q(model.nq), qd(model.nq), qdd(model.nq);
  sensor_msgs::JointState joints = jointStateMessage(model, options.effort);
  geometry_msgs::WrenchStamped wrench;
  wrench.header.frame_id = options.sensor_frame;
  jle_tools::PartialBag out(options.output);
  for (long long i = 0; i < options.samples; ++i) {
    const std::int64_t ns = kEpochNs + std::llround(static_cast<double>(i) * 1e9 / options.rate);
    const ros::Time stamp = jle_tools::stampOf(ns);
    const double t = static_cast<double>(ns - kEpochNs) * 1e-9;
    coordinatesAt(scenario, t, q, qd, qdd);
    jle::forwardKinematics(model, data, q, qd, qdd, gravity_world);
    Eigen::Vector3d f_sensor, m_sensor;
    sensorWrench(model, data, frames, scenario, t, f_sensor, m_sensor);
    wrench.header.stamp = stamp;
    jle_tools::setWrench(wrench, f_sensor, m_sensor);
    out.bag().write("/ft_sensor/wrench", stamp - ros::Duration(0, 1000), wrench);
    if (options.effort) {
      jle::addExternalWrench(model, data, frames.sensor, f_sensor, m_sensor,
                             jle::WrenchFrame::kLocal);
      jle::inverseDynamics(model, data);
    }
    fillJointState(model, data, i, stamp, joints);
    out.bag().write("/joint_states", stamp, joints);
  }
  out.commit();
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "make_example_bag", kUsage, parseOptions, run);
}
