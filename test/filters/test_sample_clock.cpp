// The sample clock (sample_clock.hpp) against the instants the samples were taken at
// (GroundTruth readings: JointReading::time beside its stamp): exact stamps and
// irregular streams kept bit for bit; receive-time stamps of a periodic stream (jitter,
// drops, gaps up to 10 periods, bursts) brought back to the instants; and, through the
// Pipeline on a Panda at 1 kHz, the effort error with and without stamps/regularize.
#include <joint_load_estimator/filters/sample_clock.hpp>
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <jle_testing/ground_truth.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>

namespace {

using Stamp = std::int64_t;
const std::string kData = JLE_TEST_DATA;
constexpr Stamp kStart = 1700000000123456789;  // [ns]

Stamp ns(double t) { return kStart + std::llround(t * 1e9); }

jle::Model<double> panda() { return jle::modelFromUrdfFile(kData + "/urdf/panda.urdf"); }

jle::GroundTruth pandaTruth() {
  const jle::Model<double> model = panda();
  return jle::GroundTruth(model, jle::randomMotion(model, jle::MotionKind::kSines, 6.0, 5),
                          {jle::randomWrench("panda_hand", 9)});
}

// Stamps taken at reception: gaussian error of 5% of the period (+-10% at 2 sigma,
// truncated at 20%), 2% of the samples dropped, a gap of 3..10 periods every 0.5 s and
// every 0.7 s a burst (three samples late, received with the fourth, 10 us apart).
jle::SensorReadings receiveStamped(const jle::GroundTruth& truth, double rate,
                                   double position_noise, bool with_bursts = true) {
  jle::SensorModel sensor;
  sensor.rate = rate;
  sensor.stamp_jitter = 0.05 / rate;
  sensor.drop_probability = 0.02;
  sensor.position_noise = position_noise;
  jle::SensorReadings r = truth.sample(sensor, 6.0, 17);
  const long block = std::max(20L, std::lround(0.5 * rate)), burst = std::lround(0.7 * rate);
  std::vector<jle::JointReading> kept;
  std::vector<std::size_t> late;
  for (const jle::JointReading& j : r.joints) {
    const long k = std::lround(j.time * rate);  // exact instants: sample k at k / rate
    if (k >= block && k % block < 3 + (k / block) % 8) continue;
    if (with_bursts && k > 0 && k % burst == 0) late.push_back(kept.size());
    kept.push_back(j);
  }
  for (const std::size_t b : late)
    if (b + 3 < kept.size())
      for (std::size_t i = 0; i < 3; ++i)
        kept[b + i].stamp = kept[b + 3].stamp - static_cast<double>(3 - i) * 1e-5;
  r.joints = kept;
  return r;
}

double rms(double sum_squares, long n) { return std::sqrt(sum_squares / static_cast<double>(n)); }

TEST(SampleClock, ExactStampsAreKeptBitForBit) {
  for (const double rate : {1000.0, 300.0, 100.0}) {
    jle::SampleClock clock(true);
    for (int k = 0; k < 2000; ++k) {
      if (k % 7 == 3) continue;  // dropped samples: the stamps stay exact
      const Stamp stamp = kStart + std::llround(k * 1e9 / rate);
      ASSERT_EQ(clock.add(stamp), stamp) << rate << " Hz, sample " << k;
    }
    EXPECT_FALSE(clock.regular());
    EXPECT_NEAR(clock.period(), 1e9 / rate, 1e-3);  // [ns] rounding of the stamps only
  }
}

TEST(SampleClock, IrregularStreamsKeepTheirStamps) {
  // Spacings uniform in [0.3, 1.7) ms, and two publishers (1 kHz, 300 Hz) merged: no
  // lattice fits either.
  jle::PortableRandom random(3);
  jle::SampleClock walk(true), merged(true);
  Stamp stamp = kStart;
  for (int k = 0; k < 3000; ++k) {
    stamp += 300000 + static_cast<Stamp>(random.uniform() * 1.4e6);
    ASSERT_EQ(walk.add(stamp), stamp) << k;
  }
  EXPECT_FALSE(walk.regular());
  std::map<Stamp, int> both;
  for (int k = 0; k < 3000; ++k) both[kStart + Stamp{k} * 1000000] = 0;
  for (int k = 0; k < 900; ++k) both[kStart + std::llround(k * 1e9 / 300.0) + 250000] = 1;
  for (const auto& s : both) ASSERT_EQ(merged.add(s.first), s.first);
  EXPECT_FALSE(merged.regular());
}

TEST(SampleClock, ReceiveTimeStampsGiveTheInstants) {
  const jle::GroundTruth truth = pandaTruth();
  for (const double rate : {100.0, 200.0, 1000.0, 10000.0}) {
    const jle::SensorReadings r = receiveStamped(truth, rate, 0.0);
    jle::SampleClock clock(true);
    // [periods^2] over the samples of no burst (a late one and the three after it,
    // which follow its instant), and over all.
    double stamp_ss = 0.0, instant_ss = 0.0, all_ss = 0.0, worst = 0.0;
    long n = 0, all = 0, not_regular = 0, burst = 0;
    for (const jle::JointReading& j : r.joints) {
      const Stamp instant = clock.add(ns(j.stamp));
      const double e = static_cast<double>(instant - ns(j.time)) * 1e-9 * rate;
      const double e_stamp = (j.stamp - j.time) * rate;
      burst = e_stamp > 0.25 ? 4 : burst - 1;
      if (j.time < 0.5) continue;  // the window fills
      not_regular += !clock.regular();
      all_ss += e * e;
      ++all;
      if (burst > 0) continue;
      instant_ss += e * e;
      stamp_ss += e_stamp * e_stamp;
      worst = std::max(worst, std::abs(e));
      ++n;
    }
    std::printf(
        "%6.0f Hz: RMS instant error %.4f periods (stamps %.4f), worst %.3f; with the "
        "bursts %.4f; %ld of %ld not detected\n",
        rate, rms(instant_ss, n), rms(stamp_ss, n), worst, rms(all_ss, all), not_regular, all);
    EXPECT_EQ(not_regular, 0) << rate << " Hz";
    // A least-squares line over 128 samples: its end is known to about 2/sqrt(128) of
    // the stamps' scatter (0.05 periods).
    EXPECT_LT(rms(instant_ss, n), 0.5 * rms(stamp_ss, n)) << rate << " Hz";
    EXPECT_LT(worst, 0.15) << rate << " Hz";
  }
}

// The Panda at 1 kHz, positions (noise 2e-4 rad) and an F/T reading at the hand, with
// receive-time stamps: the default settings with stamps/regularize auto against off. The
// published loads carry the messages' own stamps; each is scored against the truth at
// the instant its sample was taken.
struct Scored {
  double effort_rms = 0.0;  // [N m] over the joints and samples after 0.5 s
  long published = 0;
};

Scored runPanda(const jle::GroundTruth& truth, const jle::SensorReadings& r,
                jle::StampRegularize regularize) {
  const jle::Model<double> model = panda();
  jle::Settings settings;
  settings.stamps.regularize = regularize;
  jle::WrenchInputConfig input;
  input.name = "ft";
  input.link = "panda_hand";
  settings.estimator.wrenches.push_back(input);
  settings.wrenches.emplace_back().topic = "ft";
  jle::Pipeline pipeline(model, settings, nullptr);
  std::map<Stamp, double> time_of;
  for (const jle::JointReading& j : r.joints) time_of[ns(j.stamp)] = j.time;
  jle::Data<double> exact(truth.model());
  std::vector<double> q(static_cast<std::size_t>(model.nq));
  double ss = 0.0;
  long n = 0;
  Scored out;
  std::size_t w = 0;
  for (const jle::JointReading& j : r.joints) {
    for (; w < r.wrenches.size() && r.wrenches[w].stamp <= j.stamp; ++w)
      pipeline.onWrench(0, ns(r.wrenches[w].stamp), ns(r.wrenches[w].stamp), "panda_hand",
                        r.wrenches[w].force, r.wrenches[w].moment);
    for (int i = 0; i < model.nq; ++i) q[static_cast<std::size_t>(i)] = j.q[i];
    if (pipeline.onJointState(ns(j.stamp), ns(j.stamp), model.coordinate_names, q, {}, {}) !=
        jle::Outcome::kPublished)
      continue;
    ++out.published;
    const jle::LoadsRecord& rec = pipeline.record();
    const double t = time_of.at(rec.stamp);
    if (t < 0.5) continue;
    truth.loads(t, exact);
    for (std::size_t i = 0; i < rec.segment.size(); ++i) {
      const double e = rec.effort[i] - exact.effort[static_cast<std::size_t>(rec.segment[i])];
      ss += e * e;
      ++n;
    }
  }
  out.effort_rms = rms(ss, n);
  return out;
}

TEST(SampleClock, RegularisedInstantsLowerTheEffortErrorOfAPandaAt1kHz) {
  const jle::GroundTruth truth = pandaTruth();
  for (const bool bursts : {false, true})
    for (const double noise : {0.0, 2e-4}) {
      const jle::SensorReadings r = receiveStamped(truth, 1000.0, noise, bursts);
      const Scored on = runPanda(truth, r, jle::StampRegularize::kAuto);
      const Scored off = runPanda(truth, r, jle::StampRegularize::kOff);
      std::printf(
          "Panda 1 kHz, receive-time stamps%s, position noise %g rad: RMS effort error "
          "%.4f N m (regularize auto), %.4f N m (off)\n",
          bursts ? " with bursts" : "", noise, on.effort_rms, off.effort_rms);
      EXPECT_EQ(on.published, off.published);  // the same messages are used
      // Noise-free, the instants' error is the effort's: 0.0067 against 0.0212 N m
      // without bursts. The encoder noise of 2e-4 rad outweighs the stamps' 5e-5 s
      // (the motion's 0.5 rad/s times 5e-5 s is 2.5e-5 rad): no worse, within 1%.
      if (noise == 0.0)
        EXPECT_LT(on.effort_rms, off.effort_rms);
      else
        EXPECT_LT(on.effort_rms, 1.01 * off.effort_rms);
    }
}

}  // namespace
