// Hostile inputs to the running node (hostile.test, issue 14). Every message is either
// used or counted under its reason, the loads published are exactly those of the good
// messages, and /diagnostics keeps its wall-clock rate through a looping bag, a stopped
// publisher, a missing joint and a stale `stop` input, saying why the loads stopped.
//
// The hostile kinds are one table (kKinds): a kind sends its bad message(s) beside a
// good sample, or alters the hostile copy of the sample, and names the diagnostics key
// that must count it. Kinds of other rules (stamps) slot in as rows.
#include "node_test_common.hpp"

#include <functional>
#include <limits>
#include <map>

namespace {

using namespace jle_test;

const std::string kUr5 = std::string(JLE_TEST_DATA) + "/urdf/chains/ur5_chain.urdf";
constexpr double kPeriod = 0.2;  // [s] diagnostic_period in hostile.test
constexpr double kRate = 500.0;  // [Hz] the arm's joint states
// The hostile node gets the clean node's samples in the same order: the same loads,
// bit for bit; 1e-12 [N, N m] states the brief's bound.
constexpr double kExact = 1e-12;

ros::Time at(const ros::Time& start, int k) {
  return start + ros::Duration().fromNSec(static_cast<std::int64_t>(1e9 / kRate) * k);
}

// A smooth arm motion [rad] with measured efforts [N m].
sensor_msgs::JointState armState(const std::vector<std::string>& names, const ros::Time& stamp,
                                 const ros::Time& start) {
  const double t = (stamp - start).toSec();
  VectorXd q(static_cast<Eigen::Index>(names.size()));
  for (Eigen::Index i = 0; i < q.size(); ++i) q[i] = 0.4 * std::sin(2.0 * t + i) - 0.2 * i;
  sensor_msgs::JointState js = jointState(stamp, names, q);
  for (std::size_t i = 0; i < names.size(); ++i) js.effort.push_back(1.0 + i);
  return js;
}

/// Every status of one node on /diagnostics, with its wall time of arrival.
struct DiagnosticsLog {
  struct Entry {
    double wall = 0.0;
    diagnostic_msgs::DiagnosticStatus status;
  };
  std::vector<Entry> entries;
  ros::Subscriber sub;
  DiagnosticsLog() {
    sub = nh().subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 1000, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
          for (const auto& s : m->status) entries.push_back({ros::WallTime::now().toSec(), s});
        });
  }
  /// Statuses named `name` that arrived in [from, to] wall seconds.
  long count(const std::string& name, double from, double to) const {
    long n = 0;
    for (const Entry& e : entries) n += e.status.name == name && e.wall >= from && e.wall <= to;
    return n;
  }
  /// Whether a status `name` at `level` whose message contains `text` came after `from`.
  bool said(const std::string& name, std::uint8_t level, const std::string& text,
            double from = 0.0) const {
    for (const Entry& e : entries)
      if (e.status.name == name && e.wall >= from && e.status.level == level &&
          e.status.message.find(text) != std::string::npos)
        return true;
    return false;
  }
  /// The newest value of `key` in status `name`; -1 if none yet.
  long latest(const std::string& name, const std::string& key) const {
    for (auto it = entries.rbegin(); it != entries.rend(); ++it)
      if (it->status.name == name)
        for (const auto& kv : it->status.values)
          if (kv.key == key) return std::stol(kv.value);
    return -1;
  }
};

DiagnosticsLog& diagnosticsLog() {
  static DiagnosticsLog log;
  return log;
}

double wallNow() { return ros::WallTime::now().toSec(); }

// What a hostile kind sends beside the good sample: joint states and wrenches to the
// hostile node (numbered as the node counts them).
struct HostileSend {
  std::function<void(sensor_msgs::JointState)> joint;
  std::function<void(geometry_msgs::WrenchStamped)> wrench;
};

// One hostile kind: what it does to the hostile copy of a good sample `js` (sending
// its own messages with `send`), and the key counting it.
struct Kind {
  const char* name;  // the test's name
  const char* what;
  const char* key;
  std::function<void(sensor_msgs::JointState& js, const HostileSend& send)> apply;
};

