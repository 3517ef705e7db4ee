// The record of a published sample (record_builder.hpp): a delayed estimate (a smoother's,
// due after later samples, or drained at the end of the stream) carries the stamp and the
// measured efforts of its own sample, as the record of the same sample computed live (by a
// causal filter, at once) does; and each status bit, set where the settings' numbers say
// and not a step beyond.
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/frame_resolver.hpp>
#include <joint_load_estimator/pipeline/record_builder.hpp>
#include <joint_load_estimator/pipeline/timeline.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace {

using jle::Stamp;

const std::string kData = JLE_TEST_DATA;
constexpr Stamp kStart = 1700000000123456789;  // [ns]
constexpr Stamp kMs = 1000000;

// The parts a Pipeline composes around one stream, as it wires them.
struct Stream {
  explicit Stream(const jle::Settings& s)
      : settings(s),
        estimator(jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf"),
                  settings.estimator),
        frames(estimator.model(), settings, nullptr),
        timeline(settings),
        builder(estimator.model(), settings, frames, timeline),
        record(builder.sizedRecord()) {}

  // A joint sample stamped `stamp`, with `effort` measured; every record it makes (the
  // sample's own, and the smoother's due ones) into `out`.
  void feed(Stamp stamp, const std::vector<double>& q, const std::vector<double>& effort,
            std::vector<jle::LoadsRecord>& out) {
    const double t = timeline.sampleTime(stamp);
    jle::SampleStatus status = estimator.addJointSample(t, q.data());
    timeline.taken(stamp);
    builder.remember(t, stamp, &effort, estimator.filters().delaySamples());
    max_delay = std::max(max_delay, estimator.filters().delaySamples());
    if (status == jle::SampleStatus::kPublished) take(out);
    while (estimator.takeDue(status))
      if (status == jle::SampleStatus::kPublished) take(out);
  }
  void flush(std::vector<jle::LoadsRecord>& out) {
    jle::SampleStatus status = jle::SampleStatus::kPublished;
    while (estimator.flush(status))
      if (status == jle::SampleStatus::kPublished) take(out);
  }
  void take(std::vector<jle::LoadsRecord>& out) {
    EXPECT_TRUE(builder.fill(estimator, -1.0, record));  // finite loads
    out.push_back(record);
  }

  jle::Settings settings;
  jle::Estimator estimator;
  jle::FrameResolver frames;
  jle::Timeline timeline;
  jle::RecordBuilder builder;
  jle::LoadsRecord record;
  int max_delay = 0;
};

// Sample k: stamped about kStart + k ms, jittered by up to 0.2 ms (receive-time stamps,
// which stamps/regularize auto turns into a lattice of instants); every joint moving; a
// measured effort of its own per joint.
Stamp stampOf(int k) { return kStart + k * kMs + ((k * 7919) % 401 - 200) * 1000; }
std::vector<double> positions(int k) {
  std::vector<double> q(6);
  for (int i = 0; i < 6; ++i) q[static_cast<std::size_t>(i)] = 0.3 * std::sin(0.002 * k + i);
  return q;
}
std::vector<double> efforts(int k) {
  std::vector<double> e(6);
  for (int i = 0; i < 6; ++i) e[static_cast<std::size_t>(i)] = 1000.0 * k + i;
  return e;
}

TEST(RecordBuilder, DelayedRecordsCarryTheirOwnSample) {
  jle::Settings settings;
  settings.stamps.regularize = jle::StampRegularize::kAuto;
  jle::Settings smoothing = settings;
  smoothing.estimator.differentiator = jle::defaultSmoother();  // lag 0.2 s: 200 samples
  Stream live(settings), delayed(smoothing);
  std::vector<jle::LoadsRecord> now, due, drained;
  constexpr int kSamples = 600;
  std::map<Stamp, int> sample_of;
  for (int k = 0; k < kSamples; ++k) {
    sample_of[stampOf(k)] = k;
    live.feed(stampOf(k), positions(k), efforts(k), now);
    delayed.feed(stampOf(k), positions(k), efforts(k), due);
  }
  delayed.flush(drained);
  // The causal filter describes the newest sample at each, once warmed up (3 samples).
  ASSERT_EQ(now.size(), static_cast<std::size_t>(kSamples - 3));
  EXPECT_EQ(now.front().stamp, stampOf(3));
  std::map<Stamp, const jle::LoadsRecord*> live_at;
  for (const jle::LoadsRecord& r : now) live_at[r.stamp] = &r;
  EXPECT_EQ(live_at.size(), now.size());
  // The smoother: more samples behind the newest than the 128 remembered at the start.
  EXPECT_GT(delayed.max_delay, 128);
  ASSERT_GT(drained.size(), 128u);
  ASSERT_GT(due.size(), 128u);
  EXPECT_EQ(due.size() + drained.size(), static_cast<std::size_t>(kSamples));
  EXPECT_EQ(drained.back().stamp, stampOf(kSamples - 1));
  EXPECT_EQ(drained.front().stamp, stampOf(kSamples - static_cast<int>(drained.size())));
  std::size_t compared = 0;
  for (const std::vector<jle::LoadsRecord>* records : {&due, &drained})
    for (const jle::LoadsRecord& r : *records) {
      // A stamp of a sample fed (the message's own, not the regularized instant's)...
      ASSERT_EQ(sample_of.count(r.stamp), 1u) << r.stamp;
      const int k = sample_of[r.stamp];
      // ...and that sample's efforts, as the live record of the same sample has them.
      EXPECT_EQ(r.measured_effort, efforts(k)) << k;
      if (k < 3) continue;  // the causal filter's warm-up: no live record
      ASSERT_EQ(live_at.count(r.stamp), 1u) << k;
      EXPECT_EQ(r.measured_effort, live_at[r.stamp]->measured_effort) << k;
      EXPECT_EQ(r.joint, live_at[r.stamp]->joint);
      ++compared;
    }
  EXPECT_EQ(compared, now.size());
  // The stamps were jittered about their instants: forgotten samples (a restart) get the
  // time axis' instant, not a stamp of their own.
  ASSERT_TRUE(delayed.timeline.sampleClock().regular());
  const double t_last = delayed.estimator.last().stamp();
  EXPECT_EQ(delayed.builder.stampAt(t_last), stampOf(kSamples - 1));
  delayed.builder.forget();
  EXPECT_EQ(delayed.builder.stampAt(t_last), delayed.timeline.absolute(t_last));
  EXPECT_NE(delayed.builder.stampAt(t_last), stampOf(kSamples - 1));
}

