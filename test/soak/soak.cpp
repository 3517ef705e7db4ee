// Soak: 1e6 joint samples of a 7-joint arm (the Panda chain) at 1 kHz of simulated time
// through the node's message path (jle::JointStateMap, jle::Estimator::addJointSample,
// addWrench), as fast as it runs, with bad messages mixed in every 50 samples: NaN
// positions, a position array of the wrong length, a duplicate stamp, a backward stamp,
// an unknown joint name, a NaN wrench and a backward wrench. Checks that
//  - memory stays flat: VmRSS at 100% of the samples exceeds VmRSS at 10% by < 1 MB;
//  - no good sample is lost: every good sample after the filter's warm-up is kPublished
//    (the warm-up being exactly window - 1 samples, once);
//  - every bad message is counted under its own kind, as many times as it was injected.
// Prints the figures; exits 1 on a failed check. Usage: soak [SAMPLES (default 1000000)]
#include <joint_load_estimator/estimator.hpp>
#include <joint_load_estimator/ros/message_inputs.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#ifndef JLE_TEST_DATA
#error "JLE_TEST_DATA (the path of test/data) must be defined"
#endif

namespace {

long vmRssKb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  return -1;
}

enum Bad { kNan, kLength, kDuplicate, kBackward, kUnknown, kWrenchNan, kWrenchBackward, kKinds };
const char* const kBadName[kKinds] = {"nan_position",  "wrong_length",  "duplicate_stamp",
                                      "backward_stamp", "unknown_joint", "nan_wrench",
                                      "backward_wrench"};

}  // namespace

int main(int argc, char** argv) {
  const long samples = argc > 1 ? std::atol(argv[1]) : 1000000;
  const jle::Model<double> model =
      jle::modelFromUrdfFile(JLE_TEST_DATA "/urdf/chains/panda_chain.urdf");
  jle::EstimatorConfig config;
  config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;  // window 9, causal
  jle::WrenchInputConfig ft;
  ft.name = "ft";
  ft.link = "panda_link8";
  config.wrenches.push_back(ft);
  jle::Estimator estimator(model, config);
  jle::JointStateMap map(model, jle::publishedSegments(model, {}));
  const int nq = model.nq;
  const double dt = 1e-3;

  std::vector<std::string> names = model.coordinate_names, names_unknown = names;
  names_unknown.push_back("ghost_joint");
  std::vector<double> position(static_cast<std::size_t>(nq)), position_unknown(names_unknown.size());
  const std::vector<double> no_effort;
  std::vector<double> short_position(static_cast<std::size_t>(nq - 1), 0.0);

  long injected[kKinds] = {}, counted[kKinds] = {};
  long good = 0, published = 0, warming = 0, other = 0;
  long rss_10 = -1;
  double t = 0.0;

  // What the node does with a joint-state message (size check, map, estimator).
  auto message = [&](double stamp, const std::vector<std::string>& n,
                     const std::vector<double>& p) -> std::optional<jle::SampleStatus> {
    if (p.size() != n.size()) {  // dropped before the map, as the node does
      ++counted[kLength];
      return std::nullopt;
    }
    if (map.update(n, p, no_effort) >= 0) ++counted[kUnknown];
    return estimator.addJointSample(stamp, map.q().data());
  };

  const auto start = std::chrono::steady_clock::now();
  for (long i = 0; i < samples; ++i) {
    if (i == samples / 10) rss_10 = vmRssKb();
    t = 1.0 + static_cast<double>(i) * dt;
    for (int k = 0; k < nq; ++k)
      position[static_cast<std::size_t>(k)] =
          0.5 * std::sin(2.0 * M_PI * (0.2 + 0.05 * k) * t + k);
    const Eigen::Vector3d f(10.0 * std::sin(t), 2.0, -5.0), m(0.1, 0.2 * std::cos(t), 0.0);
    if (!estimator.addWrench(0, t, f, m)) ++other;

    // The good sample (every 50th carries an unknown joint name besides the 7).
    std::optional<jle::SampleStatus> s;
    if (i % 50 == 25) {
      ++injected[kUnknown];
      for (int k = 0; k < nq; ++k) position_unknown[static_cast<std::size_t>(k)] = position[static_cast<std::size_t>(k)];
      position_unknown.back() = 1.0;
      s = message(t, names_unknown, position_unknown);
    } else {
      s = message(t, names, position);
    }
    ++good;
    if (!s) ++other;
    else if (*s == jle::SampleStatus::kPublished) ++published;
    else if (*s == jle::SampleStatus::kWarmingUp) ++warming;
    else ++other;

    // The bad messages, after it.
    if (i % 50 != 10) continue;
    switch ((i / 50) % 6) {
      case 0: {  // a NaN position: the estimator refuses the sample
        ++injected[kNan];
        std::vector<double> p = position;
        p[3] = std::numeric_limits<double>::quiet_NaN();
        s = message(t + 0.5 * dt, names, p);
        if (s && *s == jle::SampleStatus::kNonFinite) ++counted[kNan];
        // The next good message carries every joint, so the NaN does not linger.
        break;
      }
      case 1:
        ++injected[kLength];
        message(t + 0.5 * dt, names, short_position);
        break;
      case 2:
        ++injected[kDuplicate];
        s = message(t, names, position);
        if (s && *s == jle::SampleStatus::kDuplicate) ++counted[kDuplicate];
        break;
      case 3:
        ++injected[kBackward];
        s = message(t - 0.5 * dt, names, position);
        if (s && *s == jle::SampleStatus::kOutOfOrder) ++counted[kBackward];
        break;
      case 4:
        ++injected[kWrenchNan];
        if (!estimator.addWrench(0, t + 0.5 * dt,
                                 Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 0), m))
          ++counted[kWrenchNan];
        break;
      default:
        ++injected[kWrenchBackward];
        if (!estimator.addWrench(0, t - 0.5 * dt, f, m)) ++counted[kWrenchBackward];
        break;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const long rss_100 = vmRssKb();

  bool ok = true;
  auto expect = [&](bool c, const char* what) {
    if (!c) {
      std::printf("FAILED: %s\n", what);
      ok = false;
    }
  };
  std::printf("samples %ld in %.2f s (%.2f us/sample, %.0f simulated s)\n", samples, seconds,
              1e6 * seconds / static_cast<double>(samples), static_cast<double>(samples) * dt);
  std::printf("VmRSS at 10%%: %ld kB, at 100%%: %ld kB, growth %ld kB (limit 1024)\n", rss_10,
              rss_100, rss_100 - rss_10);
  std::printf("good %ld: published %ld, warming up %ld (window - 1 = %d), other %ld\n", good,
              published, warming, config.differentiator.window - 1, other);
  for (int k = 0; k < kKinds; ++k)
    std::printf("bad %-16s injected %7ld counted %7ld\n", kBadName[k], injected[k], counted[k]);
  expect(rss_10 > 0 && rss_100 - rss_10 < 1024, "VmRSS grew by 1 MB or more");
  expect(warming == config.differentiator.window - 1, "warm-up is not window - 1 samples");
  expect(published == good - warming, "a good sample was not published");
  expect(other == 0, "a good sample or wrench got another status");
  for (int k = 0; k < kKinds; ++k) expect(injected[k] > 0 && counted[k] == injected[k], kBadName[k]);
  std::printf("soak: %s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
