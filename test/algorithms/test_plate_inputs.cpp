// The force plates' unit (plate_inputs.hpp): a static plate under a known foot, the
// contact threshold at the estimate's stamp (filtered above it, raw below it), the stale
// policies and the refused configurations, against numbers worked by hand.
#include <joint_load_estimator/estimation/estimator.hpp>  // PlateInputConfig
#include <joint_load_estimator/estimation/plate_inputs.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace {

using Eigen::Vector3d;

// two_leg_stand.urdf on a fixed base, every angle zero: the left foot's frame is the
// world's translated to the ankle A = (0, 0.1, -0.8).
const std::string kUrdf = std::string(JLE_TEST_DATA) + "/urdf/two_leg_stand.urdf";

// The plate frame is the world's translated to (0, 0, -0.9), its surface at z = 0 of it.
// The foot presses 700 N straight down at the centre of pressure c = (0.05, 0.12, 0)
// (plate frame) with no free moment: about the plate origin the plate reports the moment
// c x f = (-84, 35, 0) N m.
const Vector3d kF(0.0, 0.0, -700.0), kM(-84.0, 35.0, 0.0);
// The reaction on the foot, (0, 0, 700) N at c, (0.05, 0.12, -0.9) in the world; about A:
// (c - A) x F with c - A = (0.05, 0.02, -0.1): (14, -35, 0) N m.
const Vector3d kReaction(0.0, 0.0, 700.0), kReactionMoment(14.0, -35.0, 0.0);
// Rounding: the 3-point weights for samples 1 ms apart sum to 1 within ~1e-12 relative;
// on 700 N and lever arms of 0.1 m, a few 1e-10.
constexpr double kTol = 1e-9;

jle::PlateInputConfig plateConfig(jle::StalePolicy policy = jle::StalePolicy::kZero) {
  jle::PlateInputConfig c;
  c.plate.name = "plate1";
  c.plate.link = "foot_l";
  c.plate.p_world_plate = Vector3d(0.0, 0.0, -0.9);
  c.plate.contact_threshold = 20.0;
  c.timeout = 0.5;
  c.stale_policy = policy;
  return c;
}

// The plates with a 3-point filter bank beside them, fed like the estimator feeds them:
// each plate sample, then the plates resampled at the joint stamp into the bank.
struct Rig {
  explicit Rig(const jle::DifferentiatorConfig& d,
               jle::StalePolicy policy = jle::StalePolicy::kZero)
      : model(jle::modelFromUrdfFile(kUrdf)),
        data(model),
        plates(model, {plateConfig(policy)}, 0),
        bank(d, 6),
        channels(6, 0.0) {
    plates.setNeeded(model, std::vector<char>(static_cast<std::size_t>(model.nsegments()), 1));
  }
  // A plate sample and a joint sample at t; true when the bank has an estimate.
  bool step(double t, const Vector3d& f, const Vector3d& m) {
    plates.add(0, t, f, m);
    plates.resample(t, channels.data());
    return bank.update(t, channels.data());
  }
  // The plates applied to the legs standing still at q = 0, at the bank's stamp.
  void apply() {
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nq);
    jle::forwardKinematics(model, data, zero, zero, zero, Vector3d(0.0, 0.0, -9.80665));
    plates.updateContacts(bank.stamp());
    plates.apply(model, data, bank);
  }

  jle::Model<double> model;
  jle::Data<double> data;
  jle::PlateInputs plates;
  jle::DifferentiatorBank bank;
  std::vector<double> channels;
};

jle::DifferentiatorConfig threePoint() {
  jle::DifferentiatorConfig d;
  d.type = jle::DifferentiatorType::kFiniteDifference;
  return d;
}

TEST(PlateInputs, StaticPlateUnderAKnownFoot) {
  Rig rig(threePoint());
  for (int k = 0; k < 3; ++k) rig.step(1.0 + 1e-3 * k, kF, kM);
  rig.apply();
  const jle::PlateReading& r = rig.plates.reading(0);
  ASSERT_TRUE(r.contact);
  EXPECT_NEAR(r.normal_force, 700.0, kTol);
  EXPECT_NEAR((r.cop_plate - Vector3d(0.05, 0.12, 0.0)).norm(), 0.0, kTol);
  EXPECT_NEAR(r.free_moment, 0.0, kTol);
  // The foot segment's frame is the world's at A: the reaction lands there as computed.
  const int foot = rig.model.segmentOfJoint("ankle_l");
  EXPECT_NEAR((rig.data.f_ext[foot] - kReaction).norm(), 0.0, kTol);
  EXPECT_NEAR((rig.data.n_ext[foot] - kReactionMoment).norm(), 0.0, kTol);
}

