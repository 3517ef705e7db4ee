// Node tests of the inputs (inputs.test): partial joint states from several publishers,
// stale wrench inputs under each policy, a backward jump of time, and malformed messages.
// The real joint_load_estimator node runs in one namespace per test (/multi, /hold,
// /zero, /stop, /jump, /bad) under a simulated clock that the test drives.
//
// "Nothing was published for stamp t" is never waited for: the test sends a later good
// message and waits for its publication. The node handles its inputs in order on one
// thread and publishes in order on one connection, so once the later publication has
// arrived, a publication for t would have arrived before it.
#include "node_test_common.hpp"

#include <functional>
#include <limits>

namespace {

using namespace jle_test;

const std::string kData = JLE_TEST_DATA;
const std::string kUr5 = kData + "/urdf/chains/ur5_chain.urdf";
const std::string kPanda = kData + "/urdf/panda.urdf";

// Loads computed from the same constant positions by the node (its finite differences
// give qd, qdd of rounding only, ~1e-16 |q| / dt^2 ~ 1e-10 rad/s^2) and by the reference
// (qd = qdd = 0), relative to each joint's wrench: rounding, ~1e-11 (see loads.test's
// kExactRel); a missed wrench or a wrong policy is of order 1.
constexpr double kRel = 1e-9;

ros::Time at(const ros::Time& start, int k) { return start + ros::Duration(0, 1000000 * k); }

VectorXd ur5Pose() {
  VectorXd q(6);
  q << 0.2, -1.0, 1.3, -0.5, 0.8, -0.3;
  return q;
}

// ---------------------------------------------------------------------------------

// Arm joints and finger joints from two publishers, the fingers 0.5 ms after the arm:
// nothing is published until every coordinate has been heard of (the node says which one
// it still misses), then each pair is one sample (stamps/merge_window), stamped with the
// fingers' stamp: no loads at the arm's stamps.
TEST(Inputs, LoadsWaitForEveryJointFromSeveralPublishers) {
  NodeUnderTest node("multi");
  LogRecorder& log = logs();
  ros::Publisher fingers_pub = nh().advertise<sensor_msgs::JointState>("/multi/joint_states", 100);
  ASSERT_TRUE(node.connect());
  Reference ref(kPanda);
  ASSERT_EQ(ref.model.nq, 8);  // 7 arm joints, panda_finger_joint1 (joint2 mimics it)
  const std::vector<std::string> arm(ref.model.coordinate_names.begin(),
                                     ref.model.coordinate_names.begin() + 7);
  ASSERT_EQ(ref.model.coordinate_names[7], "panda_finger_joint1");
  VectorXd q(8);
  q << 0.1, -0.5, 0.2, -2.1, 0.1, 1.7, 0.6, 0.03;

  auto sendArm = [&](const ros::Time& t) { node.send(jointState(t, arm, q.head(7))); };
  auto sendFingers = [&](const ros::Time& t) {
    // The mimic joint's value is allowed (and ignored): robot drivers publish it.
    sensor_msgs::JointState js =
        jointState(t, {"panda_finger_joint1", "panda_finger_joint2"}, Eigen::Vector2d(q[7], q[7]));
    simClock().set(t);
    fingers_pub.publish(js);
  };
  // The node's error is throttled by its clock (/clock, handled on another thread than
  // the joint states): if its clock is not there yet, a throttled message waits for the
  // next. So: arm messages until the error comes (the first, as a rule).
  const ros::Time start(100, 0);
  bool named = false;
  for (int k = 0; k < 5 && !named; ++k) {
    sendArm(at(start, k));
    named =
        log.waitFor(node.name(), rosgraph_msgs::Log::ERROR,
                    {"no position received yet", "'panda_finger_joint1'"}, k < 4 ? 0.2 : kTimeout);
  }
  EXPECT_TRUE(named) << "the node did not name the joint it misses";
  // The fingers at 4.5 ms complete the instant of the last arm message: the first sample;
  // the pairs at 5 and 6 ms the next two, and the 3-point filter publishes at 6.5 ms.
  sendFingers(at(start, 4) + ros::Duration(0, 500000));
  sendArm(at(start, 5));
  sendFingers(at(start, 5) + ros::Duration(0, 500000));
  sendArm(at(start, 6));
  const ros::Time first_published = at(start, 6) + ros::Duration(0, 500000);
  sendFingers(first_published);
  auto msg = node.loads().waitForStamp(first_published);
  ASSERT_TRUE(msg) << "no loads once every joint was received";
  ASSERT_EQ(node.loads().size(), 1u) << "loads published before every joint was received, "
                                        "first stamped "
                                     << node.loads().msgs().front()->header.stamp;
  ref.compute(q, VectorXd::Zero(8), VectorXd::Zero(8));
  EXPECT_LT(ref.relativeError(*msg), kRel);
  EXPECT_EQ(msg->name.size(), 9u);  // the mimic joint's loads too
  EXPECT_EQ(msg->status & joint_load_estimator::JointLoads::HELD_JOINT, 0);
  // From then on each pair is a sample: its loads at the fingers' stamp, none at the arm's.
  for (int k = 7; k < 10; ++k) {
    sendArm(at(start, k));
    const ros::Time t = at(start, k) + ros::Duration(0, 500000);
    sendFingers(t);
    msg = node.loads().waitForStamp(t);
    ASSERT_TRUE(msg);
    EXPECT_LT(ref.relativeError(*msg), kRel);
  }
  EXPECT_EQ(node.loads().size(), 4u);
  for (const auto& m : node.loads().msgs())
    EXPECT_EQ(m->header.stamp.nsec % 1000000, 500000u) << m->header.stamp;
}

// ---------------------------------------------------------------------------------
// A wrench on tool0 that stops: after its timeout (0.02 s in inputs.test) the policy
// decides. Joint samples every 1 ms, the wrench at the same stamps until sample 29.

enum class Policy { kHold, kZero, kStop };

void runStale(const std::string& ns, Policy policy) {
  NodeUnderTest node(ns);
  ros::Publisher wrench_pub =
      nh().advertise<geometry_msgs::WrenchStamped>("/" + ns + "/wrench", 100);
  ASSERT_TRUE(node.connect());
  ASSERT_TRUE(waitForSubscriber(wrench_pub, node.name()));
  Reference ref(kUr5);
  const VectorXd q = ur5Pose(), zero = VectorXd::Zero(6);
  auto wrench = [&](const ros::Time& t, double scale) {
    geometry_msgs::WrenchStamped w;
    w.header.stamp = t;
    w.header.frame_id = "tool0";
    w.wrench.force.x = 5.0 * scale;
    w.wrench.force.y = -3.0 * scale;
    w.wrench.force.z = 20.0 * scale;
    w.wrench.torque.x = 0.5 * scale;
    w.wrench.torque.y = 0.2 * scale;
    w.wrench.torque.z = -0.1 * scale;
    wrench_pub.publish(w);
  };
  Reference loaded(kUr5), unloaded(kUr5), loaded2(kUr5);
  loaded.compute(q, zero, zero, {}, "tool0", Vector3d(5, -3, 20), Vector3d(0.5, 0.2, -0.1));
  unloaded.compute(q, zero, zero);
  loaded2.compute(q, zero, zero, {}, "tool0", 2 * Vector3d(5, -3, 20),
                  2 * Vector3d(0.5, 0.2, -0.1));

  const ros::Time start(200, 0);
  const int lead = 5, last_wrench = 29, samples = 80;
  // The wrench a few samples ahead of the joint states, so that the node holds it when
  // the joint state comes (both are handled in order on its one thread). At the very
  // start the two topics' first messages may still come in either order: until the loads
  // carry the wrench (for stop: until anything is published), each sample is given a
  // short while only; from then on each one must be published and carry it.
  for (int k = 0; k < lead; ++k) wrench(at(start, k), 1.0);
  bool attached = false;
  int first_carried = 0;
  for (int k = 0; k < samples; ++k) {
    if (k + lead <= last_wrench) wrench(at(start, k + lead), 1.0);
    node.send(jointState(at(start, k), ref.model.coordinate_names, q));
    // Samples 48..51 straddle the timeout (20 ms after sample 29): not asserted.
    const bool stale = k > 51, fresh = k < 48;
    if (k < 2 || !(stale || fresh)) continue;
    if (policy == Policy::kStop && stale) continue;  // nothing to wait for
    const auto msg = node.loads().waitForStamp(at(start, k), attached ? kTimeout : 0.2);
    if (!attached && (!msg || loaded.relativeError(*msg) >= kRel)) {
      ASSERT_LT(k, 20) << "the loads never carried the wrench";
      continue;
    }
    if (!attached) first_carried = k;
    attached = true;
    ASSERT_TRUE(msg) << "no loads stamped " << at(start, k);
    const Reference& expected = policy == Policy::kZero && stale ? unloaded : loaded;
    EXPECT_LT(expected.relativeError(*msg), kRel) << "sample " << k;
  }
  if (policy != Policy::kStop) return;

  // The contact resumes (twice the wrench): publications resume. As at the start, the
  // first joint states may come before the first wrenches (stale: not published).
  // Returns how many samples were not published before the first that was.
  // Goes on until `done` holds too.
  auto contact = [&](const ros::Time& t0, int warmup, const std::function<bool()>& done) {
    for (int k = 0; k < lead; ++k) wrench(at(t0, k), 2.0);
    int published = 0, before = 0;
    for (int k = 0; k < 40 && (published < 3 || !waitFor(done, 0.1)); ++k) {
      wrench(at(t0, k + lead), 2.0);
      node.send(jointState(at(t0, k), ref.model.coordinate_names, q));
      if (k < warmup) continue;
      const auto msg = node.loads().waitForStamp(at(t0, k), published > 0 ? kTimeout : 0.2);
      if (!msg && published == 0) {
        ++before;
        continue;
      }
      if (!msg) break;
      ++published;
      EXPECT_LT(loaded2.relativeError(*msg), kRel);
    }
    EXPECT_GE(published, 3) << "no loads after the wrench resumed at " << t0;
    return before;
  };
  const ros::Time resume = at(start, samples);
  const int before_resume = contact(resume, 0, [] { return true; });
  for (const auto& m : node.loads().msgs())
    EXPECT_FALSE(m->header.stamp > at(start, 51) && m->header.stamp < resume)
        << "published while the wrench was stale: " << m->header.stamp;

  // The node has handled every sample sent before the publications that just came (in
  // order, on one thread). After a pause of 1.5 s (the filters restart: a gap longer than
  // max_gap; their 3-sample warm-up), a second of node time has passed since the last
  // diagnostics, and they come with the next publications: not published were samples
  // 52..79 and some of 48..51, and those before the wrench came, at the start and on
  // resuming.
  // (The node's clock, on another connection, may lag behind the stamps: the diagnostics
  // may come with a later publication than the first.)
  const long handled = node.sent();
  const int before_pause = contact(resume + ros::Duration(1.5), 2, [&] {
    return diagnostics().latest(node.status(), "joint states received") >= handled;
  });
  ASSERT_GE(diagnostics().latest(node.status(), "joint states received"), handled)
      << "no diagnostics after the pause";
  const long stale_count = diagnostics().latest(node.status(), "not published: stale input");
  const int before_wrench = (first_carried - 2) + before_resume + before_pause;
  EXPECT_GE(stale_count, 28 + before_wrench);
  EXPECT_LE(stale_count, 32 + before_wrench);
}

TEST(Inputs, StaleWrenchHoldKeepsTheLastValue) { runStale("hold", Policy::kHold); }
TEST(Inputs, StaleWrenchZeroDropsIt) { runStale("zero", Policy::kZero); }
TEST(Inputs, StaleWrenchStopPublishesNothing) { runStale("stop", Policy::kStop); }

// ---------------------------------------------------------------------------------

// rosbag play -l: /clock jumps back 5 s and the stamps restart with the bag. The node
// warns once, refills its filter (a Savitzky-Golay window: 9 samples) and
// publishes again, never a stamp of the timeline it left.
TEST(Inputs, BackwardTimeJumpRestartsTheFilters) {
  NodeUnderTest node("jump");
  LogRecorder& log = logs();
  DiagnosticsRecorder& diag = diagnostics();
  ASSERT_TRUE(node.connect());
  Reference ref(kUr5);
  // The bag: 30 samples of constant accelerations, which the quadratic fit
  // reproduces exactly (rounding aside, as in loads.test: bound kRel).
  const ros::Time bag_start(300, 0);
  VectorXd q0 = ur5Pose(), v0(6), a(6);
  v0 << 0.5, -0.4, 0.3, 0.8, -0.6, 0.2;
  a << 2.0, -1.0, 3.0, -2.0, 1.5, -2.5;
  auto q = [&](double s) { return VectorXd(q0 + v0 * s + 0.5 * a * s * s); };
  const int window = 9, samples = 30;
  // After a jump, the first joint states of the new timeline may reach the node before
  // the /clock message that moved the clock with them: until it comes they are rogue
  // stamps (docs/node.md "Time stamps"), at most stamps/jump_confirm - 1 = 2 of them, and the
  // first publication is up to 2 samples later.
  const int late = 2;

  auto play = [&](const ros::Time& start, int unchecked) {
    for (int k = 0; k < samples; ++k) {
      const ros::Time t = at(start, k);
      const double s = (t - start).toSec();
      node.send(jointState(t, ref.model.coordinate_names, q(s)));
      if (k < window - 1 + unchecked) continue;
      const auto msg = node.loads().waitForStamp(t);
      ASSERT_TRUE(msg) << "no loads stamped " << t;
      ref.compute(q(s), VectorXd(v0 + a * s), a);
      EXPECT_LT(ref.relativeError(*msg), kRel) << t;
    }
  };
  play(bag_start, 0);
  const std::size_t before_jump = node.loads().size();
  ASSERT_EQ(before_jump, static_cast<std::size_t>(samples - (window - 1)));

  const ros::Time loop_start = bag_start - ros::Duration(5.0);
  play(loop_start, late);
  ASSERT_GT(node.loads().size(), before_jump);
  // The first publication after the jump is the 9th sample of the new timeline (up to
  // `late` samples later).
  const ros::Time first = node.loads().msgs()[before_jump]->header.stamp;
  EXPECT_TRUE(first >= at(loop_start, window - 1) && first <= at(loop_start, window - 1 + late))
      << "first published " << first;
  for (std::size_t i = before_jump; i < node.loads().size(); ++i) {
    const ros::Time& stamp = node.loads().msgs()[i]->header.stamp;
    EXPECT_TRUE(stamp >= loop_start && stamp < bag_start) << "published " << stamp;
  }
  EXPECT_LE(node.loads().size() - before_jump, static_cast<std::size_t>(samples - (window - 1)));
  EXPECT_GE(node.loads().size() - before_jump,
            static_cast<std::size_t>(samples - (window - 1) - late));

  // Play on 7 s later, past the diagnostics period (1 s of node time) counted from before
  // the jump: the warning was given once, and the diagnostics of the first publication
  // count one jump back and no dropped sample. (If the first joint states after the gap
  // reach the node before the /clock message that moved the clock with them, the gap is
  // a confirmed jump forward: warned and counted as such, not as a jump back.)
  play(bag_start + ros::Duration(2.0), late);
  ASSERT_TRUE(log.waitFor(node.name(), rosgraph_msgs::Log::WARN, {"time jumped back"}));
  ASSERT_TRUE(
      waitFor([&] { return diag.latest(node.status(), "joint states received") > 2 * samples; }));
  EXPECT_EQ(log.count(node.name(), rosgraph_msgs::Log::WARN, {"time jumped back"}), 1u);
  EXPECT_EQ(diag.latest(node.status(), "time jumps back"), 1);
  EXPECT_EQ(diag.latest(node.status(), "dropped: stamp order"), 0);
  EXPECT_EQ(diag.latest(node.status(), "dropped: invalid"), 0);
}

// ---------------------------------------------------------------------------------
// Malformed inputs, one node (/bad, finite differences, a wrench topic on tool0). Each
// case: prime the filter with 3 good samples after a pause of 3 s of node time (past the
// 2 s throttle of the node's error messages, and a gap that restarts the filter), send the
// bad message, then a good one, which must be published with its own stamp.

class BadInput : public ::testing::Test {
 protected:
  BadInput() : node_(badNode()), ref_(kUr5), names_(ref_.model.coordinate_names), q_(ur5Pose()) {}

