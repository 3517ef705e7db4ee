// The message path's frame resolver (frame_resolver.hpp): a reading's frame from the URDF
// where it rides on the link (the UR5's tool0, its pose typed in from the URDF), from the
// frame source otherwise, looked up as often as it must be and no more; a plate's pose
// found once; the floating base's pose; each failure naming what is missing.
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/frame_resolver.hpp>

#include <gtest/gtest.h>

#include <map>
#include <string>

namespace {

const std::string kData = JLE_TEST_DATA;

// Poses by "target<-frame", counting the look-ups.
class FakeFrames : public jle::FrameSource {
 public:
  bool lookup(const std::string& target, const std::string& frame, jle::Stamp stamp,
              Eigen::Isometry3d& X, std::string& error) override {
    ++lookups;
    last_stamp = stamp;
    const auto it = poses.find(target + "<-" + frame);
    if (it == poses.end()) {
      error = "unknown in the fake";
      return false;
    }
    X = it->second;
    return true;
  }
  std::map<std::string, Eigen::Isometry3d> poses;
  int lookups = 0;
  jle::Stamp last_stamp = -1;
};

Eigen::Isometry3d pose(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& p) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  X.translation() = p;
  return X;
}

struct Ur5 {
  Ur5() : model(jle::modelFromUrdfFile(kData + "/urdf/ur5_robot.urdf")) {
    settings.estimator.wrenches.resize(1);
    settings.estimator.wrenches[0].link = "wrist_3_link";
    settings.wrenches.resize(1);
    settings.wrenches[0].topic = "/wrist/wrench";
    settings.estimator.plates.resize(2);
    settings.estimator.plates[0].plate.name = "plate_1";
    settings.estimator.plates[1].plate.name = "plate_2";
    settings.force_plates.resize(2);
    settings.force_plates[1].pose_configured = true;
    settings.world_frame = "odom";
    settings.base_frame = "pelvis";
  }
  jle::Model<double> model;
  jle::Settings settings;
  FakeFrames frames;
};

TEST(FrameResolver, AFrameOnTheLinksSegmentComesFromTheUrdfOnce) {
  Ur5 r;
  jle::FrameResolver resolver(r.model, r.settings, &r.frames);
  std::string problem;
  for (int message = 0; message < 3; ++message)
    ASSERT_TRUE(resolver.resolveWrench(0, "tool0", 1000 + message, problem)) << problem;
  EXPECT_EQ(r.frames.lookups, 0);
  EXPECT_EQ(resolver.wrenchFrame(0), "tool0");
  // wrist_3_link-tool0_fixed_joint: rpy (-1.57079632679, 0, 0), xyz (0, 0.0823, 0).
  const Eigen::Isometry3d expected =
      pose(-1.57079632679, Eigen::Vector3d::UnitX(), Eigen::Vector3d(0.0, 0.0823, 0.0));
  EXPECT_TRUE(resolver.wrenchPose(0).isApprox(expected, 1e-12));
}

TEST(FrameResolver, AnyOtherFrameIsLookedUpAtEveryMessage) {
  Ur5 r;
  const Eigen::Isometry3d X = pose(0.3, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.1, 0, 0.2));
  r.frames.poses["wrist_3_link<-camera"] = X;
  jle::FrameResolver resolver(r.model, r.settings, &r.frames);
  std::string problem;
  ASSERT_TRUE(resolver.resolveWrench(0, "camera", 5, problem)) << problem;
  ASSERT_TRUE(resolver.resolveWrench(0, "camera", 6, problem)) << problem;
  EXPECT_EQ(r.frames.lookups, 2);  // it may move: asked at each stamp
  EXPECT_EQ(r.frames.last_stamp, 6);
  EXPECT_TRUE(resolver.wrenchPose(0).isApprox(X, 1e-15));
  // Back to the URDF's frame: no look-up, its own pose.
  ASSERT_TRUE(resolver.resolveWrench(0, "tool0", 7, problem)) << problem;
  EXPECT_EQ(r.frames.lookups, 2);
  EXPECT_FALSE(resolver.wrenchPose(0).isApprox(X, 1e-6));
}

TEST(FrameResolver, AnUnknownFrameNamesTheInputFrameAndLink) {
  Ur5 r;
  for (jle::FrameSource* frames :
       {static_cast<jle::FrameSource*>(&r.frames), static_cast<jle::FrameSource*>(nullptr)}) {
    jle::FrameResolver resolver(r.model, r.settings, frames);
    std::string problem;
    EXPECT_FALSE(resolver.resolveWrench(0, "nowhere", 5, problem));
    for (const char* part : {"'/wrist/wrench'", "'nowhere'", "'wrist_3_link'"})
      EXPECT_NE(problem.find(part), std::string::npos) << problem;
    EXPECT_NE(problem.find(frames ? "unknown in the fake" : "no frame source"), std::string::npos)
        << problem;
  }
}

TEST(FrameResolver, APlateIsFoundOnceAndAConfiguredOneNeverLookedUp) {
  Ur5 r;
  const Eigen::Isometry3d X = pose(0.5, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, 2, 0));
  r.frames.poses["world<-plate_frame"] = X;  // the fixed base's world: the URDF's root link
  jle::FrameResolver resolver(r.model, r.settings, &r.frames);
  std::string problem;
  Eigen::Isometry3d found = Eigen::Isometry3d::Identity();
  EXPECT_EQ(resolver.resolvePlate(0, "plate_frame", found, problem),
            jle::FrameResolver::PlatePose::kFound);
  EXPECT_TRUE(found.isApprox(X, 1e-15));
  EXPECT_EQ(r.frames.last_stamp, 0);  // the latest pose: a lab plate is fixed
  EXPECT_EQ(resolver.resolvePlate(0, "plate_frame", found, problem),
            jle::FrameResolver::PlatePose::kKnown);
  EXPECT_EQ(r.frames.lookups, 1);
  EXPECT_EQ(resolver.plateFrame(0), "plate_frame");
  EXPECT_EQ(resolver.resolvePlate(1, "anything", found, problem),
            jle::FrameResolver::PlatePose::kKnown);
  EXPECT_EQ(r.frames.lookups, 1);
  EXPECT_EQ(resolver.resolvePlate(0, "other_plate_frame", found, problem),
            jle::FrameResolver::PlatePose::kUnknown);
  for (const char* part : {"'plate_1'", "'other_plate_frame'", "in 'world'"})
    EXPECT_NE(problem.find(part), std::string::npos) << problem;
}

TEST(FrameResolver, TheFloatingBasesPoseAtTheSamplesStamp) {
  Ur5 r;
  const Eigen::Isometry3d X = pose(-0.2, Eigen::Vector3d::UnitY(), Eigen::Vector3d(0, 0, 0.9));
  jle::FrameResolver resolver(r.model, r.settings, &r.frames);
  std::string problem;
  Eigen::Isometry3d base;
  EXPECT_FALSE(resolver.basePose(42, base, problem));
  for (const char* part : {"'pelvis'", "'odom'", "0.000000042"})
    EXPECT_NE(problem.find(part), std::string::npos) << problem;
  r.frames.poses["odom<-pelvis"] = X;
  ASSERT_TRUE(resolver.basePose(43, base, problem)) << problem;
  EXPECT_EQ(r.frames.last_stamp, 43);
  EXPECT_TRUE(base.isApprox(X, 1e-15));
}

}  // namespace