// 15 N pressing is below the 20 N threshold: the samples enter the filter as measured,
// and the raw wrench at the stamp acts without a COP: on the foot (-1, 0, 15) N and, about
// A, (-0.3, 0.2, 0) + (O - A) x (-1, 0, 15) with O - A = (0, -0.1, -0.1):
// (-0.3, 0.2, 0) + (-1.5, 0.1, -0.1) = (-1.8, 0.3, -0.1) N m.
TEST(PlateInputs, BelowTheThresholdActsWithoutACop) {
  Rig rig(threePoint());
  const Vector3d light(1.0, 0.0, -15.0), light_moment(0.3, -0.2, 0.0);
  for (int k = 0; k < 3; ++k) rig.step(1.0 + 1e-3 * k, light, light_moment);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(rig.channels[c], light[c]);
    EXPECT_EQ(rig.channels[3 + c], light_moment[c]);
  }
  rig.apply();
  EXPECT_FALSE(rig.plates.reading(0).contact);
  EXPECT_TRUE(rig.plates.reading(0).loaded);
  const int foot = rig.model.segmentOfJoint("ankle_l");
  // Products of 0.1 m and 15 N: 1e-14.
  EXPECT_NEAR((rig.data.f_ext[foot] - Vector3d(-1.0, 0.0, 15.0)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((rig.data.n_ext[foot] - Vector3d(-1.8, 0.3, -0.1)).norm(), 0.0, 1e-14);
}

// A 9-sample causal fit right after lift-off still holds most of the stance in its
// filtered wrench; the raw signal at the stamp is out of contact, so nothing is applied
// and the contact change is reported.
TEST(PlateInputs, ContactIsTakenOnTheRawSignalAtTheStamp) {
  jle::DifferentiatorConfig d;
  d.type = jle::DifferentiatorType::kSavitzkyGolay;
  d.window = 9;
  Rig rig(d);
  for (int k = 0; k < 12; ++k) rig.step(1.0 + 1e-3 * k, kF, kM);
  rig.apply();
  EXPECT_TRUE(rig.plates.reading(0).contact);
  EXPECT_FALSE(rig.plates.updateContacts(rig.bank.stamp()));  // unchanged
  rig.step(1.012, Vector3d::Zero(), Vector3d::Zero());
  EXPECT_LT(jle::filteredWrench(rig.bank, 0).force.z(), -100.0);  // the filter's memory
  EXPECT_TRUE(rig.plates.updateContacts(rig.bank.stamp()));
  rig.apply();
  EXPECT_FALSE(rig.plates.reading(0).contact);
  EXPECT_EQ(rig.data.f_ext[rig.model.segmentOfJoint("ankle_l")], Vector3d::Zero());
}

// Timeout 0.5 s: a joint sample 0.6 s after the last plate sample finds it stale.
TEST(PlateInputs, StalePolicies) {
  for (jle::StalePolicy p :
       {jle::StalePolicy::kHold, jle::StalePolicy::kZero, jle::StalePolicy::kStop}) {
    Rig rig(threePoint(), p);
    rig.step(1.0, kF, kM);
    EXPECT_FALSE(rig.plates.stale(0));
    rig.plates.resample(1.6, rig.channels.data());
    EXPECT_TRUE(rig.plates.stale(0));
    EXPECT_EQ(rig.plates.stopped(), p == jle::StalePolicy::kStop);
    EXPECT_EQ(rig.channels[2], p == jle::StalePolicy::kZero ? 0.0 : kF.z());
  }
}

TEST(PlateInputs, NotNeededIsNeitherReadNorStale) {
  Rig rig(threePoint(), jle::StalePolicy::kStop);
  rig.plates.setNeeded(rig.model,
                       std::vector<char>(static_cast<std::size_t>(rig.model.nsegments()), 0));
  EXPECT_FALSE(rig.plates.needed(0));
  rig.plates.add(0, 1.0, kF, kM);
  rig.plates.resample(5.0, rig.channels.data());
  EXPECT_FALSE(rig.plates.stale(0));
  EXPECT_FALSE(rig.plates.stopped());
  for (double c : rig.channels) EXPECT_EQ(c, 0.0);
}

TEST(PlateInputs, DropsSamplesNotNewerOrNotFinite) {
  Rig rig(threePoint());
  EXPECT_TRUE(rig.plates.add(0, 1.0, kF, kM));
  EXPECT_FALSE(rig.plates.add(0, 1.0, kF, kM));
  EXPECT_FALSE(rig.plates.add(0, 2.0, Vector3d(0.0, std::nan(""), -700.0), kM));
}

// The plate moved by (0, 0.1, 0) more: the COP in the world moves with it, the lever arm
// about A gains 0.1 along y, and the moment 0.1 * 700 about x.
TEST(PlateInputs, PoseMovesTheReaction) {
  Rig rig(threePoint());
  rig.plates.setPose(0, Eigen::Matrix3d::Identity(), Vector3d(0.0, 0.1, -0.9));
  for (int k = 0; k < 3; ++k) rig.step(1.0 + 1e-3 * k, kF, kM);
  rig.apply();
  const int foot = rig.model.segmentOfJoint("ankle_l");
  EXPECT_NEAR((rig.data.n_ext[foot] - (kReactionMoment + Vector3d(70.0, 0.0, 0.0))).norm(), 0.0,
              kTol);
}

TEST(PlateInputs, RefusedConfigurationsNameThePlate) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kUrdf);
  auto message = [&](const jle::PlateInputConfig& c) {
    try {
      jle::PlateInputs plates(model, {c}, 0);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  // The model-free checks are the configuration's one validate(), which the Estimator
  // runs before it builds its plates.
  auto validated = [](const jle::PlateInputConfig& c) {
    jle::EstimatorConfig config;
    config.plates = {c};
    try {
      jle::validate(config);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  jle::PlateInputConfig c = plateConfig();
  c.plate.link = "hand";
  EXPECT_NE(message(c).find("force plate 'plate1'"), std::string::npos) << message(c);
  c = plateConfig();
  c.timeout = 0.0;
  EXPECT_NE(validated(c).find("force_plates[0]/timeout"), std::string::npos) << validated(c);
  c = plateConfig();
  c.plate.contact_threshold = -1.0;
  EXPECT_NE(validated(c).find("force_plates[0]/contact_threshold"), std::string::npos)
      << validated(c);
  EXPECT_EQ(validated(plateConfig()), "accepted");
  c = plateConfig();
  c.plate.R_world_plate(0, 0) = 2.0;
  EXPECT_NE(message(c).find("the pose is not a finite rotation"), std::string::npos);
  EXPECT_EQ(message(plateConfig()), "accepted");
}

}  // namespace
