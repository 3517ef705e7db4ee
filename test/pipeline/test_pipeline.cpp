// The message path (pipeline.hpp), against independent references: the exact loads of
// an exactly differentiable trajectory fed as partial joint states from two publishers
// with jittered stamps; the joints a published subset needs; stamps and measured
// efforts paired with a delayed estimate; frames from the URDF and from a frame source;
// a floating base; sensor biases; time jumps; and that every message is counted once.
#include <jle_testing/message_stream.hpp>
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace {

using jle::InputKind;
using jle::Outcome;
using jle::Stamp;

using jle_test::kData;
using jle_test::kMs;
using jle_test::kNone;
using jle_test::kStart;
using jle_test::ur5;

// The arm's joints (0-2): q_i(t) = a_i + b_i t + c_i t^2 (t [s] since kStart), for which
// the 3-point difference is exact; the wrist's (3-5) are held still, so that a sample
// holding their last message's positions is exact too.
double q(int i, double t) {
  return i < 3 ? 0.1 * i - 0.3 + (0.5 - 0.2 * i) * t + 0.7 * std::cos(i) * t * t : 0.2 * i;
}
double qd(int i, double t) { return i < 3 ? (0.5 - 0.2 * i) + 1.4 * std::cos(i) * t : 0.0; }
double qdd(int i) { return i < 3 ? 1.4 * std::cos(i) : 0.0; }

jle::Settings finiteDifferences() {
  jle::Settings s;
  s.estimator.differentiator.type = jle::DifferentiatorType::kFiniteDifference;
  s.estimator.differentiator.window = 3;
  return s;
}

void addWrenchInput(jle::Settings& s, const std::string& link, const std::string& frame = "") {
  jle::WrenchInputConfig input;
  input.name = "ft";
  input.link = link;
  s.estimator.wrenches.push_back(input);
  jle::WrenchTopicSettings topic;
  topic.topic = "ft";
  topic.frame = frame;
  s.wrenches.push_back(topic);
}

// Frames a test names, at any stamp (a tf2 buffer's role).
class FixedFrames : public jle::FrameSource {
 public:
  std::map<std::pair<std::string, std::string>, Eigen::Isometry3d> poses;
  long lookups = 0;
  bool lookup(const std::string& target, const std::string& frame, Stamp, Eigen::Isometry3d& X,
              std::string& error) override {
    ++lookups;
    const auto it = poses.find({target, frame});
    if (it == poses.end()) {
      error = "unknown to the test";
      return false;
    }
    X = it->second;
    return true;
  }
};

TEST(Pipeline, PartialMessagesGiveTheExactLoads) {
  const jle::Model<double> model = ur5();
  jle::Settings settings = finiteDifferences();
  // The stamps are the sampling instants (q is evaluated at them), jittered about a
  // lattice: what stamps/regularize auto takes for receive-time stamps (docs/node.md, "Time
  // stamps"). Off, they are the instants.
  settings.stamps.regularize = jle::StampRegularize::kOff;
  addWrenchInput(settings, "tool0");
  jle::Pipeline pipeline(model, settings, nullptr);
  const std::vector<std::string> arm = {model.coordinate_names[0], model.coordinate_names[1],
                                        model.coordinate_names[2]};
  const std::vector<std::string> wrist = {model.coordinate_names[3], model.coordinate_names[4],
                                          model.coordinate_names[5]};
  const Eigen::Vector3d f(3.0, -1.0, 4.0), m(0.2, 0.1, -0.3);  // constant: resampling exact
  jle::Data<double> reference(model);
  int published = 0;
  const auto check = [&](const jle::LoadsRecord& r) {
    ++published;
    Eigen::VectorXd qv(6), qdv(6), qddv(6);
    // The 3-point estimate describes the middle sample: the record's stamp is its own.
    const double tr = static_cast<double>(r.stamp - kStart) * 1e-9;
    for (int i = 0; i < 6; ++i) {
      qv[i] = q(i, tr);
      qdv[i] = qd(i, tr);
      qddv[i] = qdd(i);
    }
    jle::forwardKinematics(model, reference, qv, qdv, qddv, settings.estimator.gravity_world);
    jle::addExternalWrench(model, reference, model.frameIndex("tool0"), f, m,
                           jle::WrenchFrame::kLocal);
    jle::inverseDynamics(model, reference);
    for (std::size_t i = 0; i < r.segment.size(); ++i) {
      const int s = r.segment[i];
      // 3-point rounding at 1 ms: ~1e-13 rad/s^2 on qdd times O(1) inertias.
      const double scale = 1.0 + reference.force[s].norm() + reference.moment[s].norm();
      EXPECT_LT((r.force[i] - reference.force[s]).norm(), 1e-9 * scale);
      EXPECT_LT((r.moment[i] - reference.moment[s]).norm(), 1e-9 * scale);
      EXPECT_NEAR(r.effort[i], reference.effort[s], 1e-9 * scale);
    }
    EXPECT_TRUE(r.status & jle::kHeldJoint) << r.stamp;  // the wrist's joints held
  };
  for (int k = 0; k < 100; ++k) {
    // Both publishers stamp the same instant (one driver cycle), jittered by 20%.
    const Stamp stamp = kStart + k * kMs + static_cast<Stamp>(2e5 * std::sin(k));
    const double t = static_cast<double>(stamp - kStart) * 1e-9;
    std::vector<double> pa, pw;
    for (int i = 0; i < 3; ++i) pa.push_back(q(i, t));
    for (int i = 3; i < 6; ++i) pw.push_back(q(i, t));
    ASSERT_EQ(pipeline.onWrench(0, stamp, stamp, "tool0", f, m), Outcome::kUsed);
    // The wrist's driver speaks once, first: the arm's joints are still missing. Then
    // it is dead: each arm message's instant waits for it until the next one closes it,
    // and is a sample with the wrist held (its loads come by takeDrained()).
    if (k == 0) {
      EXPECT_EQ(pipeline.onJointState(stamp, stamp, wrist, pw, kNone, kNone), Outcome::kWaiting);
      EXPECT_NE(pipeline.problem().find("'" + arm[0] + "'"), std::string::npos)
          << pipeline.problem();
    }
    if (pipeline.onJointState(stamp, stamp, arm, pa, kNone, kNone) == Outcome::kPublished)
      check(pipeline.record());
    while (pipeline.takeDrained()) check(pipeline.record());
  }
  while (pipeline.flush()) check(pipeline.record());
  EXPECT_EQ(published, 98);  // every stamp but the window's start
  const jle::PipelineCounters& c = pipeline.counters();
  EXPECT_EQ(c.received(InputKind::kJointState), 101);
  EXPECT_EQ(c.count(InputKind::kJointState, Outcome::kPublished), 98);
  EXPECT_EQ(c.count(InputKind::kJointState, Outcome::kWaiting), 1);
  EXPECT_EQ(c.count(InputKind::kJointState, Outcome::kUsed), 2);
}

TEST(Pipeline, WaitsOnlyForTheCoordinatesThePublishedJointsNeed) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/talos_reduced.urdf");
  jle::Settings settings = finiteDifferences();
  settings.estimator.joints = {"leg_left_4_joint"};
  jle::Pipeline pipeline(model, settings, nullptr);
  std::vector<std::string> leg;
  for (int j = 1; j <= 6; ++j) leg.push_back("leg_left_" + std::to_string(j) + "_joint");
  int published = 0;
  for (int k = 0; k < 10; ++k) {
    const std::vector<double> p(leg.size(), 0.1 * k);
    if (pipeline.onJointState(kStart + k * kMs, 0, leg, p, kNone, kNone) == Outcome::kPublished)
      ++published;
  }
  EXPECT_EQ(published, 8);
  ASSERT_EQ(pipeline.record().joint, std::vector<std::string>{"leg_left_4_joint"});
  // Without the knee's own coordinate: waiting, naming it.
  jle::Pipeline waiting(model, settings, nullptr);
  leg.erase(leg.begin() + 3);
  EXPECT_EQ(waiting.onJointState(kStart, 0, leg, std::vector<double>(5, 0.0), kNone, kNone),
            Outcome::kWaiting);
  EXPECT_NE(waiting.problem().find("'leg_left_4_joint'"), std::string::npos) << waiting.problem();
}

