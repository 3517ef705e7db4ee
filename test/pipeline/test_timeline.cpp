// The message path's time axis (timeline.hpp), on stamps whose outcome follows from the
// rules of docs/node.md "Time stamps" by hand: the first stamp anchors the axis; a looping bag
// (stamps and clock back) and the clock going back restart the timeline at once; a jump
// forward takes stamps.jump_confirm stamps in a row; a lone rogue stamp is dropped and
// changes nothing; stamps out of order, and wrench stamps too far from the joint states,
// are told apart; and the axis gives every stamp back to the nanosecond.
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/pipeline/timeline.hpp>

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace {

using jle::Stamp;
using jle::StampVerdict;

constexpr Stamp kStart = 1700000000123456789;  // [ns]
constexpr Stamp kMs = 1000000;
constexpr Stamp kS = 1000000000;

// A joint state through the timeline as the Pipeline takes one: its stamp checked (a
// jump restarts the timeline first), its order, its time, taken. Returns the check's
// verdict, or the order's where the check let it through.
struct Stream {
  explicit Stream(const jle::Settings& settings = jle::Settings()) : timeline(settings) {}
  StampVerdict feed(Stamp stamp, Stamp clock) {
    problem.clear();
    timeline.clearJump();
    const StampVerdict check = timeline.checkJointStamp(stamp, clock, "joint_states", problem);
    if (check == StampVerdict::kRogue) return check;
    if (check == StampVerdict::kJump) timeline.restart();
    const StampVerdict order = timeline.order(stamp);
    if (order != StampVerdict::kOnTime) return order;
    last_t = timeline.sampleTime(stamp);
    timeline.taken(stamp);
    return check;
  }
  // n joint states 1 ms apart from `first`, the clock equal to the stamps.
  void run(Stamp first, int n) {
    for (int k = 0; k < n; ++k)
      ASSERT_EQ(feed(first + k * kMs, first + k * kMs), StampVerdict::kOnTime);
  }
  jle::Timeline timeline;
  std::string problem;
  double last_t = -1.0;
};

TEST(Timeline, TheFirstStampAnchorsTheAxis) {
  Stream s;
  EXPECT_FALSE(s.timeline.hasOrigin());
  EXPECT_EQ(s.timeline.lastStamp(), 0);
  EXPECT_EQ(s.feed(kStart, kStart), StampVerdict::kOnTime);
  EXPECT_TRUE(s.timeline.hasOrigin());
  EXPECT_EQ(s.timeline.origin(), kStart);
  EXPECT_EQ(s.last_t, 0.0);
  EXPECT_EQ(s.timeline.lastStamp(), kStart);
  EXPECT_EQ(s.feed(kStart + 2 * kMs, kStart + 2 * kMs), StampVerdict::kOnTime);
  EXPECT_DOUBLE_EQ(s.last_t, 2e-3);
  EXPECT_EQ(s.timeline.origin(), kStart);
  EXPECT_FALSE(s.timeline.jumped());
  // A wrench's stamp before any joint state anchors the axis as well; the joint states'
  // first within the axis' reach keeps it.
  Stream w;
  EXPECT_EQ(w.timeline.checkInputStamp(kStart - 5 * kMs, kStart, 0.1, "wrench 'ft'", w.problem),
            StampVerdict::kOnTime);
  EXPECT_EQ(w.timeline.relative(kStart - 5 * kMs), 0.0);
  EXPECT_EQ(w.feed(kStart, kStart), StampVerdict::kOnTime);
  EXPECT_EQ(w.timeline.origin(), kStart - 5 * kMs);
  EXPECT_DOUBLE_EQ(w.last_t, 5e-3);
}

// rosbag play -l: at the end of the bag, the stamps and the bag's clock go back together.
TEST(Timeline, ABagLoopRestartsTheTimelineAtOnce) {
  Stream s;
  s.run(kStart, 10);
  const Stamp last = kStart + 9 * kMs;
  EXPECT_EQ(s.feed(kStart, kStart), StampVerdict::kJump);
  EXPECT_TRUE(s.timeline.jumped());
  EXPECT_FALSE(s.timeline.jumpedForward());
  EXPECT_EQ(s.timeline.jumpFrom(), last);
  EXPECT_EQ(s.timeline.jumpTo(), kStart);
  // The new timeline starts from the stamp that jumped: its origin, its first sample.
  EXPECT_EQ(s.timeline.origin(), kStart);
  EXPECT_EQ(s.last_t, 0.0);
  EXPECT_EQ(s.timeline.lastStamp(), kStart);
  // And goes on as the first did.
  EXPECT_EQ(s.feed(kStart + kMs, kStart + kMs), StampVerdict::kOnTime);
  EXPECT_FALSE(s.timeline.jumped());
  EXPECT_DOUBLE_EQ(s.last_t, 1e-3);
  // A jump back less than time_jump_threshold (1 s) with the clock going on is no jump: an
  // old stamp, out of order.
  EXPECT_EQ(s.feed(kStart - 500 * kMs, kStart + 2 * kMs), StampVerdict::kOutOfOrder);
  EXPECT_FALSE(s.timeline.jumped());
}

TEST(Timeline, TheClockGoingBackConfirmsAJumpBackAtOnce) {
  // The clock goes back one message before the stamps do (they come on other
  // connections): that message's stamp goes forward, no jump; the next one's goes back,
  // by 2 s, and is a jump at once instead of a rogue stamp.
  Stream s;
  s.run(kStart, 5);
  EXPECT_EQ(s.feed(kStart + 5 * kMs, kStart - 10 * kS), StampVerdict::kOnTime);
  EXPECT_EQ(s.feed(kStart - 2 * kS, kStart - 10 * kS + kMs), StampVerdict::kJump);
  EXPECT_EQ(s.timeline.jumpFrom(), kStart + 5 * kMs);
  EXPECT_EQ(s.timeline.jumpTo(), kStart - 2 * kS);
  // Without the clock: the same stamps are two rogue stamps and a jump at the third.
  Stream t;
  t.run(kStart, 6);
  EXPECT_EQ(t.feed(kStart - 2 * kS, kStart + 6 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(t.feed(kStart - 2 * kS + kMs, kStart + 7 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(t.feed(kStart - 2 * kS + 2 * kMs, kStart + 8 * kMs), StampVerdict::kJump);
  EXPECT_EQ(t.timeline.jumpFrom(), kStart + 5 * kMs);
  // The clock going back while the stamps stand still (a restarted simulation): a jump.
  Stream u;
  u.run(kStart, 3);
  EXPECT_EQ(u.feed(kStart + 2 * kMs, kStart), StampVerdict::kJump);
  EXPECT_EQ(u.timeline.jumpTo(), kStart + 2 * kMs);
}

TEST(Timeline, AJumpForwardTakesJumpConfirmStampsInARow) {
  for (int confirm : {1, 3, 5}) {
    jle::Settings settings;
    settings.stamps.jump_confirm = confirm;
    Stream s(settings);
    s.run(kStart, 5);
    const Stamp last = kStart + 4 * kMs, far = kStart + 100 * kS;
    // The clock goes on at 1 ms a message: the stamps 100 s ahead are on another timeline.
    for (int k = 0; k < confirm; ++k) {
      const StampVerdict v = s.feed(far + k * kMs, last + (k + 1) * kMs);
      EXPECT_EQ(v, k + 1 < confirm ? StampVerdict::kRogue : StampVerdict::kJump)
          << confirm << " " << k;
      EXPECT_EQ(s.timeline.lastStamp(), k + 1 < confirm ? last : far + k * kMs);
    }
    EXPECT_TRUE(s.timeline.jumpedForward());
    EXPECT_EQ(s.timeline.jumpFrom(), last);
    EXPECT_EQ(s.timeline.jumpTo(), far + (confirm - 1) * kMs);
    EXPECT_EQ(s.timeline.origin(), far + (confirm - 1) * kMs);
  }
  // A stamp of the stream between them starts the count again.
  Stream s;
  s.run(kStart, 5);
  const Stamp far = kStart + 100 * kS;
  EXPECT_EQ(s.feed(far, kStart + 5 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(s.feed(far + kMs, kStart + 6 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(s.feed(kStart + 7 * kMs, kStart + 7 * kMs), StampVerdict::kOnTime);
  EXPECT_EQ(s.feed(far + 2 * kMs, kStart + 8 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(s.feed(far + 3 * kMs, kStart + 9 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(s.feed(far + 4 * kMs, kStart + 10 * kMs), StampVerdict::kJump);
  // So do stamps of the other timeline out of order among themselves.
  Stream t;
  t.run(kStart, 5);
  EXPECT_EQ(t.feed(far + kMs, kStart + 5 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(t.feed(far, kStart + 6 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(t.feed(far + 2 * kMs, kStart + 7 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(t.feed(far + 3 * kMs, kStart + 8 * kMs), StampVerdict::kJump);
  // A gap that the clock saw too (a paused bag or driver) is no jump, however long.
  Stream u;
  u.run(kStart, 5);
  EXPECT_EQ(u.feed(far, far + 7), StampVerdict::kOnTime);
  EXPECT_FALSE(u.timeline.jumped());
}

TEST(Timeline, ARogueStampIsDroppedAndChangesNothing) {
  Stream s;
  s.run(kStart, 5);
  const Stamp last = kStart + 4 * kMs;
  // 2 s back with the clock going on: one message of another timeline.
  EXPECT_EQ(s.feed(kStart - 2 * kS + 4 * kMs, last + kMs), StampVerdict::kRogue);
  // (A double holds epoch seconds to 2.4e-7 s: the words show the stamps to 1e-6 s.)
  EXPECT_EQ(s.problem.find("joint_states: stamp 1699999998.127456"), 0u) << s.problem;
  EXPECT_NE(s.problem.find(" is -2.000000 s from the stream's (1700000000.127456"),
            std::string::npos)
      << s.problem;
  EXPECT_NE(s.problem.find("): dropped (a jump of time takes 3 in a row)"), std::string::npos)
      << s.problem;
  EXPECT_FALSE(s.timeline.jumped());
  EXPECT_EQ(s.timeline.lastStamp(), last);
  EXPECT_EQ(s.timeline.origin(), kStart);
  EXPECT_EQ(s.feed(last + 2 * kMs, last + 2 * kMs), StampVerdict::kOnTime);
  EXPECT_DOUBLE_EQ(s.last_t, 6e-3);
  // Stamp 0: the clock on a stream that never had a stamp, rogue on one that has.
  bool stamped = false;
  Stamp stamp = 0;
  EXPECT_TRUE(jle::Timeline::zeroStamp(stamped, stamp, kStart));
  EXPECT_EQ(stamp, kStart);
  EXPECT_FALSE(stamped);
  stamp = kStart + kMs;
  EXPECT_TRUE(jle::Timeline::zeroStamp(stamped, stamp, kStart));
  EXPECT_EQ(stamp, kStart + kMs);
  EXPECT_TRUE(stamped);
  stamp = 0;
  EXPECT_FALSE(jle::Timeline::zeroStamp(stamped, stamp, kStart + 2 * kMs));
}

TEST(Timeline, OutOfOrderAndStaleStampsAreToldApart) {
  Stream s;
  s.run(kStart, 5);
  const Stamp last = kStart + 4 * kMs;
  jle::Timeline& t = s.timeline;
  // Joint states: the last sample's stamp, an older one, a newer one; against an instant
  // being assembled (newest stamp `last + 3 ms`) a stamp between them is out of order.
  EXPECT_EQ(t.order(last), StampVerdict::kDuplicate);
  EXPECT_EQ(t.order(last - 1), StampVerdict::kOutOfOrder);
  EXPECT_EQ(t.order(last + 1), StampVerdict::kOnTime);
  EXPECT_EQ(t.order(last + 2 * kMs, last + 3 * kMs), StampVerdict::kOutOfOrder);
  EXPECT_EQ(t.order(last + 3 * kMs, last + 3 * kMs), StampVerdict::kDuplicate);
  EXPECT_EQ(s.feed(last, last + kMs), StampVerdict::kDuplicate);
  EXPECT_EQ(s.feed(last - 3 * kMs, last + kMs), StampVerdict::kOutOfOrder);
  EXPECT_EQ(t.lastStamp(), last);
  // A wrench with timeout 0.1 s (at 1 kHz, ten periods add 10 ms): behind the joint states
  // by up to time_jump_threshold (1 s) it is on time (the buffer judges its order), ahead
  // by up to 0.11 s too; beyond either it is a rogue stamp.
  std::string problem;
  const auto input = [&](Stamp stamp) {
    return t.checkInputStamp(stamp, last + kMs, 0.1, "wrench 'ft'", problem);
  };
  EXPECT_EQ(input(last - 999 * kMs), StampVerdict::kOnTime);
  EXPECT_EQ(input(last - 1001 * kMs), StampVerdict::kRogue);
  EXPECT_EQ(problem.find("wrench 'ft': stamp 1699999999.126456"), 0u) << problem;
  EXPECT_NE(problem.find(" is -1.001000 s from the joint states' (1700000000.127456"),
            std::string::npos)
      << problem;
  EXPECT_EQ(input(last + 109 * kMs), StampVerdict::kOnTime);
  EXPECT_EQ(input(last + 111 * kMs), StampVerdict::kRogue);
  EXPECT_FALSE(t.jumped());
  // Before the first joint sample of a timeline any stamp is on time.
  Stream fresh;
  EXPECT_EQ(fresh.timeline.checkInputStamp(kStart + 100 * kS, kStart, 0.1, "wrench 'ft'", problem),
            StampVerdict::kOnTime);
  // The clock going back at a wrench restarts the timeline too.
  EXPECT_EQ(t.checkInputStamp(last, kStart, 0.1, "wrench 'ft'", problem), StampVerdict::kJump);
  t.restart();
  EXPECT_EQ(t.lastStamp(), 0);
  EXPECT_FALSE(t.hasOrigin());
}

TEST(Timeline, AbsoluteGivesEveryStampBackToTheNanosecond) {
  jle::Settings settings;
  jle::Timeline timeline(settings);
  timeline.anchor(kStart);
  // Within 2^51 ns (26 days) of the origin, either way, at odd nanoseconds: the stamp
  // itself. (The offset in ns is exact in a double; t = offset 1e-9 and t 1e9 round by
  // half an ulp each, and the two roundings stay below half a nanosecond there.)
  jle::PortableRandom random(38);
  constexpr Stamp kExact = Stamp{1} << 51, kReach = Stamp{1} << 52;
  const Stamp cases[] = {
      0, 1, -1, 999999999, kS + 1, 86400 * kS + 7, -86400 * kS - 7, kExact, -kExact, kExact - 1};
  for (Stamp offset : cases) {
    const Stamp s = kStart + offset;
    EXPECT_EQ(timeline.absolute(timeline.relative(s)), s) << offset;
  }
  for (int k = 0; k < 100000; ++k) {
    const Stamp offset =
        static_cast<Stamp>(random.uniform(-1.0, 1.0) * static_cast<double>(kExact));
    const Stamp s = kStart + offset;
    ASSERT_EQ(timeline.absolute(timeline.relative(s)), s) << offset;
  }
  // Out to the axis' reach (2^52 ns, 52 days) the roundings reach a nanosecond: within it.
  for (int k = 0; k < 100000; ++k) {
    const Stamp offset =
        static_cast<Stamp>(random.uniform(-1.0, 1.0) * static_cast<double>(kReach));
    const Stamp s = kStart + offset;
    ASSERT_LE(std::abs(timeline.absolute(timeline.relative(s)) - s), 1) << offset;
  }
  EXPECT_EQ(timeline.origin(), kStart);  // a time was handed out: the origin stays
  // Beyond the reach while no time was handed out, the origin moves to the stamp.
  jle::Timeline fresh(settings);
  fresh.anchor(1000);
  fresh.anchor(kStart);
  EXPECT_EQ(fresh.origin(), kStart);
  fresh.anchor(1000);  // still none handed out
  EXPECT_EQ(fresh.origin(), 1000);
  EXPECT_EQ(fresh.relative(1000 + kMs), 1e-3);
  fresh.anchor(kStart);
  EXPECT_EQ(fresh.origin(), 1000);
  EXPECT_EQ(jle::secondsText(1500000001), "1.500000001");
}

}  // namespace
