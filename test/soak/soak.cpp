// Soak: 1e6 joint samples of a 7-joint arm (the Panda chain) at 1 kHz of simulated time
// through the node's message path (jle::Pipeline, with the default settings and a wrench
// input), as fast as it runs, with bad messages mixed in every 50 samples: NaN
// positions, a position array of the wrong length, a duplicate stamp, a backward stamp,
// an unknown joint name, a NaN wrench, a backward wrench, and what no arm produces (a
// position of 1e300 rad, one joint 3 rad off for one message, a wrench of 1e300 N); and
// every 50 samples one good sample split over two publishers (joints 0-3 stamped 0.2 ms
// before joints 4-6), to be merged into one sample.
// Checks that
//  - memory stays flat: VmRSS at 100% of the samples exceeds VmRSS at 10% by < 1 MB;
//  - no good sample is lost: every good sample after the filter's warm-up is published
//    (the warm-up happening once, at the start);
//  - every bad message is counted under its own reason (the pipeline's counters), as
//    many times as it was injected;
//  - every load published is finite, and trusted once the filters have settled.
// Prints the figures; exits 1 on a failed check. Usage: soak [SAMPLES (default 1000000)]
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
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

enum Bad {
  kNan,
  kLength,
  kDuplicate,
  kBackward,
  kUnknown,
  kWrenchNan,
  kWrenchBackward,
  kAbsurd,
  kGlitch,
  kWrenchAbsurd,
  kKinds
};
const char* const kBadName[kKinds] = {
    "nan_position", "wrong_length",    "duplicate_stamp", "backward_stamp", "unknown_joint",
    "nan_wrench",   "backward_wrench", "absurd_position", "glitch_3_rad",   "absurd_wrench"};

}  // namespace

const char* const kUsage =
    "usage: soak [SAMPLES]\n"
    "SAMPLES (default 1000000) joint samples of the Panda chain at 1 kHz through the node's\n"
    "message path with bad messages mixed in every 50 samples; checks that memory stays\n"
    "flat, no good sample is lost and every bad message is counted under its reason. Exits 1\n"
    "on a failed check.\n";