TEST(Pipeline, DelayedEstimateCarriesTheStampAndEffortsOfItsSample) {
  const jle::Model<double> model = ur5();
  jle::Settings settings;
  settings.estimator.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
  settings.estimator.differentiator.window = 9;
  settings.estimator.differentiator.delay = 4;  // centred: 4 samples behind the newest
  jle::Pipeline pipeline(model, settings, nullptr);
  std::map<Stamp, double> effort_at;
  for (int k = 0; k < 40; ++k) {
    const Stamp stamp = kStart + 2 * k * kMs + (k % 3) * 137;  // odd nanoseconds
    std::vector<double> p(6), e(6);
    for (int i = 0; i < 6; ++i) {
      p[static_cast<std::size_t>(i)] = 0.01 * k * i;
      e[static_cast<std::size_t>(i)] = 100.0 * k + i;
    }
    effort_at[stamp] = e[0];
    if (pipeline.onJointState(stamp, stamp, model.coordinate_names, p, kNone, e) !=
        Outcome::kPublished)
      continue;
    const jle::LoadsRecord& r = pipeline.record();
    ASSERT_EQ(r.stamp, kStart + 2 * (k - 4) * kMs + ((k - 4) % 3) * 137);
    ASSERT_TRUE(effort_at.count(r.stamp));
    EXPECT_EQ(r.measured_effort[0], effort_at[r.stamp]);
  }
}

TEST(Pipeline, WrenchFramesFromTheUrdfOrTheFrameSource) {
  const jle::Model<double> model = ur5();
  const Eigen::Vector3d f(1.0, 2.0, 3.0), m(0.3, -0.2, 0.1);
  // The same wrench given in tool0's frame and in a sensor frame 0.1 m along its z,
  // rotated 90 degrees about z: the same loads (to rounding).
  Eigen::Isometry3d X_tool_sensor = Eigen::Isometry3d::Identity();
  X_tool_sensor.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_tool_sensor.translation() << 0.0, 0.0, 0.1;
  const Eigen::Vector3d f_sensor = X_tool_sensor.linear().transpose() * f;
  const Eigen::Vector3d m_sensor =
      X_tool_sensor.linear().transpose() * (m - X_tool_sensor.translation().cross(f));
  FixedFrames frames;
  frames.poses[{"tool0", "sensor"}] = X_tool_sensor;
  jle::Settings settings = finiteDifferences();
  addWrenchInput(settings, "tool0");
  jle::Pipeline direct(model, settings, nullptr), through(model, settings, &frames);
  EXPECT_EQ(through.onWrench(0, kStart, kStart, "nowhere", f, m), Outcome::kFrame);
  EXPECT_NE(through.problem().find("'nowhere'"), std::string::npos) << through.problem();
  for (int k = 0; k < 5; ++k) {
    const Stamp stamp = kStart + k * kMs;
    ASSERT_EQ(direct.onWrench(0, stamp, stamp, "tool0", f, m), Outcome::kUsed);
    ASSERT_EQ(through.onWrench(0, stamp, stamp, "sensor", f_sensor, m_sensor), Outcome::kUsed);
    const std::vector<double> p(6, 0.1 * k);
    const Outcome a = direct.onJointState(stamp, stamp, model.coordinate_names, p, kNone, kNone);
    const Outcome b = through.onJointState(stamp, stamp, model.coordinate_names, p, kNone, kNone);
    ASSERT_EQ(a, b);
    if (a != Outcome::kPublished) continue;
    for (std::size_t i = 0; i < direct.record().effort.size(); ++i)
      EXPECT_NEAR(direct.record().effort[i], through.record().effort[i], 1e-12);
  }
  // A moving frame is asked for at every message; a URDF frame rigid to the link never.
  EXPECT_EQ(frames.lookups, 6);
  // Without a frame source, only the URDF's frames resolve.
  EXPECT_EQ(direct.onWrench(0, kStart + 9 * kMs, 0, "sensor", f, m), Outcome::kFrame);
}

TEST(Pipeline, SensorBiasIsRemovedInTheReadingsFrame) {
  const jle::Model<double> model = ur5();
  jle::Settings settings = finiteDifferences();
  addWrenchInput(settings, "tool0");
  jle::Pipeline clean(model, settings, nullptr), biased(model, settings, nullptr);
  const Eigen::Vector3d bf(1.5, -2.25, 3.0), bt(0.125, -0.0625, 0.25);
  biased.setSensorBias(0, bf, bt);
  const Eigen::Vector3d f(1.0, 2.0, 3.0), m(0.3, -0.2, 0.1);
  int compared = 0;
  for (int k = 0; k < 5; ++k) {
    const Stamp stamp = kStart + k * kMs;
    clean.onWrench(0, stamp, stamp, "tool0", f, m);
    biased.onWrench(0, stamp, stamp, "tool0", f + bf, m + bt);
    const std::vector<double> p(6, 0.1 * k);
    const Outcome a = clean.onJointState(stamp, stamp, model.coordinate_names, p, kNone, kNone);
    ASSERT_EQ(biased.onJointState(stamp, stamp, model.coordinate_names, p, kNone, kNone), a);
    if (a != Outcome::kPublished) continue;
    ++compared;
    for (std::size_t i = 0; i < clean.record().effort.size(); ++i)
      EXPECT_NEAR(clean.record().effort[i], biased.record().effort[i], 1e-12);  // (x + b) - b
  }
  EXPECT_EQ(compared, 3);
}

