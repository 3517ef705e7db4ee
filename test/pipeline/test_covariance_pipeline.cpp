// The published uncertainty through the node's own message path (jle::Pipeline, as the
// node and process_bag run it) with the node's defaults (the constant-jerk Kalman filter,
// uncertainty.period 0.018 s): the effort sigma against the one computed at every sample
// (period 0) from the first sample on, through a gap and after a reset; and against a
// Monte Carlo of noisy replays at start-up, while the filter settles, and after.
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <jle_testing/ground_truth.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using jle::Outcome;
using jle::Stamp;

const std::string kData = JLE_TEST_DATA;
constexpr Stamp kStart = 1700000000000000000;  // [ns]
constexpr Stamp kMs = 1000000;
const std::vector<double> kNone;

// A clean 1 kHz Panda recording, positions only, stated position noise 1e-4 rad (the
// case of issue 19: 40 ms after the start, the default period published 8.8x the exact
// sigma).
struct PandaRecording {
  jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/panda.urdf");
  jle::GroundTruth truth{model, jle::randomMotion(model, jle::MotionKind::kSines, 5.0, 11), {}};

  std::vector<double> positions(double t) const {
    Eigen::VectorXd q, qd, qdd;
    truth.coordinates(t, q, qd, qdd);
    return std::vector<double>(q.data(), q.data() + q.size());
  }
};

jle::Settings defaults(double period) {
  jle::Settings s;  // the node's defaults: the Kalman filter, stamps as instants
  s.estimator.uncertainty.enabled = true;
  s.estimator.uncertainty.position_noise = 1e-4;
  s.estimator.uncertainty.period = period;
  return s;
}

// One message of the recording: stamp k ms after kStart (the bag's time is the stamp:
// going back, it confirms a jump, as in a looping bag), positions of the motion's time t.
struct Message {
  Stamp stamp;
  double t;  // [s] the motion's time
};

// Start-up, then a 100 ms gap at 0.6 s, then the recording starting again from its
// beginning (a looping bag: the filters reset), 1 kHz throughout.
std::vector<Message> startGapAndLoop() {
  std::vector<Message> m;
  for (int k = 0; k < 600; ++k) m.push_back({kStart + k * kMs, k * 1e-3});
  for (int k = 700; k < 1100; ++k) m.push_back({kStart + k * kMs, k * 1e-3});
  for (int k = 0; k < 400; ++k) m.push_back({kStart + k * kMs, k * 1e-3});
  return m;
}

struct Published {
  std::size_t message;        // index in the message list
  std::vector<double> sigma;  // effort_stddev per published joint
};

std::vector<Published> replay(const PandaRecording& rec, const jle::Settings& settings,
                              const std::vector<Message>& messages, long* resets = nullptr) {
  jle::Pipeline pipeline(rec.model, settings, nullptr);
  std::vector<Published> out;
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const Message& m = messages[i];
    const Outcome o = pipeline.onJointState(m.stamp, m.stamp, rec.model.coordinate_names,
                                            rec.positions(m.t), kNone, kNone);
    if (o == Outcome::kPublished) out.push_back({i, pipeline.record().effort_stddev});
  }
  if (resets) *resets = pipeline.counters().resets;
  return out;
}

// Issue 19's bound: with the default period the published sigma is within 5% of the
// exact one at every sample, the start included; here also after a gap of 100 ms (over
// 3 periods) and after the reset of a looping bag, where the filter settles again.
TEST(DefaultPeriodSigma, WithinFivePercentOfTheExactOneFromTheFirstSample) {
  const PandaRecording rec;
  const std::vector<Message> messages = startGapAndLoop();
  long resets = 0;
  const std::vector<Published> exact = replay(rec, defaults(0.0), messages, &resets);
  const std::vector<Published> periodic =
      replay(rec, defaults(jle::UncertaintyConfig().period), messages);
  ASSERT_EQ(resets, 1);  // the loop
  ASSERT_EQ(exact.size(), periodic.size());
  ASSERT_GT(exact.size(), messages.size() - 20);
  // The worst ratio per phase: the first 200 ms, the rest before the gap, the 200 ms
  // after it, and the 200 ms after the loop.
  const char* phase[4] = {"start-up 200 ms", "steady", "after the gap", "after the loop"};
  double worst[4] = {0.0, 0.0, 0.0, 0.0};
  for (std::size_t s = 0; s < exact.size(); ++s) {
    ASSERT_EQ(exact[s].message, periodic[s].message);
    const std::size_t i = exact[s].message;
    const int p = i < 200 ? 0 : i < 600 ? 1 : i < 800 ? 2 : i >= 1000 && i < 1200 ? 3 : 1;
    for (std::size_t j = 0; j < exact[s].sigma.size(); ++j) {
      const double e = exact[s].sigma[j], a = periodic[s].sigma[j];
      ASSERT_GT(e, 0.0) << "joint " << j << " message " << i;
      const double error = std::abs(a / e - 1.0);
      worst[p] = std::max(worst[p], error);
      EXPECT_LE(error, 0.05) << "joint " << j << " message " << i << " (" << phase[p] << "): sigma "
                             << a << " exact " << e;
    }
  }
  for (int p = 0; p < 4; ++p)
    std::printf("default period, %-16s worst |sigma / exact - 1| = %.4f\n", phase[p], worst[p]);
}

