// libFuzzer target: the node's message path, jle::Pipeline, the code the node and
// process_bag run. The fuzz bytes decode into a stream of JointState-like messages
// (names from a small alphabet with unknown and repeated ones, NaN / inf / huge values,
// messages that set none of the needed joints,
// empty and mismatched arrays, stamp 0, duplicate, backward and jumping stamps over the
// whole range a ROS stamp holds), wrench messages (frames known and unknown) and jumps
// of the clock. Checks the documented outcome of every message against a shadow of
// the rules (invalid sizes and values, stamp 0, stamp order, rogue stamps, confirmed
// jumps and resets: docs/node.md, "Time stamps"; joint states of several publishers merged
// into one sample per instant, stamps/merge_window), that every message is counted once,
// and the published records. Built by build_and_run.sh.
#include "fuzz_check.hpp"

#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#ifndef JLE_FUZZ_DATA
#error "JLE_FUZZ_DATA (the path of test/data) must be defined"
#endif

namespace {

// Reads the fuzz bytes; zeros once they run out.
class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  double raw() {
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits = (bits << 8) | byte();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }
  std::uint64_t raw64() {
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits = (bits << 8) | byte();
    return bits;
  }
  // A value from a table of the interesting ones, or the next 8 bytes as a double.
  double value() {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    static const double kTable[] = {0.0,
                                    0.1,
                                    -0.5,
                                    1.0,
                                    3.14159,
                                    -2.0,
                                    1e-300,
                                    1e300,
                                    -1e300,
                                    1e6,
                                    -0.0,
                                    kInf,
                                    -kInf,
                                    std::numeric_limits<double>::quiet_NaN(),
                                    std::numeric_limits<double>::denorm_min()};
    const std::uint8_t b = byte();
    if (b < 200) return kTable[b % (sizeof kTable / sizeof kTable[0])];
    return raw();
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

const char* const kNames[] = {"shoulder_pan_joint",
                              "shoulder_lift_joint",
                              "elbow_joint",
                              "wrist_1_joint",
                              "wrist_2_joint",
                              "wrist_3_joint",
                              "wrist_3_link-tool0_fixed_joint",  // fixed: not a coordinate
                              "unknown_joint",
                              "",
                              "elbow_joint "};
constexpr std::size_t kNameCount = sizeof kNames / sizeof kNames[0];

const jle::Model<double>& model() {
  static const jle::Model<double> m =
      jle::modelFromUrdfFile(JLE_FUZZ_DATA "/urdf/chains/ur5_chain.urdf");
  return m;
}

}  // namespace

namespace {

constexpr jle::Stamp kMaxStamp = 4294967295999999999;  // a ROS time: uint32 s, uint32 ns
constexpr jle::Stamp kStart = 1700000000000000000;
// Random stamps within 2^51 ns (26 days) of the start; stamp 0 and small steps from it
// reach the far end of time (a simulation clock from 0), which re-anchors the time axis.
constexpr jle::Stamp kReach = jle::Stamp{1} << 51;

// The settings from the first two bytes.
jle::Settings settingsFrom(Bytes& in) {
  jle::Settings settings;
  jle::EstimatorConfig& config = settings.estimator;
  const std::uint8_t c0 = in.byte();
  switch (c0 % 3) {
    case 0:
      config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
      config.differentiator.window = 5;
      config.differentiator.delay = (c0 >> 2) % 3;
      break;
    case 1:
      config.differentiator.type = jle::DifferentiatorType::kFiniteDifference;
      config.differentiator.window = 3;
      break;
    default:
      config.differentiator.type = jle::DifferentiatorType::kKalman;
      config.differentiator.kalman_model = jle::KalmanModel::kConstantAcceleration;
      config.differentiator.process_noise = 1e3;
      break;
  }
  config.decimation = 1 + (c0 >> 4) % 3;
  config.precision = (c0 & 0x80) ? jle::Precision::kFloat : jle::Precision::kDouble;
  const std::uint8_t c1 = in.byte();
  if (c1 & 1) config.joints = {"elbow_joint", "wrist_3_joint"};
  config.savings.reuse_unchanged = (c1 & 2) != 0;
  config.savings.static_velocity = (c1 & 4) ? 1e-3 : 0.0;
  config.savings.static_acceleration = (c1 & 4) ? 1e-3 : 0.0;
  jle::WrenchInputConfig wrench;
  wrench.name = "ft";
  wrench.link = (c1 & 8) ? "tool0" : "wrist_2_link";
  wrench.sign = (c1 & 16) ? -1.0 : 1.0;
  wrench.timeout = 0.05;
  wrench.stale_policy = static_cast<jle::StalePolicy>((c1 >> 5) % 3);
  config.wrenches.push_back(wrench);
  jle::WrenchTopicSettings topic;
  topic.topic = "ft";
  settings.wrenches.push_back(topic);
  return settings;
}

// The next stamp [ns] and clock from the fuzz bytes, within what a ROS time holds.
void advance(Bytes& in, jle::Stamp& stamp, jle::Stamp& clock) {
  switch (in.byte() % 9) {
    case 0: break;                                                     // duplicate
    case 1: stamp = std::max<jle::Stamp>(0, stamp - 10000000); break;  // backward 10 ms
    case 2: stamp = std::min(kMaxStamp, stamp + 1000000000); break;    // a gap of 1 s
    case 3:
      stamp = kStart - kReach +
              static_cast<jle::Stamp>(in.raw64() % static_cast<std::uint64_t>(2 * kReach));
      break;
    case 4: stamp = 0; break;                                            // "no stamp": the clock
    case 5: clock = std::max<jle::Stamp>(1, clock - 5000000000); break;  // clock jumps back
    default: stamp = std::min(kMaxStamp, stamp + 2000000 * (1 + in.byte() % 8)); break;
  }
  clock = std::min(kMaxStamp, clock + 1000000);
}

// The shadow of the pipeline's rules on stamps (docs/node.md, "Time stamps"; the settings'
// time_jump_threshold 1 s, stamps/jump_confirm 3, the wrench's timeout 0.05 s): stamp 0
// per input, the last joint state taken, rogue stamps (a gap the clock saw too is none)
// and the jumps they confirm, the clock going back.
struct Shadow {
  jle::Stamp last = 0;     // 0: none since the start or a reset
  jle::Stamp highest = 0;  // the newest sample taken on any timeline
  jle::Stamp last_clock = 0, pending_stamp = 0, taken_clock = 0;
  int pending = 0, clock_back = 0;
  bool joints_stamped = false, wrench_stamped = false;
  double period = 0.0;     // [ns] the joint stream's (its sample clock's) before the message
  jle::Stamp origin = -1;  // the time axis's origin before the message (-1: none)
  void before(const jle::Pipeline& p) {
    period = p.sampleClock().period();
    origin = p.hasTimeOrigin() ? p.timeOrigin() : -1;
  }
  // False: stamp 0 on an input that has had stamps (dropped); else `stamp` is effective.
  static bool zero(bool& stamped, jle::Stamp& stamp, jle::Stamp clock) {
    if (stamp != 0) return stamped = true;
    if (!stamped) stamp = clock;
    return !stamped;
  }
  // The instant being assembled from partial joint states (Pipeline's Group): its
  // stamps, the needed coordinates it has, whether its last message was counted merged.
  bool group_open = false, group_last_merged = false;
  jle::Stamp group_oldest = 0, group_newest = 0;
  std::vector<bool> group_has;
  // A reset takes an open instant first, on its own timeline, then forgets it.
  void reset() {
    if (group_open && group_last_merged) highest = std::max(highest, group_newest);
    last = 0, pending = 0, clock_back = 0, group_open = false;
  }
  void clockSeen(jle::Stamp stamp, jle::Stamp clock) {
    const bool back = last_clock != 0 && clock < last_clock;
    last_clock = clock;
    if (back) clock_back = 3;
    if (back && !(stamp > last)) reset();
  }
  // Whether a joint state's stamp is rogue (dropped); a confirmed jump resets.
  bool jointRogue(jle::Stamp stamp, jle::Stamp clock) {
    if (last == 0) return false;
    const double ahead = static_cast<double>(stamp - last) * 1e-9;
    const double forward = std::max(1.0, 10e-9 * period);
    const double lag = static_cast<double>((stamp - clock) - (last - taken_clock));
    if ((ahead >= -1.0 && ahead <= forward) || (ahead > 0.0 && std::abs(lag) * 1e-9 <= 1.0))
      return (pending = 0) != 0;
    const bool follows = pending > 0 && stamp > pending_stamp &&
                         static_cast<double>(stamp - pending_stamp) * 1e-9 <= forward;
    pending = follows ? pending + 1 : 1;
    pending_stamp = stamp;
    if (pending < 3 && !(ahead < 0.0 && clock_back > 0)) return true;
    reset();
    return false;
  }
  // Ahead of the joint states by more than the timeout plus ten periods, or behind by more
  // than the jump threshold.
  bool wrenchRogue(jle::Stamp stamp) const {
    const double ahead = static_cast<double>(stamp - last) * 1e-9;
    return last != 0 && !(ahead <= 0.05 + 1e-8 * period && ahead >= -1.0);
  }
  void taken(jle::Stamp stamp) {
    last = stamp;
    highest = std::max(highest, stamp);
    taken_clock = last_clock;
    if (clock_back > 0) --clock_back;
  }
};

struct JointMessage {
  std::vector<std::string> names;
  std::vector<double> position, velocity, effort;
  bool valid = true;  // sizes agree, names are unique, positions and velocities finite
};

// The needed coordinates the message sets.
std::vector<bool> neededIn(const jle::Pipeline& p, const JointMessage& js) {
  std::vector<bool> has(static_cast<std::size_t>(p.model().nq), false);
  for (const std::string& name : js.names)
    for (int k = 0; k < p.model().nq; ++k)
      if (name == p.model().coordinate_names[static_cast<std::size_t>(k)] && p.coordinateNeeded(k))
        has[static_cast<std::size_t>(k)] = true;
  return has;
}

// Whether the message joins the open instant: within the merge window, and no needed
// coordinate twice.
bool joins(const Shadow& shadow, const std::vector<bool>& has, jle::Stamp stamp, double window) {
  if (!shadow.group_open) return false;
  const jle::Stamp span =
      std::max(shadow.group_newest, stamp) - std::min(shadow.group_oldest, stamp);
  if (1e-9 * static_cast<double>(span) > window) return false;
  for (std::size_t k = 0; k < has.size(); ++k)
    if (has[k] && shadow.group_has[k]) return false;
  return true;
}

// The records an instant closed by this message made, the message's own, and a
// smoother's drained at a reset (of the old timeline): finite, and of a sample taken.
void checkRecords(jle::Pipeline& p, const Shadow& shadow, jle::Outcome outcome) {
  const auto check = [&](const jle::LoadsRecord& r) {
    JLE_FUZZ_CHECK(r.stamp <= shadow.highest);
    JLE_FUZZ_CHECK(r.effort.size() == r.joint.size());
    for (std::size_t i = 0; i < r.effort.size(); ++i)  // never a non-finite load
      JLE_FUZZ_CHECK(std::isfinite(r.effort[i]) && r.force[i].allFinite() &&
                     r.moment[i].allFinite());
  };
  if (outcome == jle::Outcome::kPublished) check(p.record());
  while (p.takeDrained()) check(p.record());
}

// Whether the message sets a coordinate the loads need (else kNoJoint: no sample, no time).
bool moves(const jle::Pipeline& p, const JointMessage& js) {
  for (const std::string& name : js.names)
    for (int k = 0; k < p.model().nq; ++k)
      if (name == p.model().coordinate_names[static_cast<std::size_t>(k)] && p.coordinateNeeded(k))
        return true;
  return false;
}

void decodeJointState(Bytes& in, JointMessage& js) {
  const std::size_t n = in.byte() % 9;
  js.names.resize(n);
  for (std::string& s : js.names) s = kNames[in.byte() % kNameCount];
  const std::uint8_t shape = in.byte();
  std::size_t np = n, ne = (shape & 1) ? n : 0, nv = (shape & 128) ? n : 0;
  if ((shape & 6) == 2) np = n + 1;
  if ((shape & 6) == 4 && n > 0) np = n - 1;
  if ((shape & 24) == 8) ne = n + 2;
  js.position.resize(np);
  js.velocity.resize(nv);
  js.effort.resize(ne);
  for (double& v : js.position) v = (shape & 32) ? in.value() : 0.1 * (in.byte() % 32);
  for (double& v : js.velocity) v = in.value();
  for (double& v : js.effort) v = in.value();
  js.valid = np == n && (ne == 0 || ne == n) && (nv == 0 || nv == n);
  // A non-finite velocity or effort only drops that value (the velocity: the filter's
  // prediction instead; the effort: its comparison).
  for (double v : js.position) js.valid = js.valid && std::isfinite(v);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < i; ++j) js.valid = js.valid && js.names[i] != js.names[j];
}

void checkJointOutcome(jle::Pipeline& p, const JointMessage& js, jle::Stamp stamp, jle::Stamp clock,
                       jle::Outcome outcome, Shadow& shadow) {
  using jle::Outcome;
  if (!js.valid) {
    JLE_FUZZ_CHECK(outcome == Outcome::kInvalid && !p.problem().empty());
    return;
  }
  // A message with no needed joint is neither a sample nor a time: checked first.
  JLE_FUZZ_CHECK((outcome == Outcome::kNoJoint) == !moves(p, js));
  if (outcome == Outcome::kNoJoint) return;
  const bool first = shadow.last == 0;  // no joint state taken on this timeline yet
  const bool rogue = !Shadow::zero(shadow.joints_stamped, stamp, clock) ||
                     (shadow.clockSeen(stamp, clock), shadow.jointRogue(stamp, clock));
  JLE_FUZZ_CHECK(rogue == (outcome == Outcome::kRogueStamp));
  if (rogue) {
    JLE_FUZZ_CHECK(!p.problem().empty());
    return;
  }
  // The first joint state of a timeline whose axis the wrenches set more than its reach
  // (2^52 ns) away restarts it (docs/node.md, "Time stamps"); the clock going back resets
  // only when the stamps do not go forward, so not here.
  if (first && p.jumped()) {
    JLE_FUZZ_CHECK(shadow.origin >= 0 && std::abs(stamp - shadow.origin) > jle::Stamp{1} << 52);
    shadow.reset();
  }
  JLE_FUZZ_CHECK(outcome != Outcome::kInvalid && outcome != Outcome::kFrame);
  // The order before anything is stored: of an instant taken, or older than the open one.
  const std::vector<bool> has = neededIn(p, js);
  const bool joining = joins(shadow, has, stamp, p.settings().stamps.merge_window);
  const jle::Stamp newest =
      std::max(shadow.last, shadow.group_open && !joining ? shadow.group_newest : 0);
  JLE_FUZZ_CHECK((outcome == Outcome::kOrder) == (newest != 0 && stamp <= newest));
  if (outcome == Outcome::kOrder) return;
  // A value no UR5 produces (beyond its limits, faster than it moves): dropped after the
  // stamp checks, not taken, named.
  if (outcome == Outcome::kImplausible) {
    JLE_FUZZ_CHECK(!p.problem().empty());
    return;
  }
  // A later instant closes the open one: taken (its missing joints held) unless its last
  // message was waiting for a joint never received.
  if (shadow.group_open && !joining) {
    if (shadow.group_last_merged) shadow.taken(shadow.group_newest);
    shadow.group_open = false;
  }
  if (!shadow.group_open) {
    shadow.group_has.assign(has.size(), false);
    shadow.group_oldest = shadow.group_newest = stamp;
  }
  shadow.group_open = true;
  shadow.group_oldest = std::min(shadow.group_oldest, stamp);
  shadow.group_newest = std::max(shadow.group_newest, stamp);
  bool complete = true;
  for (std::size_t k = 0; k < has.size(); ++k) {
    shadow.group_has[k] = shadow.group_has[k] || has[k];
    complete = complete && (shadow.group_has[k] || !p.coordinateNeeded(static_cast<int>(k)));
  }
  shadow.group_last_merged = outcome == Outcome::kMerged;
  if (outcome == Outcome::kWaiting || outcome == Outcome::kMerged) {
    JLE_FUZZ_CHECK(outcome == Outcome::kWaiting || !complete);
    checkRecords(p, shadow, outcome);
    return;
  }
  JLE_FUZZ_CHECK(complete);
  JLE_FUZZ_CHECK(shadow.last == 0 || shadow.group_newest > shadow.last);
  shadow.taken(shadow.group_newest);
  shadow.group_open = false;
  checkRecords(p, shadow, outcome);
  // The smoothed stream describes a sample taken on this timeline, at or before this one.
  if (p.smoothedPublished()) {
    JLE_FUZZ_CHECK(p.smoothedRecord().stamp <= shadow.last);
    JLE_FUZZ_CHECK(p.smoothedRecord().effort.size() == p.smoothedRecord().joint.size());
  }
}

void checkWrenchOutcome(const jle::Pipeline& p, const Eigen::Vector3d& force,
                        const Eigen::Vector3d& moment, const std::string& frame, jle::Stamp stamp,
                        jle::Stamp clock, jle::Outcome outcome, Shadow& shadow) {
  using jle::Outcome;
  if (!force.allFinite() || !moment.allFinite()) {
    JLE_FUZZ_CHECK(outcome == Outcome::kInvalid);
    return;
  }
  const bool rogue = !Shadow::zero(shadow.wrench_stamped, stamp, clock) ||
                     (shadow.clockSeen(stamp, clock), shadow.wrenchRogue(stamp));
  JLE_FUZZ_CHECK(rogue == (outcome == Outcome::kRogueStamp));
  if (rogue) {
    JLE_FUZZ_CHECK(!p.problem().empty());
    return;
  }
  // Beyond plausibility's bounds (the defaults: settingsFrom leaves them): dropped, named.
  const jle::PlausibilityConfig bounds;
  const bool implausible =
      force.stableNorm() > bounds.max_force || moment.stableNorm() > bounds.max_moment;
  JLE_FUZZ_CHECK(implausible == (outcome == Outcome::kImplausible));
  if (implausible) {
    JLE_FUZZ_CHECK(!p.problem().empty());
    return;
  }
  if (frame == "nowhere") JLE_FUZZ_CHECK(outcome == Outcome::kFrame);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Bytes in(data, size);
  std::unique_ptr<jle::Pipeline> pipeline;
  try {
    pipeline = std::make_unique<jle::Pipeline>(model(), settingsFrom(in), nullptr);
  } catch (const std::invalid_argument&) {
    return 0;  // a configuration the pipeline refuses (documented)
  }
  jle::Pipeline& p = *pipeline;
  jle::Stamp stamp = kStart, clock = stamp;
  Shadow shadow;
  JointMessage js;
  long messages = 0;
  for (int op = 0; op < 400 && !in.empty(); ++op) {
    const std::uint8_t kind = in.byte();
    advance(in, stamp, clock);
    ++messages;
    shadow.before(p);
    if (kind % 8 >= 6) {  // a wrench message, in a frame the URDF has or not
      Eigen::Vector3d f, mo;
      for (int i = 0; i < 3; ++i) f[i] = in.value();
      for (int i = 0; i < 3; ++i) mo[i] = in.value();
      const std::string frame = kind % 8 == 7 ? "tool0" : (kind & 8) ? "base_link" : "nowhere";
      const jle::Outcome outcome = p.onWrench(0, stamp, clock, frame, f, mo);
      checkWrenchOutcome(p, f, mo, frame, stamp, clock, outcome, shadow);
      checkRecords(p, shadow, outcome);  // a reset's drained loads
      continue;
    }
    decodeJointState(in, js);
    const jle::Outcome outcome =
        p.onJointState(stamp, clock, js.names, js.position, js.velocity, js.effort);
    checkJointOutcome(p, js, stamp, clock, outcome, shadow);
  }
  const jle::PipelineCounters& c = p.counters();
  JLE_FUZZ_CHECK(c.received(jle::InputKind::kJointState) + c.received(jle::InputKind::kWrench) ==
                 messages);
  return 0;
}