TEST(Pipeline, FloatingBasePoseFromTheFrameSource) {
  jle::ModelOptions options;
  options.floating_base = true;
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/free_body.urdf", options);
  jle::Settings settings = finiteDifferences();
  settings.floating_base = true;
  FixedFrames frames;
  jle::Pipeline pipeline(model, settings, &frames);
  EXPECT_EQ(pipeline.onJointState(kStart, kStart, {}, kNone, kNone, kNone), Outcome::kNoBasePose);
  EXPECT_NE(pipeline.problem().find("'" + model.link_name[0] + "' in 'world'"), std::string::npos)
      << pipeline.problem();
  // At rest in the world: the base carries the weight (its residual, segment 0).
  frames.poses[{"world", model.link_name[0]}] = Eigen::Isometry3d::Identity();
  Outcome last = Outcome::kUsed;
  for (int k = 1; k < 5; ++k)
    last = pipeline.onJointState(kStart + k * kMs, kStart + k * kMs, {}, kNone, kNone, kNone);
  ASSERT_EQ(last, Outcome::kPublished);
  EXPECT_NEAR(pipeline.record().base_force.norm(), model.totalMass() * 9.80665, 1e-9);
}

TEST(Pipeline, TimeJumpsAreConfirmedAndFarStampsReanchorTheTimeAxis) {
  const jle::Model<double> model = ur5();
  jle::Pipeline pipeline(model, finiteDifferences(), nullptr);
  const std::vector<double> p(6, 0.2);
  auto feed = [&](Stamp stamp, Stamp clock) {
    return pipeline.onJointState(stamp, clock, model.coordinate_names, p, kNone, kNone);
  };
  for (int k = 0; k < 5; ++k) feed(kStart + k * kMs, kStart + k * kMs);
  // Back by less than time_jump_threshold (1 s): out of order, dropped, no reset.
  EXPECT_EQ(feed(kStart, kStart + 5 * kMs), Outcome::kOrder);
  EXPECT_EQ(pipeline.counters().resets, 0);
  // Back by 2 s with the clock going on (a bag's stamps looping): two rogue stamps,
  // dropped and named; the third in a row (stamps.jump_confirm) is a jump: reset, the
  // filters start again from it, and so does the time axis.
  EXPECT_EQ(feed(kStart - 2000 * kMs, kStart + 6 * kMs), Outcome::kRogueStamp);
  EXPECT_NE(pipeline.problem().find("joint_states: stamp 1699999998.1234"), std::string::npos)
      << pipeline.problem();
  EXPECT_NE(pipeline.problem().find("-2.004000 s from the stream's"), std::string::npos)
      << pipeline.problem();
  EXPECT_EQ(feed(kStart - 1999 * kMs, kStart + 7 * kMs), Outcome::kRogueStamp);
  EXPECT_FALSE(pipeline.jumped());
  EXPECT_EQ(pipeline.counters().resets, 0);
  EXPECT_EQ(feed(kStart - 1998 * kMs, kStart + 8 * kMs), Outcome::kUsed);
  EXPECT_TRUE(pipeline.jumped());
  EXPECT_FALSE(pipeline.jumpedForward());
  EXPECT_EQ(pipeline.jumpFrom(), kStart + 4 * kMs);
  EXPECT_EQ(pipeline.jumpTo(), kStart - 1998 * kMs);
  EXPECT_EQ(pipeline.timeOrigin(), kStart - 1998 * kMs);
  EXPECT_EQ(pipeline.counters().resets, 1);
  EXPECT_EQ(pipeline.counters().count(InputKind::kJointState, Outcome::kRogueStamp), 2);
  // A gap of 5 s that the clock saw too (a paused driver or bag): no rogue stamp, no jump.
  EXPECT_EQ(feed(kStart + 3002 * kMs, kStart + 5008 * kMs), Outcome::kUsed);
  EXPECT_EQ(pipeline.counters().resets, 1);
  EXPECT_EQ(pipeline.counters().count(InputKind::kJointState, Outcome::kRogueStamp), 2);
  // The clock going back while the stamps do not move forward: a reset at once.
  EXPECT_EQ(feed(kStart - 1998 * kMs, kStart), Outcome::kUsed);
  EXPECT_EQ(pipeline.counters().resets, 2);
  EXPECT_EQ(feed(kStart - 1997 * kMs, kStart + kMs), Outcome::kUsed);
  // 100 days ahead: beyond what the time axis resolves to 1 ns, confirmed like any jump,
  // with a new origin; the record still carries the exact stamps.
  const Stamp far = kStart + Stamp{100} * 86400 * 1000000000;
  for (int k = 0; k < 5; ++k)
    EXPECT_EQ(feed(far + k * kMs + 1, far + k * kMs + 1), k < 2   ? Outcome::kRogueStamp
                                                          : k < 4 ? Outcome::kUsed
                                                                  : Outcome::kPublished);
  EXPECT_EQ(pipeline.counters().resets, 3);
  EXPECT_EQ(pipeline.counters().forward_jumps, 1);
  EXPECT_EQ(pipeline.counters().backJumps(), 2);
  EXPECT_EQ(pipeline.timeOrigin(), far + 2 * kMs + 1);
  EXPECT_EQ(pipeline.record().stamp, far + (4 - pipeline.delaySamples()) * kMs + 1);
}