int main(int argc, char** argv) {
  if (jle::cli::answerHelpOrVersion(argc, argv, "soak", kUsage)) return 0;
  using jle::InputKind;
  using jle::Outcome;
  const long samples = argc > 1 ? std::atol(argv[1]) : 1000000;
  const jle::Model<double> model =
      jle::modelFromUrdfFile(JLE_TEST_DATA "/urdf/chains/panda_chain.urdf");
  jle::Settings settings;  // the defaults, as the node runs them, and one wrench input
  jle::WrenchInputConfig ft;
  ft.name = "ft";
  ft.link = "panda_link8";
  settings.estimator.wrenches.push_back(ft);
  jle::WrenchTopicSettings topic;
  topic.topic = "ft";
  settings.wrenches.push_back(topic);
  jle::Pipeline pipeline(model, settings, nullptr);
  const int nq = model.nq;
  const jle::Stamp dt = 1000000;  // [ns] 1 kHz
  const std::string frame = "panda_link8";

  std::vector<std::string> names = model.coordinate_names, names_unknown = names;
  names_unknown.push_back("ghost_joint");
  std::vector<double> position(static_cast<std::size_t>(nq)),
      position_unknown(names_unknown.size());
  const std::vector<double> none;
  std::vector<double> short_position(static_cast<std::size_t>(nq - 1), 0.0);

  long injected[kKinds] = {};
  long good = 0, published = 0, warming = 0, late_warming = 0, other = 0;
  long nonfinite = 0, untrusted = 0;  // published loads: not finite; flagged after 1 s
  long split = 0, split_wrong = 0;    // samples split over two publishers; not merged
  const std::vector<std::string> names_a(model.coordinate_names.begin(),
                                         model.coordinate_names.begin() + 4),
      names_b(model.coordinate_names.begin() + 4, model.coordinate_names.end());
  long rss_10 = -1;
  // The clock (the node's ros::Time::now()) goes on at the pace of the good samples; a
  // bad message's stamp is its own.
  jle::Stamp now = 0;
  auto message = [&](jle::Stamp stamp, const std::vector<std::string>& n,
                     const std::vector<double>& p) {
    return pipeline.onJointState(stamp, now, n, p, none, none);
  };

  const auto start = std::chrono::steady_clock::now();
  for (long i = 0; i < samples; ++i) {
    if (i == samples / 10) rss_10 = vmRssKb();
    const jle::Stamp stamp = 1700000000000000000 + i * dt;
    now = stamp;
    const double t = 1.0 + static_cast<double>(i) * 1e-3;
    for (int k = 0; k < nq; ++k)
      position[static_cast<std::size_t>(k)] = 0.5 * std::sin(2.0 * M_PI * (0.2 + 0.05 * k) * t + k);
    const Eigen::Vector3d f(10.0 * std::sin(t), 2.0, -5.0), m(0.1, 0.2 * std::cos(t), 0.0);
    if (pipeline.onWrench(0, stamp, now, frame, f, m) != Outcome::kUsed) ++other;

    // The good sample (every 50th carries an unknown joint name besides the 7).
    Outcome s;
    if (i % 50 == 25) {
      ++injected[kUnknown];
      for (int k = 0; k < nq; ++k)
        position_unknown[static_cast<std::size_t>(k)] = position[static_cast<std::size_t>(k)];
      position_unknown.back() = 1.0;
      s = message(stamp, names_unknown, position_unknown);
    } else if (i % 50 == 40 && i > 1000) {  // split: the first half waits for the second
      ++split;
      const Outcome first =
          message(stamp - dt / 5, names_a, {position.begin(), position.begin() + 4});
      s = message(stamp, names_b, {position.begin() + 4, position.end()});
      split_wrong += first != Outcome::kMerged || s != Outcome::kPublished;
    } else {
      s = message(stamp, names, position);
    }
    ++good;
    if (s == Outcome::kPublished) {
      ++published;
      const jle::LoadsRecord& r = pipeline.record();
      for (double e : r.effort) nonfinite += !std::isfinite(e);
      untrusted += i > 1000 && r.status != jle::kTrusted;
    } else if (s == Outcome::kUsed)
      (published == 0 ? warming : late_warming)++;
    else
      ++other;

    // The bad messages, after it.
    if (i % 50 != 10) continue;
    const jle::Stamp half = dt / 2;
    switch ((i / 50) % 9) {
      case 0: {  // a NaN position: refused before it reaches the filters
        ++injected[kNan];
        std::vector<double> p = position;
        p[3] = std::numeric_limits<double>::quiet_NaN();
        message(stamp + half, names, p);
        break;
      }
      case 1:
        ++injected[kLength];
        message(stamp + half, names, short_position);
        break;
      case 2:
        ++injected[kDuplicate];
        message(stamp, names, position);
        break;
      case 3:
        ++injected[kBackward];
        message(stamp - half, names, position);
        break;
      case 6: {  // finite but absurd: refused at the door, counted implausible
        ++injected[kAbsurd];
        std::vector<double> p = position;
        p[1] = 1e300;
        message(stamp + half, names, p);
        break;
      }
      case 7: {  // one joint 3 rad off for one message: faster than it can move
        ++injected[kGlitch];
        std::vector<double> p = position;
        p[2] += 3.0;
        message(stamp + half, names, p);
        break;
      }
      case 8:
        ++injected[kWrenchAbsurd];
        pipeline.onWrench(0, stamp + half, now, frame, Eigen::Vector3d(0, 0, 1e300), m);
        break;
      case 4:
        ++injected[kWrenchNan];
        pipeline.onWrench(0, stamp + half, now, frame,
                          Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 0), m);
        break;
      default:
        ++injected[kWrenchBackward];
        pipeline.onWrench(0, stamp - half, now, frame, f, m);
        break;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const long rss_100 = vmRssKb();
  const jle::PipelineCounters& c = pipeline.counters();
  // What the pipeline counted, per kind of bad message (NaN and wrong length are both
  // invalid joint states, duplicate and backward both out of order).
  const long counted[kKinds] = {
      c.count(InputKind::kJointState, Outcome::kInvalid) - injected[kLength],
      c.count(InputKind::kJointState, Outcome::kInvalid) - injected[kNan],
      c.count(InputKind::kJointState, Outcome::kOrder) - injected[kBackward],
      c.count(InputKind::kJointState, Outcome::kOrder) - injected[kDuplicate],
      c.unknown_joints,
      c.count(InputKind::kWrench, Outcome::kInvalid),
      c.count(InputKind::kWrench, Outcome::kOrder),
      c.count(InputKind::kJointState, Outcome::kImplausible) - injected[kGlitch],
      c.count(InputKind::kJointState, Outcome::kImplausible) - injected[kAbsurd],
      c.count(InputKind::kWrench, Outcome::kImplausible)};

  bool ok = true;
  auto expect = [&](bool cond, const char* what) {
    if (!cond) {
      std::printf("FAILED: %s\n", what);
      ok = false;
    }
  };
  std::printf("samples %ld in %.2f s (%.2f us/sample, %.0f simulated s)\n", samples, seconds,
              1e6 * seconds / static_cast<double>(samples), static_cast<double>(samples) * 1e-3);
  std::printf("VmRSS at 10%%: %ld kB, at 100%%: %ld kB, growth %ld kB (limit 1024)\n", rss_10,
              rss_100, rss_100 - rss_10);
  std::printf("good %ld: published %ld, warming up %ld at the start, %ld later, other %ld\n", good,
              published, warming, late_warming, other);
  for (int k = 0; k < kKinds; ++k)
    std::printf("bad %-16s injected %7ld counted %7ld\n", kBadName[k], injected[k], counted[k]);
  expect(rss_10 > 0 && rss_100 - rss_10 < 1024, "VmRSS grew by 1 MB or more");
  expect(warming > 0 && warming < 20 && late_warming == 0,
         "warm-up is not a few samples, once, at the start");
  expect(published == good - warming, "a good sample was not published");
  expect(other == 0, "a good sample or wrench got another outcome");
  std::printf("published loads not finite: %ld; flagged untrusted after 1 s: %ld\n", nonfinite,
              untrusted);
  expect(nonfinite == 0, "a published load is not finite");
  expect(untrusted == 0, "a load after the filters settled is flagged untrusted");
  std::printf("split over two publishers: %ld samples, merged %ld, not merged %ld, held %ld\n",
              split, c.count(InputKind::kJointState, Outcome::kMerged), split_wrong,
              c.held_samples);
  expect(split > 0 && split_wrong == 0 &&
             c.count(InputKind::kJointState, Outcome::kMerged) == split && c.held_samples == 0,
         "a sample split over two publishers was not merged into one");
  expect(c.received(InputKind::kJointState) == split + good + injected[kNan] + injected[kLength] +
                                                   injected[kDuplicate] + injected[kBackward] +
                                                   injected[kAbsurd] + injected[kGlitch],
         "a joint state was not counted");
  for (int k = 0; k < kKinds; ++k)
    expect(injected[k] > 0 && counted[k] == injected[k], kBadName[k]);
  std::printf("soak: %s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