// A joint state of the sample `js`, 0.3 rad off, stamped `stamp`.
sensor_msgs::JointState offBy(const sensor_msgs::JointState& js, const ros::Time& stamp) {
  sensor_msgs::JointState bad = js;
  bad.header.stamp = stamp;
  for (double& q : bad.position) q += 0.3;
  return bad;
}

// A wrench of 1000 N stamped `stamp`: used, it would change every load.
geometry_msgs::WrenchStamped wild(const ros::Time& stamp) {
  geometry_msgs::WrenchStamped w;
  w.header.stamp = stamp;
  w.header.frame_id = "tool0";
  w.wrench.force.x = 1000.0;
  w.wrench.torque.y = -100.0;
  return w;
}

const ros::Duration kTwoHours(7200.0);

// A joint state 0.5 ms before the sample `js`, joint 1 at `q1`: used, it would be a
// sample of its own (and a glitch in every filter).
sensor_msgs::JointState joint1At(const sensor_msgs::JointState& js, double q1) {
  sensor_msgs::JointState bad = js;
  bad.header.stamp = js.header.stamp - ros::Duration(0.0005);
  bad.position[1] = q1;
  return bad;
}

const std::vector<Kind>& kinds() {
  static const std::vector<Kind> table = {
      {"DuplicateName", "a joint named twice, the second 0.5 rad off", "dropped: invalid",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         sensor_msgs::JointState bad = js;
         bad.name.push_back(js.name[1]);
         bad.position.push_back(js.position[1] + 0.5);
         bad.effort.push_back(0.0);
         send.joint(bad);
       }},
      {"EmptyJointState", "an empty joint state", "not used: no needed joint",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         sensor_msgs::JointState empty;
         empty.header.stamp = js.header.stamp - ros::Duration(0.0005);
         send.joint(empty);
       }},
      {"OtherPublishersJoint", "a gripper's joint alone", "not used: no needed joint",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         sensor_msgs::JointState gripper;
         gripper.header.stamp = js.header.stamp - ros::Duration(0.0003);
         gripper.name = {"gripper_finger_joint"};
         gripper.position = {0.02};
         send.joint(gripper);
       }},
      // Joint states split over two publishers (docs/node.md "Never silently wrong"): the arm's
      // first three joints 0.3 ms before the other three, the same positions as the clean
      // sample: merged into one sample, stamped with the newer stamp, the clean loads.
      {"SplitPublishers", "the sample split over two publishers, 0.3 ms apart",
       "merged: joint states of one instant from several publishers",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         sensor_msgs::JointState first = js;
         first.header.stamp = js.header.stamp - ros::Duration(0.0003);
         const auto keep = [](auto& v, std::size_t from, std::size_t to) {
           if (v.empty()) return;
           v.assign(v.begin() + static_cast<long>(from), v.begin() + static_cast<long>(to));
         };
         const std::size_t n = js.name.size();
         for (auto* v : {&first.position, &first.velocity, &first.effort}) keep(*v, 0, 3);
         keep(first.name, 0, 3);
         for (auto* v : {&js.position, &js.velocity, &js.effort}) keep(*v, 3, n);
         keep(js.name, 3, n);
         send.joint(first);
       }},
      {"NanEffort", "a NaN effort", "efforts not compared: non-finite",
       [](sensor_msgs::JointState& js, const HostileSend&) {
         js.effort[2] = std::numeric_limits<double>::quiet_NaN();
       }},
      // Stamps (docs/node.md, "Time stamps"): a single outlier is not a jump of time.
      {"JointStateTwoHoursAhead", "a joint state stamped 2 h ahead", "dropped: rogue stamp",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.joint(offBy(js, js.header.stamp + kTwoHours));
       }},
      {"JointStateTwoHoursBack", "a joint state stamped 2 h back", "dropped: rogue stamp",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.joint(offBy(js, js.header.stamp - kTwoHours));
       }},
      {"JointStateStampedZero", "a joint state stamped 0 on a stamped stream",
       "dropped: rogue stamp",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.joint(offBy(js, ros::Time()));
       }},
      {"WrenchTwoHoursAhead", "a wrench stamped 2 h ahead", "dropped: rogue stamp",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.wrench(wild(js.header.stamp + kTwoHours));
       }},
      {"WrenchTwoHoursBack", "a wrench stamped 2 h back", "dropped: rogue stamp",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.wrench(wild(js.header.stamp - kTwoHours));
       }},
      {"WrenchAheadOfItsTimeout", "a wrench ahead of the joint states by 0.5 s (timeout 0.05 s)",
       "dropped: rogue stamp",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.wrench(wild(js.header.stamp + ros::Duration(0.5)));
       }},
      {"WrenchStampedZero", "a wrench stamped 0 on a stamped input", "dropped: rogue stamp",
       [](sensor_msgs::JointState&, const HostileSend& send) { send.wrench(wild(ros::Time())); }},
      // Never silently wrong (issue 39): values no UR5 produces.
      {"AbsurdPosition", "a joint state with a position of 1e300 rad", "dropped: implausible",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.joint(joint1At(js, 1e300));
       }},
      {"PositionBeyondLimits", "a joint state with a position of 100 rad (limits 2 pi)",
       "dropped: implausible",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.joint(joint1At(js, 100.0));
       }},
      {"GlitchedPosition", "a joint state with one joint 3 rad off for one sample",
       "dropped: implausible",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         send.joint(joint1At(js, js.position[1] + 3.0));
       }},
      {"AbsurdWrench", "a wrench of 1e300 N", "dropped: implausible",
       [](sensor_msgs::JointState& js, const HostileSend& send) {
         geometry_msgs::WrenchStamped w = wild(js.header.stamp);
         w.wrench.force.x = 1e300;
         send.wrench(w);
       }},
  };
  return table;
}

