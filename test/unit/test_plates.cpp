// Force plates in the core: the decoding (force_plate.hpp) and the estimator's plate
// path (threshold, contact at the estimate's stamp, no stance load smeared on a swinging
// foot), against hand-worked numbers.
#include <joint_load_estimator/estimator.hpp>
#include <joint_load_estimator/force_plate.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

using Eigen::Vector3d;

constexpr double kG = 9.80665;

// The numbers of the sign test (test/rostest/test_plates.cpp has the working): the plate
// frame is the world's translated to O = (0.3, 0.2, -0.04), its surface 0.04 above O. The
// foot presses f = (50, -30, -700) N at the COP c = (-0.15, -0.19, 0.04) (plate frame)
// with a free moment of 2 N m about +z; about O the plate reports (134.2, -103, 16) N m.
const Vector3d kF(50.0, -30.0, -700.0), kM(134.2, -103.0, 16.0);

jle::ForcePlateConfig plate() {
  jle::ForcePlateConfig p;
  p.name = "plate1";
  p.link = "foot";
  p.p_world_plate = Vector3d(0.3, 0.2, -0.04);
  p.surface_height = 0.04;
  p.contact_threshold = 20.0;
  return p;
}

TEST(ForcePlate, DecodesTheCopAndFreeMomentAboutAnOriginBelowTheSurface) {
  const jle::PlateReading r = jle::readForcePlate(plate(), kF, kM);
  ASSERT_TRUE(r.contact);
  // Rounding of one division: 1e-15.
  EXPECT_NEAR(r.normal_force, 700.0, 1e-12);
  EXPECT_NEAR(r.cop_plate.x(), -0.15, 1e-15);
  EXPECT_NEAR(r.cop_plate.y(), -0.19, 1e-15);
  EXPECT_NEAR(r.cop_plate.z(), 0.04, 0.0);
  EXPECT_NEAR(r.free_moment, 2.0, 1e-13);
  // The reaction on the foot: the opposite wrench.
  EXPECT_EQ(r.force_on_foot_plate, -kF);
  EXPECT_EQ(r.moment_on_foot_plate, -kM);

  // Taking the moment as about the surface (h = 0) gives another point: x = -my / fz =
  // 103 / -700, y = mx / fz = 134.2 / -700.
  jle::ForcePlateConfig at_surface = plate();
  at_surface.surface_height = 0.0;
  const jle::PlateReading s = jle::readForcePlate(at_surface, kF, kM);
  EXPECT_NEAR(s.cop_plate.x(), -103.0 / 700.0, 1e-15);
  EXPECT_NEAR(s.cop_plate.y(), -134.2 / 700.0, 1e-15);
  EXPECT_GT(std::abs(s.cop_plate.x() - r.cop_plate.x()), 1e-3);
}