  // One connection to the node for all its tests.
  static NodeUnderTest& badNode() {
    static NodeUnderTest node("bad");
    return node;
  }

  void SetUp() override {
    ASSERT_TRUE(node_.connect());
    ref_.compute(q_, VectorXd::Zero(6), VectorXd::Zero(6));
  }

  // Good samples 3 s after the last stamp used, with the clock standing still: a jump of
  // time forward, which the first two confirm as rogue stamps (stamps/jump_confirm 3,
  // docs/node.md "Time stamps") and the third restarts the filter from; two more make the
  // three the fit needs. Waits for the publication of the last, and for the
  // diagnostics that count them.
  void prime() {
    next_ = next_ + ros::Duration(3.0);
    for (int k = 0; k < 5; ++k) node_.send(good(tick()));
    ASSERT_TRUE(node_.loads().waitForStamp(last_)) << "no loads after priming at " << last_;
    // The diagnostics come on the node's wall-clock timer (diagnostic_period 0.1 s in
    // inputs.test), whatever the inputs do.
    auto current = [&] {
      return diagnostics_.latest(node_.status(), "joint states received") == node_.sent();
    };
    ASSERT_TRUE(waitFor(current, 2.0)) << "no diagnostics after priming";
  }
  // The next stamp, 1 ms after the previous one.
  ros::Time tick() {
    last_ = next_;
    next_ = next_ + ros::Duration(0, 1000000);
    return last_;
  }
  sensor_msgs::JointState good(const ros::Time& t) const { return jointState(t, names_, q_); }
  // Sends a good sample and checks that it is published with its stamp, with the loads
  // of the reference.
  void expectGoodPublished() {
    const ros::Time t = tick();
    node_.send(good(t));
    const auto msg = node_.loads().waitForStamp(t);
    ASSERT_TRUE(msg) << "the good message after the bad one was not published";
    EXPECT_LT(ref_.relativeError(*msg), kRel);
  }
  long counter(const std::string& key) const { return diagnostics_.latest(node_.status(), key); }
  // Sends `bad` (stamped with the next tick), then a good message; checks that the bad
  // one is not published, the good one is, an error naming all of `parts` was logged and
  // the diagnostics counter `key` went up by one.
  void expectDropped(sensor_msgs::JointState bad, const std::vector<std::string>& parts,
                     const std::string& key) {
    prime();
    const long before = counter(key);
    bad.header.stamp = tick();
    node_.send(bad);
    expectGoodPublished();
    EXPECT_FALSE(node_.loads().find(bad.header.stamp)) << "the bad message was published";
    EXPECT_TRUE(log_.waitFor(node_.name(), rosgraph_msgs::Log::ERROR, parts))
        << "no error naming " << ::testing::PrintToString(parts);
    prime();
    EXPECT_EQ(counter(key), before + 1) << key;
  }