// Sends n samples of the arm at kRate (wall), from sample `first`, to `node`.
void play(NodeUnderTest& node, const std::vector<std::string>& names, const ros::Time& start,
          int first, int n) {
  ros::WallRate rate(kRate);
  for (int k = first; k < first + n; ++k) {
    node.send(armState(names, at(start, k), start));
    ros::spinOnce();
    rate.sleep();
  }
}

// Every load of `clean` stamped in [from, to] is in `hostile` at the same stamp, equal
// to kExact; the loads whose measured effort of joint 2 only the hostile copy lacks (NaN
// effort), counted.
long sameLoads(const LoadsRecorder& clean, const LoadsRecorder& hostile, const ros::Time& from,
               const ros::Time& to) {
  long nan_compared = 0;
  for (const auto& c : clean.msgs()) {
    if (c->header.stamp < from || c->header.stamp > to) continue;
    const auto h = hostile.find(c->header.stamp);
    EXPECT_TRUE(h) << "no hostile loads at " << c->header.stamp;
    if (!h) return -1;
    for (std::size_t j = 0; j < c->name.size(); ++j) {
      const auto &a = c->wrench[j], &b = h->wrench[j];
      for (double d : {a.force.x - b.force.x, a.force.y - b.force.y, a.force.z - b.force.z,
                       a.torque.x - b.torque.x, a.torque.y - b.torque.y, a.torque.z - b.torque.z,
                       c->effort[j] - h->effort[j]})
        EXPECT_LE(std::abs(d), kExact) << c->name[j] << " at " << c->header.stamp;
    }
    nan_compared += std::isnan(h->measured_effort[2]) && !std::isnan(c->measured_effort[2]);
    EXPECT_EQ(h->measured_effort[1], c->measured_effort[1]);
  }
  return nan_compared;
}

// The loads published in [from, to] by a node.
long loadsIn(const LoadsRecorder& loads, const ros::Time& from, const ros::Time& to) {
  long n = 0;
  for (const auto& m : loads.msgs()) n += m->header.stamp >= from && m->header.stamp <= to;
  return n;
}

// The clean and the hostile node of hostile.test, with their tool-wrench inputs.
struct HostilePair {
  NodeUnderTest clean{"clean"}, hostile{"hostile"};
  ros::Publisher clean_ft = nh().advertise<geometry_msgs::WrenchStamped>("/clean/ft", 1000);
  ros::Publisher hostile_ft = nh().advertise<geometry_msgs::WrenchStamped>("/hostile/ft", 1000);
  bool connected = false;
  // Both nodes get the same constant tool wrench at every sample: whichever order its
  // reading and the joint state arrive in, each node reads the same value, so the two
  // nodes' loads stay equal bit for bit while a used wild reading would not.
  geometry_msgs::WrenchStamped tool;