// A wrench stamped by a clock from 0 (a simulation's) before any joint state, the joint
// states by the wall clock: the time axis the wrench set cannot hold the joint states'
// stamps to the nanosecond (at 54 years a double's step is 238 ns), so their first restarts
// the timeline; samples 32 ns apart are then both taken (the fuzzer found them taken for
// duplicates).
TEST(Pipeline, JointStatesFarFromTheWrenchesOriginRestartTheTimeline) {
  const jle::Model<double> model = ur5();
  jle::Settings settings = finiteDifferences();
  addWrenchInput(settings, "tool0");
  jle::Pipeline pipeline(model, settings, nullptr);
  const Eigen::Vector3d f(1.0, 2.0, 3.0), m = Eigen::Vector3d::Zero();
  EXPECT_EQ(pipeline.onWrench(0, 4 * kMs, 4 * kMs, "tool0", f, m), Outcome::kUsed);
  EXPECT_EQ(pipeline.timeOrigin(), 4 * kMs);
  auto feed = [&](Stamp stamp) {
    std::vector<double> p(6);
    const double t = static_cast<double>(stamp - kStart) * 1e-9;
    for (int i = 0; i < 6; ++i) p[static_cast<std::size_t>(i)] = q(i, t);
    return pipeline.onJointState(stamp, stamp, model.coordinate_names, p, kNone, kNone);
  };
  EXPECT_EQ(feed(kStart), Outcome::kUsed);
  EXPECT_TRUE(pipeline.jumped());
  EXPECT_TRUE(pipeline.jumpedForward());
  EXPECT_EQ(pipeline.jumpFrom(), 4 * kMs);
  EXPECT_EQ(pipeline.jumpTo(), kStart);
  EXPECT_EQ(pipeline.timeOrigin(), kStart);
  EXPECT_EQ(pipeline.counters().forward_jumps, 1);
  EXPECT_EQ(feed(kStart + 32), Outcome::kUsed);
  EXPECT_FALSE(pipeline.jumped());
  EXPECT_EQ(feed(kStart + 64), Outcome::kPublished);
  EXPECT_EQ(pipeline.record().stamp, kStart + 64 - 32 * pipeline.delaySamples());
  EXPECT_EQ(pipeline.counters().count(InputKind::kJointState, Outcome::kOrder), 0);
  EXPECT_EQ(pipeline.counters().resets, 1);
  // The wrench's stamps afterwards (received by the wall clock): 54 years behind the
  // joint states, a rogue stamp.
  EXPECT_EQ(pipeline.onWrench(0, 5 * kMs, kStart + 80, "tool0", f, m), Outcome::kRogueStamp);
  // A timeline whose origin the joint states set keeps it for a wrench stamped far away
  // that was not taken (rogue): nothing restarts.
  EXPECT_EQ(feed(kStart + 96), Outcome::kPublished);
  EXPECT_EQ(pipeline.counters().resets, 1);
}

TEST(Pipeline, StampZeroIsTheClockOnlyOnAStreamThatNeverHadStamps) {
  const jle::Model<double> model = ur5();
  jle::Settings settings = finiteDifferences();
  addWrenchInput(settings, "tool0");
  jle::Pipeline pipeline(model, settings, nullptr);
  const Eigen::Vector3d f(1.0, 2.0, 3.0), m(0.3, -0.2, 0.1);
  // A live driver that stamps nothing: the clock (the reception time) stands in. Every
  // joint at 1 rad/s, which a UR5 can do (plausibility: its URDF's 3.15 rad/s).
  for (int k = 0; k < 4; ++k) {
    const Stamp clock = kStart + k * kMs;
    ASSERT_EQ(pipeline.onWrench(0, 0, clock, "tool0", f, m), Outcome::kUsed);
    const std::vector<double> p(6, 0.001 * k);
    const Outcome o = pipeline.onJointState(0, clock, model.coordinate_names, p, kNone, kNone);
    ASSERT_EQ(o, k < 2 ? Outcome::kUsed : Outcome::kPublished) << k << ": " << pipeline.problem();
  }
  EXPECT_EQ(pipeline.record().stamp, kStart + (3 - pipeline.delaySamples()) * kMs);
  // Once a stream has had a stamp, a stamp 0 is dropped and counted, whatever the clock.
  const std::vector<double> p(6, 0.005);
  EXPECT_EQ(pipeline.onJointState(kStart + 5 * kMs, kStart + 5 * kMs, model.coordinate_names, p,
                                  kNone, kNone),
            Outcome::kPublished);
  EXPECT_EQ(pipeline.onJointState(0, kStart + 6 * kMs, model.coordinate_names, p, kNone, kNone),
            Outcome::kRogueStamp);
  EXPECT_NE(pipeline.problem().find("joint_states: stamp 0"), std::string::npos)
      << pipeline.problem();
  EXPECT_EQ(pipeline.onWrench(0, kStart + 6 * kMs, kStart + 6 * kMs, "tool0", f, m),
            Outcome::kUsed);
  EXPECT_EQ(pipeline.onWrench(0, 0, kStart + 7 * kMs, "tool0", f, m), Outcome::kRogueStamp);
  EXPECT_NE(pipeline.problem().find("wrench 'ft': stamp 0"), std::string::npos)
      << pipeline.problem();
  const jle::PipelineCounters& c = pipeline.counters();
  EXPECT_EQ(c.count(InputKind::kJointState, Outcome::kRogueStamp), 1);
  EXPECT_EQ(c.count(InputKind::kWrench, Outcome::kRogueStamp), 1);
}

// Rogue stamps against the clean stream: a UR5 at 500 Hz (default settings) with a
// 2 sin(3t) N m torque at the tool; each message's values are those of its instant t.
struct Message {
  bool wrench = false;
  Stamp stamp = 0, clock = 0;
  double t = 0.0;
};

std::vector<Message> cleanStream(int n, Stamp start, double t0) {
  std::vector<Message> out;
  for (int k = 0; k < n; ++k) {
    const Stamp stamp = start + 2 * k * kMs;
    const double t = t0 + 0.002 * k;
    out.push_back({true, stamp, stamp, t});
    out.push_back({false, stamp, stamp, t});
  }
  return out;
}

struct StreamRun {
  std::map<Stamp, std::vector<double>> effort;  // by the record's stamp
  jle::PipelineCounters counters;
};

StreamRun feedStream(const std::vector<Message>& messages) {
  const jle::Model<double> model = ur5();
  jle::Settings settings;
  addWrenchInput(settings, "tool0");
  jle::Pipeline pipeline(model, settings, nullptr);
  StreamRun out;
  std::vector<double> p(6);
  for (const Message& msg : messages) {
    if (msg.wrench) {
      const Eigen::Vector3d f(1.0, -2.0, 0.5), m(0.0, 0.0, 2.0 * std::sin(3.0 * msg.t));
      pipeline.onWrench(0, msg.stamp, msg.clock, "tool0", f, m);
      continue;
    }
    for (int i = 0; i < 6; ++i)
      p[static_cast<std::size_t>(i)] = q(i, msg.t) + 0.1 * std::sin(msg.t);
    if (pipeline.onJointState(msg.stamp, msg.clock, model.coordinate_names, p, kNone, kNone) ==
        Outcome::kPublished)
      out.effort[pipeline.record().stamp] = pipeline.record().effort;
  }
  out.counters = pipeline.counters();
  return out;
}

