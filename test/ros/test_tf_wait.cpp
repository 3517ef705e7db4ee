// Tf2FrameSource's wait for a late transform (the node's tf_wait): a transform that
// another thread (the node's listener) inserts after the lookup started is waited for;
// one that never comes costs one wait, not one per message; so does a frame nothing has
// published yet (a latched /tf_static on its way); a stamp far past tf2's newest and a
// static chain are never waited for. A tf2::BufferCore filled by a thread of the
// test stands for the listener (no master).
#include <joint_load_estimator/ros/conversions.hpp>

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <tf2/buffer_core.h>

#include <chrono>
#include <string>
#include <thread>

namespace {

using jle::Stamp;

constexpr Stamp kSecond = 1000000000;
constexpr Stamp kStart = 1000 * kSecond;
constexpr Stamp kPeriod = 5000000;  // 200 Hz

geometry_msgs::TransformStamped pose(Stamp stamp, double x, const std::string& parent = "world",
                                     const std::string& child = "pelvis") {
  geometry_msgs::TransformStamped t;
  t.header.stamp = jle::toRosTime(stamp);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = x;
  t.transform.rotation.w = 1.0;
  return t;
}

class TfWait : public testing::Test {
 protected:
  TfWait() : frames_(buffer_) {
    for (int k = 0; k < 10; ++k) add(kStart + k * kPeriod, 0.01 * k);
  }
  void add(Stamp stamp, double x) { buffer_.setTransform(pose(stamp, x), "test"); }
  bool lookup(Stamp stamp, double& x) {
    Eigen::Isometry3d X;
    std::string error;
    const bool ok = frames_.lookup("world", "pelvis", stamp, X, error);
    x = X.translation().x();
    return ok;
  }
  // The pose of `stamp` inserted by another thread `after` of wall time.
  std::thread later(Stamp stamp, double x, std::chrono::milliseconds after) {
    return std::thread([this, stamp, x, after] {
      std::this_thread::sleep_for(after);
      add(stamp, x);
    });
  }

  tf2::BufferCore buffer_;
  jle::Tf2FrameSource frames_;
};

TEST_F(TfWait, ALateTransformIsWaitedFor) {
  frames_.setWait(2.0);  // far more than the thread's delay, even on a loaded machine
  const Stamp next = kStart + 10 * kPeriod;
  std::thread feeder = later(next, 0.1, std::chrono::milliseconds(20));
  double x = 0.0;
  EXPECT_TRUE(lookup(next, x));
  feeder.join();
  EXPECT_DOUBLE_EQ(x, 0.1);  // the new pose, not an extrapolation
  EXPECT_EQ(frames_.waits(), 1);
  EXPECT_EQ(frames_.waitsRunOut(), 0);
  EXPECT_GE(frames_.longestWait(), 0.019);
  // A known stamp: no wait.
  EXPECT_TRUE(lookup(kStart + 5 * kPeriod, x));
  EXPECT_DOUBLE_EQ(x, 0.05);
  EXPECT_EQ(frames_.waits(), 1);
}

TEST_F(TfWait, WithoutAWaitALateTransformIsAMiss) {
  const Stamp next = kStart + 10 * kPeriod;  // no setWait: 0
  std::thread feeder = later(next, 0.1, std::chrono::milliseconds(20));
  double x = 0.0;
  EXPECT_FALSE(lookup(next, x));
  feeder.join();
  EXPECT_EQ(frames_.waits(), 0);
  EXPECT_TRUE(lookup(next, x));  // once it has come
}

TEST_F(TfWait, AStoppedStreamCostsOneWait) {
  frames_.setWait(0.03);
  double x = 0.0;
  const Stamp last = kStart + 9 * kPeriod;
  EXPECT_FALSE(lookup(last + kPeriod, x));
  EXPECT_EQ(frames_.waits(), 1);
  EXPECT_EQ(frames_.waitsRunOut(), 1);
  EXPECT_GE(frames_.longestWait(), 0.029);
  // The next stamps, still within the wait of the newest pose: a miss at once.
  frames_.clearLongestWait();
  EXPECT_FALSE(lookup(last + 2 * kPeriod, x));
  EXPECT_FALSE(lookup(last + 3 * kPeriod, x));
  EXPECT_EQ(frames_.waits(), 1);
  EXPECT_EQ(frames_.longestWait(), 0.0);
  // The stream moves on: a late pose is waited for again.
  add(last + 4 * kPeriod, 0.13);
  frames_.setWait(2.0);
  std::thread feeder = later(last + 5 * kPeriod, 0.14, std::chrono::milliseconds(10));
  EXPECT_TRUE(lookup(last + 5 * kPeriod, x));
  feeder.join();
  EXPECT_DOUBLE_EQ(x, 0.14);
  EXPECT_EQ(frames_.waits(), 2);
  EXPECT_EQ(frames_.waitsRunOut(), 1);
}

TEST_F(TfWait, AStampFarPastTheNewestIsNotWaitedFor) {
  frames_.setWait(0.03);
  double x = 0.0;
  EXPECT_FALSE(lookup(kStart + 9 * kPeriod + 7 * kPeriod, x));  // 35 ms past the newest
  EXPECT_EQ(frames_.waits(), 0);
  // Nor one before what tf2 holds, nor stamp 0 (the latest).
  EXPECT_FALSE(lookup(kStart - kSecond, x));
  EXPECT_TRUE(lookup(0, x));
  EXPECT_DOUBLE_EQ(x, 0.09);
  EXPECT_EQ(frames_.waits(), 0);
}

TEST_F(TfWait, AStaticChainIsNotWaitedFor) {
  frames_.setWait(0.03);
  buffer_.setTransform(pose(0, 2.0, "world", "plate"), "test", true);
  Eigen::Isometry3d X;
  std::string error;
  EXPECT_TRUE(frames_.lookup("world", "plate", kStart + kSecond, X, error));
  EXPECT_DOUBLE_EQ(X.translation().x(), 2.0);
  EXPECT_TRUE(frames_.lookup("world", "plate", 0, X, error));
  EXPECT_EQ(frames_.waits(), 0);
}

TEST_F(TfWait, AFrameNotYetPublishedIsWaitedForOnce) {
  // A latched static transform the listener delivers after the first message needs it.
  frames_.setWait(2.0);
  std::thread feeder([this] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    buffer_.setTransform(pose(0, 2.0, "world", "plate"), "test", true);
  });
  Eigen::Isometry3d X;
  std::string error;
  EXPECT_TRUE(frames_.lookup("world", "plate", 0, X, error)) << error;
  feeder.join();
  EXPECT_DOUBLE_EQ(X.translation().x(), 2.0);
  EXPECT_EQ(frames_.waits(), 1);
  EXPECT_EQ(frames_.waitsRunOut(), 0);
  // One that never comes: one wait, then a miss at once, naming the frame.
  frames_.setWait(0.03);
  EXPECT_FALSE(frames_.lookup("world", "nowhere", kStart, X, error));
  EXPECT_NE(error.find("nowhere"), std::string::npos) << error;
  EXPECT_EQ(frames_.waits(), 2);
  EXPECT_EQ(frames_.waitsRunOut(), 1);
  EXPECT_FALSE(frames_.lookup("world", "nowhere", kStart + kPeriod, X, error));
  EXPECT_FALSE(frames_.lookup("nowhere", "world", kStart, X, error));  // another pair
  EXPECT_EQ(frames_.waits(), 3);
  EXPECT_FALSE(frames_.lookup("nowhere", "world", kStart, X, error));
  EXPECT_EQ(frames_.waits(), 3);
}

}  // namespace