  NodeUnderTest& node_;
  Reference ref_;
  std::vector<std::string> names_;
  VectorXd q_;
  LogRecorder& log_ = logs();
  DiagnosticsRecorder& diagnostics_ = diagnostics();
  static ros::Time next_, last_;  // stamps increase across the tests of this node
};
ros::Time BadInput::next_(1000, 0), BadInput::last_;

TEST_F(BadInput, UnknownJointNamesAreIgnoredAndTheRestUsed) {
  prime();
  const long before = counter("messages with unknown joints");
  sensor_msgs::JointState js = good(tick());
  js.name.push_back("ghost_joint");
  js.position.push_back(1.0);
  node_.send(js);
  const auto msg = node_.loads().waitForStamp(js.header.stamp);
  ASSERT_TRUE(msg) << "a message naming an unknown joint was not used";
  EXPECT_LT(ref_.relativeError(*msg), kRel);
  EXPECT_TRUE(log_.waitFor(node_.name(), rosgraph_msgs::Log::WARN, {"'ghost_joint'"}));
  prime();
  EXPECT_EQ(counter("messages with unknown joints"), before + 1);
}

TEST_F(BadInput, NaNPositionIsDropped) {
  sensor_msgs::JointState bad = good(ros::Time());
  bad.position[2] = std::numeric_limits<double>::quiet_NaN();
  expectDropped(bad, {"position", "'elbow_joint'"}, "dropped: invalid");
}

// A non-finite velocity costs that velocity only (measured_velocity, issue 37): the
// message is used and its loads published; warned naming the joint, and counted.
TEST_F(BadInput, InfiniteVelocityCostsOnlyThatVelocity) {
  prime();
  const long before = counter("velocities not used: non-finite");
  const long invalid = counter("dropped: invalid");
  sensor_msgs::JointState js = good(tick());
  js.velocity.assign(6, 0.0);
  js.velocity[4] = std::numeric_limits<double>::infinity();
  node_.send(js);
  const auto msg = node_.loads().waitForStamp(js.header.stamp);
  ASSERT_TRUE(msg) << "a message with an infinite velocity was not used";
  for (double e : msg->effort) EXPECT_TRUE(std::isfinite(e));
  EXPECT_TRUE(
      log_.waitFor(node_.name(), rosgraph_msgs::Log::WARN, {"velocity", "'wrist_2_joint'"}));
  prime();
  EXPECT_EQ(counter("velocities not used: non-finite"), before + 1);
  EXPECT_EQ(counter("dropped: invalid"), invalid);
}

// The effort is kept only for comparison (issue 14): a NaN drops that joint's comparison,
// not the loads; warned and counted.
TEST_F(BadInput, NaNEffortDropsOnlyItsComparison) {
  prime();
  const long before = counter("efforts not compared: non-finite");
  const long invalid = counter("dropped: invalid");
  sensor_msgs::JointState js = good(tick());
  js.effort.assign(6, 1.0);
  js.effort[0] = std::numeric_limits<double>::quiet_NaN();
  node_.send(js);
  const auto msg = node_.loads().waitForStamp(js.header.stamp);
  ASSERT_TRUE(msg) << "a message with a NaN effort was not used";
  EXPECT_LT(ref_.relativeError(*msg), kRel);
  ASSERT_EQ(msg->measured_effort.size(), 6u);
  EXPECT_TRUE(std::isnan(msg->measured_effort[0]));
  EXPECT_EQ(msg->measured_effort[1], 1.0);
  EXPECT_TRUE(
      log_.waitFor(node_.name(), rosgraph_msgs::Log::WARN, {"effort", "'shoulder_pan_joint'"}));
  prime();
  EXPECT_EQ(counter("efforts not compared: non-finite"), before + 1);
  EXPECT_EQ(counter("dropped: invalid"), invalid);
}

TEST_F(BadInput, TooFewPositionsAreDropped) {
  sensor_msgs::JointState bad = good(ros::Time());
  bad.position.pop_back();
  expectDropped(bad, {"6 names but 5 positions"}, "dropped: invalid");
}

TEST_F(BadInput, WrongNumberOfVelocitiesIsDropped) {
  sensor_msgs::JointState bad = good(ros::Time());
  bad.velocity.assign(2, 0.0);
  expectDropped(bad, {"6 names but 2 velocities"}, "dropped: invalid");
}

// A duplicate stamp and an older one (within time_jump_threshold, so not a jump of
// time). /clock does not go back: in a bag or a simulation it is the stamps that do.
TEST_F(BadInput, DuplicateAndOutOfOrderStampsAreDropped) {
  prime();
  const long before = counter("dropped: stamp order");
  const long jumps = counter("time jumps back");
  const ros::Time newest = last_;
  sensor_msgs::JointState dup = good(newest), old = good(newest - ros::Duration(0, 500000));
  dup.position[0] += 0.1;  // if it were used, the loads would show it
  old.position[0] += 0.1;
  node_.sendKeepingClock(dup);
  node_.sendKeepingClock(old);
  expectGoodPublished();
  std::size_t newest_published = 0;
  for (const auto& m : node_.loads().msgs()) {
    newest_published += m->header.stamp == newest ? 1 : 0;
    EXPECT_NE(m->header.stamp, old.header.stamp) << "the out-of-order message was published";
  }
  EXPECT_EQ(newest_published, 1u) << "the duplicate was published";
  EXPECT_TRUE(log_.waitFor(node_.name(), rosgraph_msgs::Log::WARN, {"duplicate stamp"}));
  prime();
  EXPECT_EQ(counter("dropped: stamp order"), before + 2);
  // Neither message reset anything (prime()'s own gap may count a jump forward, when its
  // first joint states reach the node before the /clock message that moved the clock).
  EXPECT_EQ(counter("time jumps back"), jumps);
}

// A wrench in a frame neither the URDF nor tf2 knows: dropped with an error naming it;
// the next wrench, in tool0, is applied. Last of the node's tests: its wrench stays held.
TEST_F(BadInput, WrenchInAnUnknownFrameIsDropped) {
  ros::Publisher wrench_pub = nh().advertise<geometry_msgs::WrenchStamped>("/bad/wrench", 100);
  ASSERT_TRUE(waitForSubscriber(wrench_pub, node_.name()));
  prime();
  const long before = counter("dropped: unresolved frame");
  geometry_msgs::WrenchStamped w;
  w.header.stamp = last_;
  w.header.frame_id = "nowhere";
  w.wrench.force.z = 50.0;
  wrench_pub.publish(w);
  expectGoodPublished();  // without the wrench: the reference has none
  EXPECT_TRUE(log_.waitFor(node_.name(), rosgraph_msgs::Log::ERROR, {"'nowhere'"}));
  // The same wrench in tool0: the loads carry it from the next samples on.
  w.header.frame_id = "tool0";
  w.header.stamp = last_;
  wrench_pub.publish(w);
  Reference loaded(kUr5);
  loaded.compute(q_, VectorXd::Zero(6), VectorXd::Zero(6), {}, "tool0", Vector3d(0, 0, 50),
                 Vector3d::Zero());
  bool carried = false;
  for (int k = 0; k < 20 && !carried; ++k) {
    const ros::Time t = tick();
    node_.send(good(t));
    const auto msg = node_.loads().waitForStamp(t);
    ASSERT_TRUE(msg);
    carried = loaded.relativeError(*msg) < kRel;
  }
  EXPECT_TRUE(carried) << "the wrench in tool0 after the bad one was not applied";
  prime();
  EXPECT_EQ(counter("dropped: unresolved frame"), before + 1);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_inputs");
  return RUN_ALL_TESTS();
}