  ::testing::AssertionResult connect() {
    if (connected) return ::testing::AssertionSuccess();
    for (NodeUnderTest* n : {&clean, &hostile})
      if (::testing::AssertionResult r = n->connect(); !r) return r;
    if (!waitForSubscriber(clean_ft, clean.name()) ||
        !waitForSubscriber(hostile_ft, hostile.name()))
      return ::testing::AssertionFailure() << "no subscriber to the tool wrench";
    tool.header.frame_id = "tool0";
    tool.wrench.force.z = -15.0;
    tool.wrench.torque.x = 0.7;
    connected = true;
    return ::testing::AssertionSuccess();
  }
  void sendTool(const ros::Time& stamp) {
    tool.header.stamp = stamp;
    clean_ft.publish(tool);
    hostile_ft.publish(tool);
  }
};

HostilePair& hostilePair() {
  static HostilePair pair;
  return pair;
}

// n samples of the 500 Hz arm from `start` to the clean and the hostile node, the
// hostile one getting a message of the next kind of `cycle` every 10 samples: its loads
// must be the clean node's at every stamp, each bad message counted under its key,
// nothing lost, and /diagnostics at its rate throughout.
void hostileStream(const std::vector<const Kind*>& cycle, const ros::Time& start, int n) {
  HostilePair& pair = hostilePair();
  ASSERT_TRUE(pair.connect());
  NodeUnderTest &clean = pair.clean, &hostile = pair.hostile;
  DiagnosticsLog& diag = diagnosticsLog();
  // What came before (another stream) has been taken: the counters from here on (not
  // fatal: the stream's own checks then say what differs).
  EXPECT_TRUE(waitFor([&] {
    return diag.latest(hostile.status(), "joint states received") == hostile.sent() &&
           diag.latest(clean.status(), "joint states received") == clean.sent();
  }));
  std::map<std::string, long> before;
  const std::vector<std::string> keys = {"dropped: invalid",
                                         "not used: no needed joint",
                                         "efforts not compared: non-finite",
                                         "dropped: rogue stamp",
                                         "dropped: stamp order",
                                         "dropped: implausible",
                                         "not published: non-finite loads",
                                         "time jumps back",
                                         "merged: joint states of one instant from several "
                                         "publishers",
                                         "input '/hostile/joint_states': lost (header.seq gaps)"};
  for (const std::string& key : keys)
    before[key] = std::max(0L, diag.latest(hostile.status(), key));
  Reference ref(kUr5);
  const std::vector<std::string>& names = ref.model.coordinate_names;
  std::map<std::string, long> expected;
  const HostileSend send{
      [&](const sensor_msgs::JointState& js) { hostile.sendKeepingClock(js); },
      [&](const geometry_msgs::WrenchStamped& w) { pair.hostile_ft.publish(w); }};
  simClock().set(at(start, 0));
  ros::WallDuration(0.1).sleep();  // the clock at the nodes before the first joint state
  const double begin = wallNow();
  ros::WallRate rate(kRate);
  for (int k = 0; k < n; ++k) {
    sensor_msgs::JointState good = armState(names, at(start, k), start), bad = good;
    simClock().set(good.header.stamp);
    if (k % 10 == 5) {
      const Kind& kind = *cycle[static_cast<std::size_t>(k / 10) % cycle.size()];
      kind.apply(bad, send);
      ++expected[kind.key];
    }
    send.joint(bad);
    clean.sendKeepingClock(good);
    // The wrench after the joint state of its stamp; the first one of a stream once the
    // nodes have taken that joint state (it would be far ahead of the last stream's).
    if (k == 0) ros::WallDuration(0.05).sleep();
    pair.sendTool(good.header.stamp);
    ros::spinOnce();
    rate.sleep();
  }
  const double end = wallNow();
  spinUntilQuiet([&] { return clean.loads().size() + hostile.loads().size(); });
  ASSERT_TRUE(waitFor([&] {
    return diag.latest(hostile.status(), "joint states received") == hostile.sent();
  })) << diag.latest(hostile.status(), "joint states received")
      << " of " << hostile.sent();

  // The loads: those of the clean stream at every stamp, and at the same stamps.
  const ros::Time last = at(start, n - 1);
  ASSERT_GT(loadsIn(clean.loads(), start, last), n - 10);
  EXPECT_EQ(loadsIn(hostile.loads(), start, last), loadsIn(clean.loads(), start, last));
  EXPECT_EQ(sameLoads(clean.loads(), hostile.loads(), start, last),
            expected["efforts not compared: non-finite"]);
  // Each bad message under its reason, and nothing else; nothing lost at 500 Hz.
  for (const std::string& key : keys)
    EXPECT_EQ(diag.latest(hostile.status(), key) - before[key], expected[key]) << key;
  EXPECT_EQ(diag.latest(clean.status(), "input '/clean/joint_states': lost (header.seq gaps)"), 0);
  // /diagnostics at its rate during the stream (one period of slack at each end).
  const long expected_count = static_cast<long>((end - begin) / kPeriod);
  EXPECT_GE(diag.count(hostile.status(), begin, end), expected_count - 2);
  EXPECT_LE(diag.count(hostile.status(), begin, end), expected_count + 2);
}

