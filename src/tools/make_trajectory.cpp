// make_trajectory: a deterministic analytic joint-state CSV (and optionally an applied
// wrench) for joint_loads. The formula is in kUsage and docs/joint_loads.md.
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/io/csv.hpp>
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

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
    R"(usage: make_trajectory --urdf ROBOT.urdf [--duration 2.0] [--rate 1000] [--seed 1]
                       [--wrench LINK] [--output FILE]

Writes a joint-state CSV for joint_loads (docs/joint_loads.md): columns t, then
JOINT.q, JOINT.qd, JOINT.qdd for every joint with its own coordinate (mimic joints
left out), then with --wrench wrench@LINK.fx,.fy,.fz,.mx,.my,.mz. Rows at
t = i / RATE for i = 0 .. round(DURATION * RATE). Numbers with %.17g.

Every coordinate is a sum of n = 2 or 3 sines, and qd, qdd are its exact derivatives:
  q(t)   =  sum_j A_j sin(w_j t + p_j)
  qd(t)  =  sum_j A_j w_j cos(w_j t + p_j)
  qdd(t) = -sum_j A_j w_j^2 sin(w_j t + p_j)
with w_j = 2 pi f_j, f_j in [0.1, 0.8) Hz, p_j in [0, 2 pi), A_j in [0.05, 0.4) rad
(revolute, continuous) or [0.002, 0.01) m (prismatic). Each wrench component is
  c(t) = B0 + B1 sin(w t + p),  w = 2 pi f, f in [0.1, 1) Hz, p in [0, 2 pi),
B0 in [-10, 10) N and B1 in [0, 10) N for fx, fy, fz; [-1, 1) and [0, 1) N m for mx, my, mz.

Random numbers: std::mt19937 seeded with SEED; u = (a * 2^26 + b) / 2^53 with
a = (first draw) >> 5, b = (second draw) >> 6 (MT19937's genrand_res53, u in [0, 1));
a number in [lo, hi) is lo + (hi - lo) u. Draw order: for each coordinate in the
column order, n = (u < 0.5 ? 2 : 3), then per sine A, f, p; then for each wrench
component fx .. mz: B0, B1, f, p. So the numbers are the same with every standard
library; the printed values are the same wherever sin and cos are (glibc).

  --urdf PATH       the robot
  --duration S      seconds covered, >= 0 (default 2.0)
  --rate HZ         samples per second, > 0 (default 1000)
  --seed N          0 .. 4294967295 (default 1)
  --wrench LINK     add a wrench applied at the origin of URDF link LINK, in its frame
  --output PATH     default: standard output; written to a temporary file beside PATH
                    and renamed onto it on success only
  --help            this text

Exit status: 0 success; 1 a data error (unreadable URDF, unwritable output);
2 a usage error (unknown, missing or repeated option, bad value, unknown LINK).
)";

constexpr double kTwoPi = 6.283185307179586;

struct Options {
  std::string urdf, output, wrench_link;
  double duration = 2.0;
  double rate = 1000.0;
  std::uint32_t seed = 1;
};

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> v = optionValues(
      argc, argv, {"--urdf", "--duration", "--rate", "--seed", "--wrench", "--output"});
  Options options;
  options.urdf = requiredValue(v, "--urdf", "ROBOT.urdf");
  if (v.count("--output")) options.output = v["--output"];
  if (v.count("--wrench")) options.wrench_link = v["--wrench"];
  if (v.count("--duration")) options.duration = parseNumber("--duration", v["--duration"]);
  if (v.count("--rate")) options.rate = parseNumber("--rate", v["--rate"]);
  if (options.duration < 0.0) throw UsageError("--duration: must be >= 0");
  if (!(options.rate > 0.0)) throw UsageError("--rate: must be > 0");
  if (options.duration * options.rate > 1e9) throw UsageError("--duration * --rate: over 1e9 rows");
  if (v.count("--seed"))
    options.seed =
        static_cast<std::uint32_t>(parseInteger("--seed", v["--seed"], 0, 4294967295ULL));
  return options;
}