TEST(ForcePlate, ReactionInTheWorldAboutTheFoot) {
  const jle::ForcePlateConfig p = plate();
  const jle::PlateReading r = jle::readForcePlate(p, kF, kM);
  // About the ankle A = (0.1, 0, 0.08): the COP in the world is (0.15, 0.01, 0), c - A =
  // (0.05, 0.01, -0.08), F = (-50, 30, 700): (c - A) x F = (9.4, -31, 2), and the free
  // moment on the foot -2 about z: (9.4, -31, 0).
  Vector3d F, M;
  jle::plateReactionInWorld(p, r, Vector3d(0.1, 0.0, 0.08), F, M);
  EXPECT_NEAR((F - Vector3d(-50.0, 30.0, 700.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((M - Vector3d(9.4, -31.0, 0.0)).norm(), 0.0, 1e-12);
}

TEST(ForcePlate, NoContactBelowTheThresholdPullingOrNotFinite) {
  const jle::ForcePlateConfig p = plate();
  EXPECT_FALSE(jle::readForcePlate(p, Vector3d(1.0, 0.0, -15.0), Vector3d(0.3, -0.2, 0.0)).contact);
  EXPECT_FALSE(jle::readForcePlate(p, Vector3d(0.0, 0.0, 100.0), Vector3d::Zero()).contact);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(jle::readForcePlate(p, Vector3d(0.0, 0.0, nan), Vector3d::Zero()).contact);
  jle::ForcePlateConfig zero = p;
  zero.contact_threshold = 0.0;
  EXPECT_FALSE(jle::readForcePlate(zero, Vector3d::Zero(), Vector3d::Zero()).contact);
  // No contact, no reaction.
  Vector3d F = Vector3d::Ones(), M = Vector3d::Ones();
  jle::plateReactionInWorld(p, jle::PlateReading(), Vector3d::Zero(), F, M);
  EXPECT_EQ(F, Vector3d::Zero());
  EXPECT_EQ(M, Vector3d::Zero());
}

// ---------------------------------------------------------------------------------
// The estimator: a foot at rest on a y ankle at A = (0.1, 0, 0.08), 1 kg at
// G = A + (0.05, 0, -0.05). In contact (the numbers above) the ankle carries
// F_A = (50, -30, -690.19335), M_A = (-9.4, 30.5096675, 0); without contact its weight
// alone: F_A = (0, 0, 9.80665), M_A = (0, -0.4903325, 0).

const char* const kFoot = R"(<?xml version="1.0"?>
<robot name="standing_foot">
  <link name="ground"/>
  <joint name="ankle" type="revolute">
    <parent link="ground"/><child link="foot"/>
    <origin xyz="0.1 0 0.08" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1000" velocity="10"/>
  </joint>
  <link name="foot">
    <inertial>
      <origin xyz="0.05 0 -0.05" rpy="0 0 0"/><mass value="1.0"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.004"/>
    </inertial>
  </link>
</robot>)";

const Vector3d kStanceForce(50.0, -30.0, -690.19335), kStanceMoment(-9.4, 30.5096675, 0.0);
const Vector3d kSwingForce(0.0, 0.0, kG), kSwingMoment(0.0, -0.4903325, 0.0);

jle::EstimatorConfig plateConfig(const jle::DifferentiatorConfig& differentiator) {
  jle::EstimatorConfig c;
  c.differentiator = differentiator;
  jle::PlateInputConfig p;
  p.plate = plate();
  p.timeout = 1.0;
  c.plates.push_back(p);
  return c;
}

// Stance (samples 0..59), swing with 15 N of noise below the threshold (60..119), stance
// again (120..199), 1 kHz, plate and joint samples at the same stamps. After every joint
// sample, the published loads must be the stance numbers when the plate was in contact
// at the estimate's stamp and the swing numbers when it was not, exactly, as soon as
// the filter's window (or the Kalman filter's memory) has seen nothing else.
// Without the contact gate, the filtered plate channels would still carry hundreds of
// newtons for several samples after lift-off (Savitzky-Golay: the window's stance
// samples; Kalman: its decaying state) and the swing loads would be off by as much.
// `stance(j)`: the fraction of the stance wrench that the filter returns at stamp j
// (1 once it has seen nothing else), negative where not checked.
template <typename Stance>
void runStanceSwingStance(const jle::DifferentiatorConfig& differentiator, Stance stance) {
  const jle::Model<double> model = jle::modelFromUrdfString(kFoot);
  jle::Estimator estimator(model, plateConfig(differentiator));
  const int s = model.segmentOfJoint("ankle");
  auto contact = [](int k) { return k < 60 || k >= 120; };
  const double q = 0.0;
  int swing_checked = 0, first_swing_checked = -1, stance_checked = 0;
  for (int k = 0; k < 200; ++k) {
    const double t = 3.0 + 1e-3 * k;
    if (contact(k))
      ASSERT_TRUE(estimator.addPlateSample(0, t, kF, kM));
    else
      ASSERT_TRUE(
          estimator.addPlateSample(0, t, Vector3d(1.0, 0.0, -15.0), Vector3d(0.3, -0.2, 0.0)));
    if (estimator.addJointSample(t, &q) != jle::SampleStatus::kPublished) continue;
    const int j = static_cast<int>(std::lround((estimator.stamp() - 3.0) * 1000.0));
    const jle::PlateReading& r = estimator.plateReading(0);
    const Vector3d& F = estimator.data().force[s];
    const Vector3d& M = estimator.data().moment[s];
    if (!contact(j)) {
      // A swinging foot: exactly its weight from the first stamp after lift-off, although
      // the filters still remember the stance. Rounding only: 1e-12.
      EXPECT_FALSE(r.contact) << "stamp sample " << j;
      EXPECT_NEAR((F - kSwingForce).norm(), 0.0, 1e-12) << "stamp sample " << j;
      EXPECT_NEAR((M - kSwingMoment).norm(), 0.0, 1e-12) << "stamp sample " << j;
      if (first_swing_checked < 0) first_swing_checked = j;
      ++swing_checked;
    } else {
      EXPECT_TRUE(r.contact) << "stamp sample " << j;
      // The filtered plate wrench is the fraction c of the stance wrench (the samples
      // out of contact entered the filter as zero): the foot gets c times the stance
      // reaction, at the same COP. Rounding of the filter's weights: 1e-9 of 700 N.
      const double c = stance(j);
      if (c >= 0.0) {
        const Vector3d F_expected = kSwingForce + c * (kStanceForce - kSwingForce);
        const Vector3d M_expected = kSwingMoment + c * (kStanceMoment - kSwingMoment);
        EXPECT_NEAR((F - F_expected).norm(), 0.0, 1e-9 * 700.0) << "stamp sample " << j;
        EXPECT_NEAR((M - M_expected).norm(), 0.0, 1e-9 * 700.0) << "stamp sample " << j;
        ++stance_checked;
        EXPECT_NEAR(r.cop_plate.x(), -0.15, 1e-12);
        EXPECT_NEAR(r.cop_plate.y(), -0.19, 1e-12);
      }
    }
  }
  EXPECT_EQ(first_swing_checked, 60);  // from the very first stamp after lift-off
  EXPECT_GE(swing_checked, 55);
  // Every published stance stamp was checked: Kalman (4 samples of warm-up, stamp = the
  // newest) 3..59; Savitzky-Golay (9 samples, stamp 4 behind) 4..59 and 120..195.
  EXPECT_EQ(stance_checked, differentiator.type == jle::DifferentiatorType::kKalman ? 57 : 56 + 76);
}

TEST(EstimatorPlates, NoStanceSmearedOnTheSwingFootSavitzkyGolayCentred) {
  jle::DifferentiatorConfig d;
  d.type = jle::DifferentiatorType::kSavitzkyGolay;
  d.window = 9;
  d.order = 2;
  d.delay = 4;  // centred: the window reaches 4 samples past the stamp
  // The value weights of the centred quadratic fit over 9 equally spaced samples (the
  // textbook Savitzky-Golay smoothing coefficients) are (-21, 14, 39, 54, 59, 54, 39,
  // 14, -21) / 231; the stance fraction at j sums those of the window [j - 4, j + 4]'s
  // stance samples: 1 inside a stance, e.g. (59 + 54 + 39 + 14 - 21) / 231 = 145 / 231 at
  // heel strike (j = 120). Had the 15 N of noise entered the filter, the foot would get
  // ~15 N x (-21 + 14 + 39 + 54) / 231 = 5.6 N more there.
  runStanceSwingStance(d, [](int j) {
    const double w[9] = {-21, 14, 39, 54, 59, 54, 39, 14, -21};
    double sum = 0.0;
    for (int i = 0; i < 9; ++i) {
      const int sample = j - 4 + i;
      if (sample < 60 || sample >= 120) sum += w[i];
    }
    return sum / 231.0;
  });
}

TEST(EstimatorPlates, NoStanceSmearedOnTheSwingFootKalman) {
  jle::DifferentiatorConfig d;  // the node's default before the adaptive filter
  d.type = jle::DifferentiatorType::kKalman;
  d.kalman_model = jle::KalmanModel::kConstantJerk;
  d.process_noise = 1e4;
  d.measurement_noise = 1e-4;
  // The filter starts at rest at its first sample: the first stance is exact (a
  // constant). After heel strike it converges in ~30 ms per e-fold: the second stance is
  // not checked (that lag is the filter's, as for the kinematics).
  runStanceSwingStance(d, [](int j) { return j < 60 ? 1.0 : -1.0; });
}

// A plate that goes silent: under the default policy (zero) it is out of contact once
// its newest sample is older than the timeout at the estimate's stamp.
TEST(EstimatorPlates, StalePlateIsOutOfContact) {
  const jle::Model<double> model = jle::modelFromUrdfString(kFoot);
  jle::DifferentiatorConfig d;
  d.type = jle::DifferentiatorType::kFiniteDifference;
  jle::EstimatorConfig config = plateConfig(d);
  config.plates[0].timeout = 0.0055;
  jle::Estimator estimator(model, config);
  const int s = model.segmentOfJoint("ankle");
  const double q = 0.0;
  for (int k = 0; k < 20; ++k) {
    const double t = 1e-3 * k;
    if (k < 10) estimator.addPlateSample(0, t, kF, kM);
    if (estimator.addJointSample(t, &q) != jle::SampleStatus::kPublished) continue;
    // Samples 2..9 fresh; 10..14 held within 5.5 ms; from 15 on stale: zero.
    const bool expect_contact = k < 15;
    EXPECT_EQ(estimator.plateReading(0).contact, expect_contact) << k;
    EXPECT_NEAR(estimator.data().force[s].z(), expect_contact ? -690.19335 : kG, 1e-9) << k;
    EXPECT_EQ(estimator.plateStale(0), k >= 15) << k;
  }
}

// Float arithmetic: the same numbers to float precision (1e-6 of 700 N).
TEST(EstimatorPlates, FloatPrecision) {
  const jle::Model<double> model = jle::modelFromUrdfString(kFoot);
  jle::DifferentiatorConfig d;
  d.type = jle::DifferentiatorType::kFiniteDifference;
  jle::EstimatorConfig config = plateConfig(d);
  config.precision = jle::Precision::kFloat;
  jle::Estimator estimator(model, config);
  const int s = model.segmentOfJoint("ankle");
  const double q = 0.0;
  int published = 0;
  for (int k = 0; k < 5; ++k) {
    estimator.addPlateSample(0, 1e-3 * k, kF, kM);
    if (estimator.addJointSample(1e-3 * k, &q) != jle::SampleStatus::kPublished) continue;
    ++published;
    EXPECT_NEAR((estimator.data().force[s] - kStanceForce).norm(), 0.0, 1e-6 * 700.0);
    EXPECT_NEAR((estimator.data().moment[s] - kStanceMoment).norm(), 0.0, 1e-6 * 700.0);
  }
  EXPECT_EQ(published, 3);
}

// A foot on no computed segment (pruned away) is not needed; a bad link is refused with
// the plate's name.
TEST(EstimatorPlates, ConfigurationErrors) {
  const jle::Model<double> model = jle::modelFromUrdfString(kFoot);
  jle::DifferentiatorConfig d;
  jle::EstimatorConfig config = plateConfig(d);
  config.plates[0].plate.link = "toe";
  try {
    jle::Estimator estimator(model, config);
    ADD_FAILURE() << "an unknown link was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("plate1"), std::string::npos) << e.what();
  }
  config = plateConfig(d);
  config.plates[0].timeout = 0.0;
  EXPECT_THROW(jle::Estimator(model, config), std::invalid_argument);
}

}  // namespace