// Each kind on its own (the cases of issue 14, one test each): 200 samples, 20 of them
// with the kind beside. Each stream starts 100 s after the last (the clock moves as
// far: a pause, not a rogue stamp).
class HostileKind : public ::testing::TestWithParam<int> {};

TEST_P(HostileKind, ChangesNoLoadsAndIsCounted) {
  const Kind& kind = kinds()[static_cast<std::size_t>(GetParam())];
  RecordProperty("kind", kind.what);
  hostileStream({&kind}, ros::Time(20000 + 100 * GetParam(), 0), 200);
}

INSTANTIATE_TEST_SUITE_P(Each, HostileKind, ::testing::Range(0, static_cast<int>(kinds().size())),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return std::string(kinds()[static_cast<std::size_t>(info.param)].name);
                         });

// Every kind in turn, a hostile message every 10 samples of a 2 s stream at 500 Hz.
TEST(Hostile, AHostileMessageEveryTenSamplesChangesNoLoadsAndIsCounted) {
  std::vector<const Kind*> cycle;
  for (const Kind& kind : kinds()) cycle.push_back(&kind);
  hostileStream(cycle, ros::Time(10000, 0), 1000);
}

// A burst faster than the node takes it: what its publisher numbered (roscpp numbers
// every message, header.seq) and the node never received is counted as lost, exactly.
// A few paced messages before and after the burst, so that a loss at its start or end
// is a gap too.
TEST(Hostile, LossAboveCapacityIsCounted) {
  NodeUnderTest node("flood");
  ASSERT_TRUE(node.connect());
  DiagnosticsLog& diag = diagnosticsLog();
  Reference ref(kUr5);
  const std::vector<std::string>& names = ref.model.coordinate_names;
  const ros::Time start(600, 0);
  play(node, names, start, 0, 10);
  simClock().set(at(start, 10010));
  for (int k = 10; k < 10010; ++k) node.sendKeepingClock(armState(names, at(start, k), start));
  play(node, names, start, 10010, 10);
  const std::string status = node.status(),
                    key = "input '/flood/joint_states': lost (header.seq gaps)";
  long received = -1, lost = -1;
  EXPECT_TRUE(waitFor([&] {
    received = diag.latest(status, "joint states received");
    lost = diag.latest(status, key);
    return received >= 0 && lost >= 0 && received + lost == node.sent();
  })) << "received "
      << received << " + lost " << lost << " != sent " << node.sent();
  RecordProperty("burst_lost", static_cast<int>(lost));
  if (lost > 0) {
    EXPECT_TRUE(diag.said(status, diagnostic_msgs::DiagnosticStatus::WARN, "messages lost"));
  }
}

// rosbag play -l: the clock and the stamps jump back; then the publisher stops.
TEST(Hostile, DiagnosticsKeepTheirRateThroughALoopingBagAndAStoppedPublisher) {
  NodeUnderTest node("loop");
  ASSERT_TRUE(node.connect());
  DiagnosticsLog& diag = diagnosticsLog();
  Reference ref(kUr5);
  const ros::Time start(300, 0);
  play(node, ref.model.coordinate_names, start, 0, 250);
  const double jump = wallNow();
  // The loop again, from 2.5 s back (beyond time_jump_threshold, 1 s).
  play(node, ref.model.coordinate_names, start - ros::Duration(2.0), 0, 250);
  const double stop = wallNow();
  EXPECT_TRUE(waitFor([&] {
    return diag.said(node.status(), diagnostic_msgs::DiagnosticStatus::ERROR, "no joint states for",
                     stop);
  })) << "no ERROR when the joint states stopped";
  waitFor([] { return false; }, 2 * kPeriod);
  const double end = wallNow();
  EXPECT_GE(diag.count(node.status(), jump, end), static_cast<long>((end - jump) / kPeriod) - 2);
  EXPECT_GE(diag.latest(node.status(), "time jumps back"), 1);
  EXPECT_TRUE(diag.said(node.status(), diagnostic_msgs::DiagnosticStatus::OK, "publishing", jump));
}