// The loads at every stamp both runs have are the same (1e-12 N m); returns how many.
long expectSameLoads(const StreamRun& a, const StreamRun& b) {
  long common = 0;
  for (const auto& kv : a.effort) {
    const auto it = b.effort.find(kv.first);
    if (it == b.effort.end()) continue;
    ++common;
    for (std::size_t i = 0; i < kv.second.size(); ++i)
      EXPECT_NEAR(kv.second[i], it->second[i], 1e-12) << "stamp " << kv.first << " joint " << i;
  }
  return common;
}

constexpr Stamp kTwoHours = Stamp{7200} * 1000000000;

TEST(Pipeline, ASingleRogueStampIsDroppedAndCounted) {
  const std::vector<Message> clean = cleanStream(400, kStart, 0.0);
  const StreamRun reference = feedStream(clean);
  ASSERT_GT(reference.effort.size(), 390u);
  struct Case {
    const char* name;
    bool wrench;
    Stamp offset;
  };
  for (const Case& c :
       {Case{"joint state 2 h back", false, -kTwoHours},
        Case{"joint state 2 h forward", false, kTwoHours},
        Case{"wrench 2 h ahead", true, kTwoHours}, Case{"wrench 2 h back", true, -kTwoHours}}) {
    SCOPED_TRACE(c.name);
    std::vector<Message> hostile = clean;
    const Message& at = clean[2 * 200 + 1];  // the 200th joint state
    hostile.insert(hostile.begin() + 2 * 200 + 2,
                   {c.wrench, at.stamp + c.offset, at.clock + kMs, at.t + 0.001});
    const StreamRun r = feedStream(hostile);
    EXPECT_EQ(expectSameLoads(r, reference), static_cast<long>(reference.effort.size()));
    EXPECT_EQ(r.effort.size(), reference.effort.size());
    const InputKind kind = c.wrench ? InputKind::kWrench : InputKind::kJointState;
    EXPECT_EQ(r.counters.count(kind, Outcome::kRogueStamp), 1);
    EXPECT_EQ(r.counters.count(Outcome::kRogueStamp), 1);
    EXPECT_EQ(r.counters.resets, 0);
    // Every later good reading of that input is used again.
    EXPECT_EQ(r.counters.count(InputKind::kWrench, Outcome::kUsed),
              reference.counters.count(InputKind::kWrench, Outcome::kUsed));
    EXPECT_EQ(r.counters.count(InputKind::kJointState, Outcome::kPublished),
              reference.counters.count(InputKind::kJointState, Outcome::kPublished));
  }
}

TEST(Pipeline, AConfirmedJumpResetsAsAFreshStartWould) {
  // 1 s, then the stamps go back by 10 s and run on, the clock going on (a driver's
  // clock set back).
  std::vector<Message> stream = cleanStream(500, kStart, 0.0);
  std::vector<Message> after = cleanStream(300, kStart - 9000 * kMs, 1.0);
  for (Message& m : after) m.clock += 10000 * kMs;
  stream.insert(stream.end(), after.begin(), after.end());
  const StreamRun jumped = feedStream(stream);
  // A fresh start from the confirming joint state (the third of the new timeline): the
  // two before it and the three wrenches until it were rogue stamps.
  const StreamRun fresh = feedStream(std::vector<Message>(after.begin() + 5, after.end()));
  EXPECT_EQ(expectSameLoads(jumped, fresh), static_cast<long>(fresh.effort.size()));
  EXPECT_EQ(jumped.counters.resets, 1);
  EXPECT_EQ(jumped.counters.count(InputKind::kJointState, Outcome::kRogueStamp), 2);
  EXPECT_EQ(jumped.counters.count(InputKind::kWrench, Outcome::kRogueStamp), 3);
  // After the jump, only loads of the new timeline (all before kStart), as many as fresh.
  long after_jump = 0;
  for (const auto& kv : jumped.effort) after_jump += kv.first < kStart;
  EXPECT_EQ(after_jump, static_cast<long>(fresh.effort.size()));
  EXPECT_GT(after_jump, 280);
}

TEST(Pipeline, ALoopingBagWithItsClockResetsAtOnce) {
  // rosbag play -l under use_sim_time: the clock goes back with the stamps.
  std::vector<Message> stream = cleanStream(500, kStart, 0.0);
  const std::vector<Message> loop = cleanStream(300, kStart, 0.0);
  stream.insert(stream.end(), loop.begin(), loop.end());
  const StreamRun looped = feedStream(stream);
  const StreamRun fresh = feedStream(loop);
  EXPECT_EQ(expectSameLoads(looped, fresh), static_cast<long>(fresh.effort.size()));
  EXPECT_EQ(looped.counters.resets, 1);
  EXPECT_EQ(looped.counters.count(Outcome::kRogueStamp), 0);
}

TEST(Pipeline, MalformedMessagesAreCountedAndNamed) {
  const jle::Model<double> model = ur5();
  jle::Settings settings = finiteDifferences();
  addWrenchInput(settings, "tool0");
  jle::Pipeline pipeline(model, settings, nullptr);
  const std::vector<std::string>& names = model.coordinate_names;
  std::vector<double> p(6, 0.0);
  EXPECT_EQ(pipeline.onJointState(kStart, 0, names, std::vector<double>(5), kNone, kNone),
            Outcome::kInvalid);
  EXPECT_EQ(pipeline.onJointState(kStart, 0, names, p, std::vector<double>(2), kNone),
            Outcome::kInvalid);
  p[2] = std::nan("");
  EXPECT_EQ(pipeline.onJointState(kStart, 0, names, p, kNone, kNone), Outcome::kInvalid);
  EXPECT_NE(pipeline.problem().find("'" + names[2] + "'"), std::string::npos) << pipeline.problem();
  p[2] = 0.0;
  std::vector<std::string> extra = names;
  extra.push_back("gripper_joint");
  p.push_back(0.0);
  EXPECT_EQ(pipeline.onJointState(kStart, 0, extra, p, kNone, kNone), Outcome::kUsed);
  EXPECT_EQ(pipeline.unknownJoint(), "gripper_joint");
  EXPECT_EQ(pipeline.onWrench(0, kStart, 0, "", Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones()),
            Outcome::kFrame);
  EXPECT_EQ(pipeline.onWrench(0, kStart, 0, "tool0", Eigen::Vector3d::Constant(INFINITY),
                              Eigen::Vector3d::Ones()),
            Outcome::kInvalid);
  const jle::PipelineCounters& c = pipeline.counters();
  EXPECT_EQ(c.count(InputKind::kJointState, Outcome::kInvalid), 3);
  EXPECT_EQ(c.unknown_joints, 1);
  EXPECT_EQ(c.received(InputKind::kWrench), 2);
  // Stamp 0 on a stream that has had stamps: dropped (docs/node.md, "Time stamps").
  EXPECT_EQ(pipeline.onJointState(0, kStart, names, std::vector<double>(6), kNone, kNone),
            Outcome::kRogueStamp);
}

}  // namespace