// The UR5 publishing wrist_3_joint only (URDF effort limit 28 N m), a wrench input on its
// link (timeout 5 ms), a force plate under it (needed) and one under the shoulder (not
// needed).
jle::Settings wristSettings() {
  jle::Settings s;
  s.estimator.joints = {"wrist_3_joint"};
  s.estimator.wrenches.resize(1);
  s.estimator.wrenches[0].name = "ft";
  s.estimator.wrenches[0].link = "wrist_3_link";
  s.estimator.wrenches[0].timeout = 0.005;  // [s] half the samples' spacing
  s.wrenches.resize(1);
  s.wrenches[0].topic = "ft";
  s.estimator.plates.resize(2);
  s.estimator.plates[0].plate.name = "under_wrist";
  s.estimator.plates[0].plate.link = "wrist_3_link";
  s.estimator.plates[1].plate.name = "under_shoulder";
  s.estimator.plates[1].plate.link = "shoulder_link";
  s.force_plates.resize(2);
  return s;
}

TEST(RecordBuilder, EachStatusBitWhereTheSettingsPutIt) {
  Stream s(wristSettings());
  jle::Estimator& e = s.estimator;
  ASSERT_TRUE(e.layout().plateNeeded(0));
  ASSERT_FALSE(e.layout().plateNeeded(1));
  // Samples 10 ms apart, the wrench with each but the last: 10 ms old there.
  std::vector<jle::LoadsRecord> out;
  for (int k = 0; k < 10; ++k) {
    const Stamp stamp = kStart + 10 * k * kMs;
    if (k < 9)
      e.addWrench(0, s.timeline.relative(stamp), Eigen::Vector3d(1.0, 0.0, 0.0),
                  Eigen::Vector3d::Zero());
    s.feed(stamp, positions(k), efforts(k), out);
  }
  ASSERT_FALSE(out.empty());
  const double t = e.last().stamp();  // 0.09 s
  ASSERT_EQ(out.back().stamp, kStart + 90 * kMs);
  // Filled: the wrench fresh at the sample before, stale at the last; the plates never had
  // a sample: the needed one stale (the other one's staleness is not followed).
  ASSERT_GE(out.size(), 2u);
  EXPECT_FALSE(out[out.size() - 2].inputs[0].stale);
  jle::LoadsRecord rec = s.builder.sizedRecord();
  s.builder.fill(e, t - 1.0, rec);
  EXPECT_TRUE(rec.inputs[0].stale);
  EXPECT_TRUE(rec.plates[0].stale);
  EXPECT_EQ(rec.status & jle::kStaleInput, jle::kStaleInput);
  // Each bit by hand on a clean record (settle_time 0.05 s, effort_factor 3).
  rec.inputs[0].stale = rec.plates[0].stale = rec.plates[1].stale = false;
  rec.effort[0] = 0.0;
  const jle::RecordBuilder& b = s.builder;
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kTrusted);
  // Settling: within settle_time of the filters' (re)start.
  EXPECT_EQ(b.status(e, t - 0.04, rec), jle::kSettling);
  EXPECT_EQ(b.status(e, t - 0.06, rec), jle::kTrusted);
  // A sample that held a joint within settle_time, before or after.
  s.builder.heldAt(t - 0.04);
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kHeldJoint);
  s.builder.heldAt(t + 0.04);
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kHeldJoint);
  s.builder.heldAt(t - 0.06);
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kTrusted);
  s.builder.heldAt(t);
  s.builder.clearHeld();
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kTrusted);
  // A stale input; a stale plate only where the loads need it.
  rec.inputs[0].stale = true;
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kStaleInput);
  rec.inputs[0].stale = false;
  rec.plates[1].stale = true;
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kTrusted);
  rec.plates[0].stale = true;
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kStaleInput);
  rec.plates[0].stale = false;
  // An effort beyond 3 x 28 N m, either sign.
  rec.effort[0] = 84.0;
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kTrusted);
  rec.effort[0] = 84.001;
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kImplausibleLoad);
  rec.effort[0] = -84.001;
  EXPECT_EQ(b.status(e, t - 1.0, rec), jle::kImplausibleLoad);
  // All at once.
  rec.inputs[0].stale = true;
  s.builder.heldAt(t);
  const std::uint8_t all = b.status(e, t, rec);
  EXPECT_EQ(all, jle::kSettling | jle::kStaleInput | jle::kImplausibleLoad | jle::kHeldJoint);
  EXPECT_EQ(jle::describeStatus(all), "settling, stale input, implausible load, held joint");
}

}  // namespace
