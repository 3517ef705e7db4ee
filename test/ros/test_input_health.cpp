// InputHealth (ros/input_health.hpp): the per-input counts behind the node's
// diagnostics, against counts written out by hand; MasterWatch (ros/master_watch.hpp): a
// lost, returned or restarted ROS master, from the polls the node makes.
#include <joint_load_estimator/ros/input_health.hpp>
#include <joint_load_estimator/ros/master_watch.hpp>

#include <gtest/gtest.h>

namespace {

using jle::InputHealth;
using jle::Outcome;

TEST(InputHealth, SequenceGapsPerPublisherAreLoss) {
  InputHealth h("/joint_states");
  // Two publishers interleaved, each numbering its own messages: no loss.
  for (std::uint32_t s = 1; s <= 5; ++s) {
    h.take("/arm", s, Outcome::kPublished, 1.0);
    h.take("/gripper", 100 + s, Outcome::kNoJoint, 1.0);
  }
  EXPECT_EQ(h.lost(), 0);
  h.take("/arm", 9, Outcome::kPublished, 2.0);  // 6, 7, 8 never came
  EXPECT_EQ(h.lost(), 3);
  h.take("/arm", 1, Outcome::kPublished, 2.5);  // a restarted publisher: no loss
  h.take("/arm", 2, Outcome::kPublished, 3.0);
  h.take("/silent", 0, Outcome::kPublished, 3.0);  // a publisher that does not number
  h.take("/silent", 0, Outcome::kPublished, 3.0);
  EXPECT_EQ(h.lost(), 3);
  EXPECT_EQ(h.received(), 15);
  EXPECT_EQ(h.lastReceived(), 3.0);
}

TEST(InputHealth, PeriodsCountTheirOwnMessages) {
  InputHealth h("ft");
  h.take("/a", 1, Outcome::kUsed, 1.0);
  h.take("/a", 2, Outcome::kFrame, 1.0);
  InputHealth::Period p = h.since();
  EXPECT_EQ(p.received, 2);
  EXPECT_EQ(p.used, 1);
  EXPECT_EQ(p.lost, 0);
  EXPECT_EQ(p.last_drop, Outcome::kFrame);
  h.take("/a", 4, Outcome::kOrder, 2.0);
  h.take("/a", 5, Outcome::kInvalid, 2.0);
  p = h.since();
  EXPECT_EQ(p.received, 2);
  EXPECT_EQ(p.used, 0);  // every reading of the period dropped
  EXPECT_EQ(p.lost, 1);
  EXPECT_EQ(p.last_drop, Outcome::kInvalid);
  p = h.since();
  EXPECT_EQ(p.received, 0);
  // Waiting, stale, unchanged are taken by the pipeline: not drops.
  for (Outcome o : {Outcome::kUsed, Outcome::kPublished, Outcome::kWaiting, Outcome::kStale,
                    Outcome::kUnchanged})
    EXPECT_FALSE(InputHealth::dropped(o));
  for (Outcome o : {Outcome::kInvalid, Outcome::kOrder, Outcome::kFrame, Outcome::kNoBasePose,
                    Outcome::kNoJoint})
    EXPECT_TRUE(InputHealth::dropped(o));
}

// The node polls ros::master::check() and /run_id: a master that stops answering is
// said once; the same one back (its run_id) loses nothing; another one (a restarted
// roscore: a new run_id, even between two polls, or none to compare) is a restart, said
// once.
TEST(MasterWatch, LostBackAndRestarted) {
  using Event = jle::MasterWatch::Event;
  jle::MasterWatch w("run-1");
  EXPECT_EQ(w.update(true, "run-1"), Event::kNone);
  EXPECT_EQ(w.update(false, ""), Event::kLost);
  EXPECT_EQ(w.update(false, ""), Event::kNone);
  EXPECT_EQ(w.update(true, "run-1"), Event::kBack);
  EXPECT_EQ(w.update(true, "run-1"), Event::kNone);
  // Restarted between two polls: a new run_id.
  EXPECT_EQ(w.update(true, "run-2"), Event::kRestarted);
  EXPECT_EQ(w.previousRunId(), "run-1");
  EXPECT_EQ(w.runId(), "run-2");
  EXPECT_EQ(w.update(true, "run-2"), Event::kNone);
  // Down, then up with another run_id, which roscore sets a moment after its master
  // answers: the polls without it decide nothing yet.
  EXPECT_EQ(w.update(false, ""), Event::kLost);
  EXPECT_EQ(w.update(true, ""), Event::kNone);
  EXPECT_EQ(w.update(true, "run-3"), Event::kRestarted);
  EXPECT_EQ(w.previousRunId(), "run-2");
  // Back without any run_id for 3 polls: taken for a restart (unknown run_id).
  EXPECT_EQ(w.update(false, ""), Event::kLost);
  EXPECT_EQ(w.update(true, ""), Event::kNone);
  EXPECT_EQ(w.update(true, ""), Event::kNone);
  EXPECT_EQ(w.update(true, ""), Event::kRestarted);
  EXPECT_EQ(w.runId(), "");
  // A master without /run_id (rosmaster alone): back after a loss is taken for a restart.
  jle::MasterWatch bare("");
  EXPECT_EQ(bare.update(true, ""), Event::kNone);
  EXPECT_EQ(bare.update(false, ""), Event::kLost);
  EXPECT_EQ(bare.update(true, ""), Event::kRestarted);
  // A node started before roscore set /run_id learns it at a poll, and a restart then
  // names both run_ids.
  jle::MasterWatch early("");
  EXPECT_EQ(early.update(true, ""), Event::kNone);
  EXPECT_EQ(early.update(true, "run-1"), Event::kNone);
  EXPECT_EQ(early.runId(), "run-1");
  EXPECT_EQ(early.update(false, ""), Event::kLost);
  EXPECT_EQ(early.update(true, "run-2"), Event::kRestarted);
  EXPECT_EQ(early.previousRunId(), "run-1");
  EXPECT_EQ(early.runId(), "run-2");
}

}  // namespace