namespace {

// Issue 14, item 1: every hostile joint state is used or counted under its reason, and
// the loads of the good messages are exactly those of the good messages alone.
TEST(Pipeline, HostileJointStatesAreCountedAndChangeNoLoads) {
  const jle::Model<double> model = ur5();
  jle::Settings settings = finiteDifferences();
  jle::Pipeline clean(model, settings, nullptr), hostile(model, settings, nullptr);
  const std::vector<std::string>& names = model.coordinate_names;
  std::vector<std::string> twice = names;
  twice.push_back(names[1]);  // shoulder_lift twice, the second 0.5 rad off
  const std::vector<std::string> gripper = {"gripper_finger_joint"};
  std::vector<double> p(6), pe(6, 1.0), p_twice, one = {0.3};
  int compared = 0;
  for (int k = 0; k < 60; ++k) {
    const Stamp stamp = kStart + k * kMs;
    const double t = k * 1e-3;
    for (int i = 0; i < 6; ++i) p[i] = q(i, t);
    // Before the good message of this stamp: a duplicate, an empty one, a gripper's.
    p_twice = p;
    p_twice.push_back(p[1] + 0.5);
    EXPECT_EQ(hostile.onJointState(stamp, stamp, twice, p_twice, kNone, kNone), Outcome::kInvalid);
    EXPECT_NE(hostile.problem().find("'" + names[1] + "' is named twice"), std::string::npos)
        << hostile.problem();
    EXPECT_EQ(hostile.onJointState(stamp - kMs / 2, stamp, {}, kNone, kNone, kNone),
              Outcome::kNoJoint);
    EXPECT_EQ(hostile.onJointState(stamp - kMs / 3, stamp, gripper, one, kNone, one),
              Outcome::kNoJoint);
    // The good one; every 7th with a NaN effort on joint 2 (the loads still computed).
    std::vector<double> effort = pe;
    if (k % 7 == 3) effort[2] = std::nan("");
    const Outcome a = clean.onJointState(stamp, stamp, names, p, kNone, pe);
    const Outcome b = hostile.onJointState(stamp, stamp, names, p, kNone, effort);
    ASSERT_EQ(a, b) << k;
    EXPECT_EQ(hostile.nonFiniteEffort(), k % 7 == 3 ? names[2] : "");
    if (b != Outcome::kPublished) continue;
    const jle::LoadsRecord &rc = clean.record(), &rh = hostile.record();
    ASSERT_EQ(rc.stamp, rh.stamp);
    for (std::size_t i = 0; i < rc.segment.size(); ++i) {
      // The same samples in the same order: bit-identical.
      EXPECT_EQ(rc.force[i], rh.force[i]);
      EXPECT_EQ(rc.moment[i], rh.moment[i]);
      EXPECT_EQ(rc.effort[i], rh.effort[i]);
    }
    // The record describes the middle sample (finite differences, window 3): the NaN
    // effort drops that sample's comparison for joint 2 only.
    const bool nan_sample = (rh.stamp - kStart) / kMs % 7 == 3;
    EXPECT_EQ(std::isnan(rh.measured_effort[2]), nan_sample);
    EXPECT_EQ(rh.measured_effort[1], 1.0);
    compared += nan_sample;
  }
  EXPECT_GT(compared, 0);
  const jle::PipelineCounters& c = hostile.counters();
  EXPECT_EQ(c.count(InputKind::kJointState, Outcome::kInvalid), 60);
  EXPECT_EQ(c.count(InputKind::kJointState, Outcome::kNoJoint), 120);
  EXPECT_EQ(c.nonfinite_efforts, 9);  // k = 3, 10, ..., 59
  EXPECT_EQ(c.resets, 0);
  EXPECT_EQ(c.count(InputKind::kJointState, Outcome::kPublished),
            clean.counters().count(InputKind::kJointState, Outcome::kPublished));
}

TEST(Pipeline, ProblemKeysKeepTheDigitsOfNames) {
  // Numbers do not make another problem; a name's digits do ('/ft2' is not '/ft').
  EXPECT_EQ(jle::problemKey("stamp 1700000000.123 (previous 1700000000.124)"),
            jle::problemKey("stamp 1700000001.5 (previous 1700000001.6)"));
  EXPECT_NE(jle::problemKey("stale inputs (stale_policy stop): /ft2: not publishing"),
            jle::problemKey("stale inputs (stale_policy stop): /ft: not publishing"));
  EXPECT_NE(jle::problemKey("joint 'wrist_1_joint'"), jle::problemKey("joint 'wrist_2_joint'"));
}

TEST(Pipeline, StaleStopNamesTheStoppingInputOnly) {
  const jle::Model<double> model = ur5();
  jle::Settings settings = finiteDifferences();
  addWrenchInput(settings, "tool0");
  addWrenchInput(settings, "tool0");
  settings.wrenches[0].topic = "/ft";
  settings.wrenches[1].topic = "/ft2";
  settings.estimator.wrenches[1].stale_policy = jle::StalePolicy::kStop;
  jle::Pipeline pipeline(model, settings, nullptr);
  EXPECT_EQ(pipeline.missingJoint(), model.coordinate_names[0]);
  const std::vector<double> p(6, 0.1);
  Outcome last = Outcome::kUsed;
  for (int k = 0; k < 5; ++k)  // neither input has spoken: both stale, only /ft2 stops
    last = pipeline.onJointState(kStart + k * kMs, 0, model.coordinate_names, p, kNone, kNone);
  EXPECT_EQ(last, Outcome::kStale);
  EXPECT_EQ(pipeline.missingJoint(), "");
  EXPECT_EQ(pipeline.stoppingInputs(), "/ft2");
  EXPECT_NE(pipeline.problem().find(": /ft2: not publishing"), std::string::npos)
      << pipeline.problem();
}

}  // namespace