// The default filter's covariance against a Monte Carlo through the same path: the
// clean recording published with the default period, then 4000 replays with Gaussian
// encoder noise of the stated 1e-4 rad; at 40 ms (the filter still settling), 120 ms
// and 400 ms, the empirical variance of each effort must match the published sigma^2.
// 4000 samples of a variance: relative standard error sqrt(2 / 4000) = 2.2%, so 12%
// (5.4 of them) fails a true agreement with negligible probability over the 21 terms,
// and fails the 8.8x of issue 19 and a gain missing its settling by far.
TEST(DefaultFilterSigma, MatchesAMonteCarloThroughTheMessagePath) {
  const PandaRecording rec;
  const std::vector<int> instants = {40, 120, 400};
  const int samples = instants.back() + 1;
  std::vector<Message> messages;
  for (int k = 0; k < samples; ++k) messages.push_back({kStart + k * kMs, k * 1e-3});
  const jle::Settings published_settings = defaults(jle::UncertaintyConfig().period);
  // The published effort and sigma of the clean run at each instant.
  std::vector<std::vector<double>> mean(instants.size()), sigma(instants.size());
  std::vector<std::string> joints;
  {
    jle::Pipeline pipeline(rec.model, published_settings, nullptr);
    std::size_t next = 0;
    for (int k = 0; k < samples; ++k) {
      const Outcome o =
          pipeline.onJointState(messages[k].stamp, messages[k].stamp, rec.model.coordinate_names,
                                rec.positions(messages[k].t), kNone, kNone);
      if (next < instants.size() && k == instants[next]) {
        ASSERT_EQ(o, Outcome::kPublished) << k;
        mean[next] = pipeline.record().effort;
        sigma[next] = pipeline.record().effort_stddev;
        joints = pipeline.record().joint;
        ++next;
      }
    }
  }

  jle::Settings noisy = published_settings;
  noisy.estimator.uncertainty.enabled = false;  // plays no part in the loads
  std::vector<std::vector<double>> positions(static_cast<std::size_t>(samples));
  for (int k = 0; k < samples; ++k) positions[k] = rec.positions(messages[k].t);
  const int replays = 4000;
  const std::size_t nj = mean[0].size();
  std::vector<std::vector<double>> sum2(instants.size(), std::vector<double>(nj, 0.0));
  jle::PortableRandom random(19);
  std::vector<double> q;
  for (int r = 0; r < replays; ++r) {
    jle::Pipeline pipeline(rec.model, noisy, nullptr);
    std::size_t next = 0;
    for (int k = 0; k < samples; ++k) {
      q = positions[k];
      for (double& v : q) v += 1e-4 * random.gaussian();
      pipeline.onJointState(messages[k].stamp, messages[k].stamp, rec.model.coordinate_names, q,
                            kNone, kNone);
      if (next < instants.size() && k == instants[next]) {
        for (std::size_t j = 0; j < nj; ++j) {
          const double d = pipeline.record().effort[j] - mean[next][j];
          sum2[next][j] += d * d;
        }
        ++next;
      }
    }
  }
  for (std::size_t n = 0; n < instants.size(); ++n) {
    std::printf("t = %3d ms, empirical / published variance:", instants[n]);
    for (std::size_t j = 0; j < nj; ++j) {
      const double ratio = sum2[n][j] / replays / (sigma[n][j] * sigma[n][j]);
      std::printf(" %.3f", ratio);
      EXPECT_NEAR(ratio, 1.0, 0.12) << joints[j] << " at " << instants[n] << " ms";
    }
    std::printf("\n");
  }
}

}  // namespace