struct Sine {
  double amplitude = 0.0, omega = 0.0, phase = 0.0;
};

// The trajectory's numbers, in the documented draw order (kUsage).
struct Trajectory {
  std::vector<std::vector<Sine>> coordinates;  // model.coordinate_names order
  std::vector<double> offsets;                 // of the wrench components fx .. mz
  std::vector<Sine> components;                // of the wrench components fx .. mz
};

Trajectory randomTrajectory(const jle::Model<double>& model, bool wrench, std::uint32_t seed) {
  jle::PortableRandom random(seed);
  Trajectory out;
  out.coordinates.resize(static_cast<std::size_t>(model.nq));
  for (int k = 0; k < model.nq; ++k) {
    const int s = model.segmentOfJoint(model.coordinate_names[k]);
    const bool prismatic = model.joint_type[s] == jle::JointType::kPrismatic;
    const int terms = random.uniform() < 0.5 ? 2 : 3;
    for (int j = 0; j < terms; ++j) {
      Sine sine;
      sine.amplitude = prismatic ? random.uniform(0.002, 0.01) : random.uniform(0.05, 0.4);
      sine.omega = kTwoPi * random.uniform(0.1, 0.8);
      sine.phase = random.uniform(0.0, kTwoPi);
      out.coordinates[k].push_back(sine);
    }
  }
  if (wrench)
    for (int i = 0; i < 6; ++i) {
      const double scale = i < 3 ? 10.0 : 1.0;
      out.offsets.push_back(random.uniform(-scale, scale));
      Sine sine;
      sine.amplitude = random.uniform(0.0, scale);
      sine.omega = kTwoPi * random.uniform(0.1, 1.0);
      sine.phase = random.uniform(0.0, kTwoPi);
      out.components.push_back(sine);
    }
  return out;
}

// One row at time t: t, then q, qd, qdd of each coordinate, then the wrench.
void fillRow(const Trajectory& trajectory, double t, double* out) {
  *out++ = t;
  for (const std::vector<Sine>& sines : trajectory.coordinates) {
    double q = 0.0, qd = 0.0, qdd = 0.0;
    for (const Sine& s : sines) {
      const double angle = s.omega * t + s.phase;
      const double sin = std::sin(angle), cos = std::cos(angle);
      q += s.amplitude * sin;
      qd += s.amplitude * s.omega * cos;
      qdd -= s.amplitude * s.omega * s.omega * sin;
    }
    *out++ = q;
    *out++ = qd;
    *out++ = qdd;
  }
  for (std::size_t c = 0; c < trajectory.components.size(); ++c) {
    const Sine& s = trajectory.components[c];
    *out++ = trajectory.offsets[c] + s.amplitude * std::sin(s.omega * t + s.phase);
  }
}

void run(const Options& options) {
  const jle::Model<double> model = jle::modelFromUrdfFile(options.urdf);
  std::vector<std::string> wrench_links;
  if (!options.wrench_link.empty()) {
    bool known = false;
    for (const jle::Frame<double>& f : model.frames) known = known || f.name == options.wrench_link;
    if (!known)
      throw UsageError("--wrench: no link '" + options.wrench_link + "' in " + options.urdf);
    wrench_links.push_back(options.wrench_link);
  }
  const Trajectory trajectory = randomTrajectory(model, !wrench_links.empty(), options.seed);

  const std::vector<std::string> names = jle::stateColumnNames(model, wrench_links);
  std::vector<double> row(names.size());
  jle::CsvWriter writer(options.output);
  writer.writeHeader(names);
  const long long rows = std::llround(options.duration * options.rate);
  for (long long i = 0; i <= rows; ++i) {
    fillRow(trajectory, static_cast<double>(i) / options.rate, row.data());
    writer.writeRow(row.data(), row.size());
  }
  writer.commit();
}

}  // namespace

int main(int argc, char** argv) {
  return jle::cli::runTool(argc, argv, "make_trajectory", kUsage, parseOptions, run);
}