// The Kalman smoother (differentiator/lag): each joint state's loads once, with its own
// stamp and measured effort, in order: during the stream with a delay of lag = 0.2 s
// (200 samples at 1 kHz: beyond the ring the pipeline starts with), across a gap beyond
// max_gap (the 150 samples before it published at the first one after it, all due:
// takeDrained()), and at the end (flush()).
namespace {

void expectEveryJointStateOnce(jle::DifferentiatorType type) {
  const jle::Model<double> model = ur5();
  jle::Settings settings;
  settings.estimator.differentiator.type = type;
  settings.estimator.differentiator.lag = 0.2;
  jle::Pipeline pipeline(model, settings, nullptr);
  std::vector<Stamp> sent, published;
  std::vector<double> measured;
  const auto take = [&]() {
    published.push_back(pipeline.record().stamp);
    measured.push_back(pipeline.record().measured_effort[0]);
  };
  for (int k = 0; k < 400; ++k) {
    // A 0.8 s gap after 150 samples (max_gap: 0.5 s).
    const Stamp stamp = kStart + k * kMs + (k >= 150 ? 800 * kMs : 0);
    const double t = 1e-3 * k;
    std::vector<double> p(6), e(6, 0.0);
    for (int i = 0; i < 6; ++i) p[static_cast<std::size_t>(i)] = q(i, t);
    e[0] = k;  // the sample's own number, to pair it with its loads
    sent.push_back(stamp);
    if (pipeline.onJointState(stamp, stamp, model.coordinate_names, p, kNone, e) ==
        Outcome::kPublished)
      take();
    const std::size_t before = published.size();
    while (pipeline.takeDrained()) take();
    // The gap's carry at once, at the first sample after it.
    EXPECT_EQ(published.size() - before, k == 150 ? 149u : 0u) << k;
  }
  EXPECT_EQ(pipeline.delaySamples(), 200);
  EXPECT_EQ(pipeline.pendingSamples(), 200);
  while (pipeline.flush()) take();
  EXPECT_EQ(pipeline.pendingSamples(), 0);
  EXPECT_EQ(published, sent);
  for (std::size_t k = 0; k < measured.size(); ++k) EXPECT_EQ(measured[k], static_cast<double>(k));
}

}  // namespace

TEST(Pipeline, SmootherPublishesEveryJointStateOnceAcrossAGapAndAtTheEnd) {
  expectEveryJointStateOnce(jle::DifferentiatorType::kKalman);
}

// The adaptive smoother (type adaptive with a lag) through the same path.
TEST(Pipeline, AdaptiveSmootherPublishesEveryJointStateOnceAcrossAGapAndAtTheEnd) {
  expectEveryJointStateOnce(jle::DifferentiatorType::kAdaptive);
}

// differentiator/lag in seconds through the message path: a 1 kHz stream whose first
// interval is 1.75 ms (it made the delay 114 samples, 0.114 s), then 0.8 to 1.2 ms
// apart, and 200 Hz from its second second (5 ms steps after 1 ms ones: several loads
// due at once, takeDrained()). Each record's stamp is 0.2 s before the newest joint
// state's within 1.4 ms at 1 kHz (the recent interval plus the intervals' spread,
// 0.4 ms, as test_smoother) and where the rate drops within the 5 ms step (a sample made
// overdue by it was not due at the sample before: measured 4.4 ms); every joint state
// once.
TEST(Pipeline, SmootherDelayIsTheLagInSeconds) {
  const jle::Model<double> model = ur5();
  jle::Settings settings;
  settings.estimator.differentiator.lag = 0.2;
  jle::Pipeline pipeline(model, settings, nullptr);
  jle::PortableRandom random(5);
  std::vector<Stamp> sent, published;
  double worst_1khz = 0.0, worst = 0.0;
  Stamp stamp = kStart;
  for (int k = 0; k < 1500; ++k) {
    const Stamp step = k < 1000 ? static_cast<Stamp>(random.uniform(0.8, 1.2) * kMs) : 5 * kMs;
    stamp += k == 0 ? 0 : (k == 1 ? 1750000 : step);
    // Within the UR5's limits for its 3.5 s (q() takes shoulder_pan beyond 2 pi at 2.7 s).
    std::vector<double> p(6);
    for (int i = 0; i < 6; ++i)
      p[static_cast<std::size_t>(i)] =
          0.5 * std::sin(1e-9 * static_cast<double>(stamp - kStart) + i);
    sent.push_back(stamp);
    const auto take = [&]() {
      published.push_back(pipeline.record().stamp);
      const double error = std::abs(1e-9 * static_cast<double>(stamp - published.back()) - 0.2);
      worst = std::max(worst, error);
      if (k < 1000) worst_1khz = std::max(worst_1khz, error);
    };
    if (pipeline.onJointState(stamp, stamp, model.coordinate_names, p, kNone, kNone) ==
        Outcome::kPublished)
      take();
    while (pipeline.takeDrained()) take();
  }
  EXPECT_LE(worst_1khz, 1.4e-3);
  EXPECT_LE(worst, 5e-3);
  while (pipeline.flush()) published.push_back(pipeline.record().stamp);
  EXPECT_EQ(published, sent);
}

namespace {

// One loads record as the test compares them: stamp, measured effort, every effort.
struct Taken {
  Stamp stamp;
  double measured;
  std::vector<double> effort;
};

Taken taken(const jle::Pipeline& pipeline) {
  const jle::LoadsRecord& r = pipeline.record();
  return {r.stamp, r.measured_effort[0], r.effort};
}

// Joint state k of a 1 kHz stream starting at `start`, its number as joint 0's effort.
Outcome feedNumbered(jle::Pipeline& pipeline, const jle::Model<double>& model, Stamp start, int k) {
  const Stamp stamp = start + k * kMs;
  const double t = 1e-3 * k;
  std::vector<double> p(6), e(6, 0.0);
  for (int i = 0; i < 6; ++i) p[static_cast<std::size_t>(i)] = q(i, t);
  e[0] = k;
  return pipeline.onJointState(stamp, stamp, model.coordinate_names, p, kNone, e);
}

}  // namespace