TEST(Hostile, DiagnosticsNameTheMissingJoint) {
  NodeUnderTest node("missing");
  ASSERT_TRUE(node.connect());
  DiagnosticsLog& diag = diagnosticsLog();
  Reference ref(kUr5);
  std::vector<std::string> five = ref.model.coordinate_names;
  five.pop_back();
  const double begin = wallNow();
  const ros::Time start(400, 0);
  int k = 0;
  const bool named = waitFor([&] {
    play(node, five, start, k, 10);
    k += 10;
    return diag.said(node.status(), diagnostic_msgs::DiagnosticStatus::ERROR,
                     "waiting for joint '" + ref.model.coordinate_names.back() + "'");
  });
  EXPECT_TRUE(named);
  const double end = wallNow();
  EXPECT_GE(diag.count(node.status(), begin, end), static_cast<long>((end - begin) / kPeriod) - 2);
  EXPECT_EQ(node.loads().size(), 0u);
}

// ft (hold) gets every reading in a frame nobody knows: WARN, all dropped. ft2 (stop)
// stops: ERROR naming ft2, and the log names ft2 alone.
TEST(Hostile, DiagnosticsNameTheDroppedAndTheStaleInput) {
  NodeUnderTest node("stale");
  ros::Publisher ft = nh().advertise<geometry_msgs::WrenchStamped>("/stale/ft", 100);
  ros::Publisher ft2 = nh().advertise<geometry_msgs::WrenchStamped>("/stale/ft2", 100);
  ASSERT_TRUE(node.connect());
  ASSERT_TRUE(waitForSubscriber(ft, node.name()));
  ASSERT_TRUE(waitForSubscriber(ft2, node.name()));
  DiagnosticsLog& diag = diagnosticsLog();
  Reference ref(kUr5);
  const ros::Time start(500, 0);
  int k = 0;
  bool ft2_on = true;
  auto step = [&](int samples) {
    ros::WallRate rate(kRate);
    for (int i = 0; i < samples; ++i, ++k) {
      geometry_msgs::WrenchStamped w;
      w.header.stamp = at(start, k);
      w.wrench.force.z = 3.0;
      simClock().set(w.header.stamp);
      w.header.frame_id = "nowhere";
      ft.publish(w);
      w.header.frame_id = "tool0";
      if (ft2_on) ft2.publish(w);
      node.sendKeepingClock(armState(ref.model.coordinate_names, w.header.stamp, start));
      ros::spinOnce();
      rate.sleep();
    }
  };
  using diagnostic_msgs::DiagnosticStatus;
  EXPECT_TRUE(waitFor([&] {
    step(10);
    return diag.said(node.status(), DiagnosticStatus::WARN,
                     "input 'ft': every reading dropped (unresolved frame)");
  }));
  EXPECT_GT(node.loads().size(), 0u);
  ft2_on = false;
  const double stopped = wallNow();
  EXPECT_TRUE(waitFor([&] {
    step(10);
    return diag.said(node.status(), DiagnosticStatus::ERROR, "not publishing: input 'ft2' stale",
                     stopped);
  }));
  EXPECT_TRUE(logs().waitFor(node.name(), rosgraph_msgs::Log::WARN,
                             {"(stale_policy stop): ft2: not publishing"}));
  EXPECT_EQ(logs().count(node.name(), rosgraph_msgs::Log::DEBUG, {"(stale_policy stop): ft,"}), 0u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_hostile");
  jle_test::nh();
  jle_test::simClock();
  jle_test::logs();
  diagnosticsLog();
  return RUN_ALL_TESTS();
}