// The smoother's pending joint states when time jumps back (a looping bag) or the filter
// is replaced (retune): their loads come out of takeDrained(), oldest first, equal to
// those the end of the stream (flush()) would have given; then the new timeline's own,
// every one once. Nothing is lost and nothing is counted twice.
TEST(Pipeline, SmootherDrainsItsPendingSamplesOnAJumpBackAndOnRetune) {
  const jle::Model<double> model = ur5();
  jle::Settings settings;
  settings.estimator.differentiator.lag = 0.1;  // D = 100 samples at 1 kHz
  constexpr int kFirst = 300;
  // The reference: the first timeline alone, ended by flush().
  std::vector<Taken> ended;
  {
    jle::Pipeline pipeline(model, settings, nullptr);
    for (int k = 0; k < kFirst; ++k) feedNumbered(pipeline, model, kStart, k);
    while (pipeline.flush()) ended.push_back(taken(pipeline));
  }
  ASSERT_EQ(ended.size(), 100u);
  const auto expectSame = [&](const std::vector<Taken>& got, const char* what) {
    ASSERT_EQ(got.size(), ended.size()) << what;
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].stamp, ended[i].stamp) << what << " " << i;
      EXPECT_EQ(got[i].measured, static_cast<double>(kFirst - 100 + static_cast<int>(i))) << what;
      EXPECT_EQ(got[i].effort, ended[i].effort) << what << " " << i;
    }
  };

  // A jump back: the first timeline again from its start (stamps and clock go back).
  jle::Pipeline pipeline(model, settings, nullptr);
  std::vector<Stamp> published;
  for (int k = 0; k < kFirst; ++k)
    if (feedNumbered(pipeline, model, kStart, k) == Outcome::kPublished)
      published.push_back(pipeline.record().stamp);
  EXPECT_FALSE(pipeline.takeDrained());
  EXPECT_EQ(published.size(), static_cast<std::size_t>(kFirst - 100));
  EXPECT_NE(feedNumbered(pipeline, model, kStart, 0), Outcome::kPublished);
  EXPECT_EQ(pipeline.counters().resets, 1);
  std::vector<Taken> drained;
  while (pipeline.takeDrained()) drained.push_back(taken(pipeline));
  expectSame(drained, "jump back");
  EXPECT_FALSE(pipeline.takeDrained());
  // The new timeline: each of its joint states once, from the first.
  std::vector<Stamp> second;
  for (int k = 1; k < kFirst; ++k)
    if (feedNumbered(pipeline, model, kStart, k) == Outcome::kPublished)
      second.push_back(pipeline.record().stamp);
  while (pipeline.flush()) second.push_back(pipeline.record().stamp);
  ASSERT_EQ(second.size(), static_cast<std::size_t>(kFirst));
  for (int k = 0; k < kFirst; ++k) EXPECT_EQ(second[static_cast<std::size_t>(k)], kStart + k * kMs);

  // retune to the causal filter: the smoother's pending loads first.
  jle::Pipeline tuned(model, settings, nullptr);
  for (int k = 0; k < kFirst; ++k) feedNumbered(tuned, model, kStart, k);
  jle::DifferentiatorConfig causal = settings.estimator.differentiator;
  causal.lag = 0.0;
  jle::DifferentiatorConfig bad = causal;
  bad.lag = -1.0;
  EXPECT_THROW(tuned.retune(bad, 1), std::invalid_argument);
  EXPECT_FALSE(tuned.takeDrained());  // a refused retune changes nothing
  EXPECT_EQ(tuned.pendingSamples(), 100);
  EXPECT_FALSE(tuned.retune(causal, 1));
  drained.clear();
  while (tuned.takeDrained()) drained.push_back(taken(tuned));
  expectSame(drained, "retune");
  EXPECT_EQ(tuned.pendingSamples(), 0);
}

// A drained record (a smoother's loads still to come when time jumps back) carries the
// side outputs of its own sample: the sensor's residual, the base residual, the
// coordinates, the inputs' staleness, equal to those the same samples give when the
// stream ends (flush()), and different from one sample to the next (the sensor's reading
// and the motion change at every sample), so that outputs of another sample would show.
TEST(Pipeline, DrainedRecordsCarryTheSideOutputsOfTheirOwnSample) {
  jle::ModelOptions options;
  options.floating_base = true;
  options.keep_fixed_joints = {"wrist_3_link-tool0_fixed_joint"};
  const jle::Model<double> model =
      jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf", options);
  jle::Settings settings;
  settings.floating_base = true;
  settings.estimator.differentiator.lag = 0.05;  // 50 samples at 1 kHz
  addWrenchInput(settings, "");
  settings.estimator.wrenches[0].sensor_joint = "wrist_3_link-tool0_fixed_joint";
  FixedFrames frames;
  frames.poses[{"world", model.link_name[0]}] = Eigen::Isometry3d::Identity();
  constexpr int kFirst = 200;
  const auto feed = [&](jle::Pipeline& p, int k) {
    const Stamp stamp = kStart + k * kMs;
    const double t = 1e-3 * k;
    p.onWrench(0, stamp, stamp, "tool0", Eigen::Vector3d(1.0 + t, -2.0, 30.0 * t),
               Eigen::Vector3d(0.1, 0.2 * t, -0.3));
    std::vector<double> position(6);
    for (int i = 0; i < 6; ++i) position[static_cast<std::size_t>(i)] = q(i, t);
    return p.onJointState(stamp, stamp, model.coordinate_names, position, kNone, kNone);
  };
  std::vector<jle::LoadsRecord> ended;
  {
    jle::Pipeline reference(model, settings, &frames);
    for (int k = 0; k < kFirst; ++k) feed(reference, k);
    while (reference.flush()) ended.push_back(reference.record());
  }
  // 50 pending in the smoother, and the newest, held for the wrench input to be read
  // around its stamp (Estimator::holdsSamples).
  ASSERT_EQ(ended.size(), 51u);
  jle::Pipeline pipeline(model, settings, &frames);
  for (int k = 0; k < kFirst; ++k) feed(pipeline, k);
  feed(pipeline, 0);  // time jumps back
  ASSERT_EQ(pipeline.counters().resets, 1);
  std::size_t i = 0;
  for (; pipeline.takeDrained(); ++i) {
    ASSERT_LT(i, ended.size());
    const jle::LoadsRecord& got = pipeline.record();
    const jle::LoadsRecord& want = ended[i];
    EXPECT_EQ(got.stamp, want.stamp) << i;
    EXPECT_EQ(got.effort, want.effort) << i;
    EXPECT_EQ(got.q, want.q) << i;
    EXPECT_EQ(got.qd, want.qd) << i;
    EXPECT_EQ(got.qdd, want.qdd) << i;
    EXPECT_EQ(got.base_force, want.base_force) << i;
    EXPECT_EQ(got.base_moment, want.base_moment) << i;
    ASSERT_EQ(got.inputs.size(), 1u);
    EXPECT_TRUE(got.inputs[0].used);
    EXPECT_FALSE(got.inputs[0].stale);
    EXPECT_EQ(got.inputs[0].residual.force, want.inputs[0].residual.force) << i;
    EXPECT_EQ(got.inputs[0].residual.moment, want.inputs[0].residual.moment) << i;
    EXPECT_EQ(got.inputs[0].frame, "tool0");
    if (i == 0) continue;
    // The sample's own: the previous record's differ.
    EXPECT_GT((got.inputs[0].residual.force - ended[i - 1].inputs[0].residual.force).norm(), 1e-3)
        << i;
    EXPECT_GT((got.base_force - ended[i - 1].base_force).norm(), 1e-6) << i;
  }
  EXPECT_EQ(i, ended.size());
}
