// Force plates in the core: the decoding (force_plate.hpp) and the estimator's plate
// path (threshold, contact at the estimate's stamp, no stance load smeared on a swinging
// foot), against hand-worked numbers.
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/force_plate.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <jle_testing/papers_foot.hpp>

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
// In swing the plate reads 15 N below the threshold: f = (1, 0, -15), m = (0.3, -0.2, 0)
// about O. It acts on the foot as measured (no COP): the reaction (-1, 0, 15) with
// (-0.3, 0.2, 0) about O, i.e. (-0.3, 0.2, 0) + (O - A) x (-1, 0, 15) = (2.7, -2.68, 0.2)
// about A, so the ankle carries F_A = (1, 0, -15 + 9.80665), M_A = (-2.7, 2.68, -0.2) +
// the weight's (0, -0.4903325, 0).
const Vector3d kNoiseF(1.0, 0.0, -15.0), kNoiseM(0.3, -0.2, 0.0);
const Vector3d kNoiseForce = kSwingForce + Vector3d(1.0, 0.0, -15.0);
const Vector3d kNoiseMoment = kSwingMoment + Vector3d(-2.7, 2.68, -0.2);

jle::EstimatorConfig plateConfig(const jle::DifferentiatorConfig& differentiator) {
  jle::EstimatorConfig c;
  c.differentiator = differentiator;
  jle::PlateInputConfig p;
  p.plate = plate();
  p.timeout = 1.0;
  c.plates.push_back(p);
  return c;
}

// Stance (samples 0..59), swing with 15 N below the threshold (60..119), stance again
// (120..199), 1 kHz, plate and joint samples at the same stamps. After every joint
// sample, the published loads must be the stance numbers when the plate was in contact
// at the estimate's stamp, exactly as soon as the filter's window (or the Kalman filter's
// memory) has seen nothing else, and the swing numbers (the 15 N reading as measured)
// when it was not, exactly from the first swing stamp on.
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
    const int j = static_cast<int>(std::lround((estimator.last().stamp() - 3.0) * 1000.0));
    const jle::PlateReading& r = estimator.last().plateReading(0);
    const Vector3d& F = estimator.last().data().force[s];
    const Vector3d& M = estimator.last().data().moment[s];
    if (!contact(j)) {
      // A swinging foot: exactly its weight and the 15 N reading from the first stamp
      // after lift-off, although the filters still remember the stance. Rounding only:
      // 1e-12.
      EXPECT_FALSE(r.contact) << "stamp sample " << j;
      EXPECT_TRUE(r.loaded) << "stamp sample " << j;
      EXPECT_NEAR((F - kNoiseForce).norm(), 0.0, 1e-12) << "stamp sample " << j;
      EXPECT_NEAR((M - kNoiseMoment).norm(), 0.0, 1e-12) << "stamp sample " << j;
      if (first_swing_checked < 0) first_swing_checked = j;
      ++swing_checked;
    } else {
      EXPECT_TRUE(r.contact) << "stamp sample " << j;
      // The filtered plate wrench is c times the stance reading plus 1 - c times the
      // 15 N one (every sample enters the filter as measured; its weights sum to 1): the
      // foot gets the same mix of the two reactions. Rounding of the filter's weights:
      // 1e-9 of 700 N.
      const double c = stance(j);
      if (c >= 0.0) {
        const Vector3d F_expected = kNoiseForce + c * (kStanceForce - kNoiseForce);
        const Vector3d M_expected = kNoiseMoment + c * (kStanceMoment - kNoiseMoment);
        EXPECT_NEAR((F - F_expected).norm(), 0.0, 1e-9 * 700.0) << "stamp sample " << j;
        EXPECT_NEAR((M - M_expected).norm(), 0.0, 1e-9 * 700.0) << "stamp sample " << j;
        ++stance_checked;
        if (c == 1.0) {
          EXPECT_NEAR(r.cop_plate.x(), -0.15, 1e-12);
          EXPECT_NEAR(r.cop_plate.y(), -0.19, 1e-12);
        }
        // The COP of the mix: on the surface, the moment about it has no in-plane part.
        const Vector3d f = c * kF + (1.0 - c) * kNoiseF, m = c * kM + (1.0 - c) * kNoiseM;
        EXPECT_NEAR(r.cop_plate.z(), 0.04, 0.0);
        EXPECT_NEAR((m - r.cop_plate.cross(f)).head<2>().norm(), 0.0, 1e-9 * 700.0);
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
  // heel strike (j = 120), the 15 N reading's weight being the rest, 86 / 231.
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
    EXPECT_EQ(estimator.last().plateReading(0).contact, expect_contact) << k;
    EXPECT_NEAR(estimator.last().data().force[s].z(), expect_contact ? -690.19335 : kG, 1e-9) << k;
    EXPECT_EQ(estimator.last().plateStale(0), k >= 15) << k;
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
    EXPECT_NEAR((estimator.last().data().force[s] - kStanceForce).norm(), 0.0, 1e-6 * 700.0);
    EXPECT_NEAR((estimator.last().data().moment[s] - kStanceMoment).norm(), 0.0, 1e-6 * 700.0);
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

namespace {

// ---------------------------------------------------------------------------------
// Contact without a step: the paper's section 6 foot (papers_foot.hpp: a foot turning
// about a fixed ankle, gravity along -y) in a running-like stance on a plate whose
// surface is the world's y = 0 (plate z = world y). Exact inputs at 10 kHz: the foot's
// angle theta(t) of papers_foot.hpp, and the plate's reading of the ground reaction
// F_P = (F_x, F_y) at a centre of pressure c travelling 0.2 m from heel to toe. F_y
// rises from 0 to 2.5 body weights (75 kg) in 30 ms at heel strike (a quintic smooth
// step: below 20 N for its first 3 ms), dips at mid-stance and falls back to 0 in 30 ms
// at toe-off; F_x = -0.2 F_y cos(pi tau / T) (braking, then propulsion). The truth: the paper's
// planar equations (papers_foot.hpp) with the COP's lever, at the estimate's stamp.
struct ImpactScene {
  jle_test::PapersFoot foot;
  double t_strike = 0.05, T = 0.25, rise = 0.03;  ///< [s] heel strike, stance, rise time
  double peak = 2.5 * 75.0 * kG;                  ///< [N]
  double heel_x = -0.05, travel = 0.2;            ///< [m] COP at heel strike, its travel

  /// The reaction on the foot [N] and the COP in the world [m] at time t.
  void reaction(double t, Eigen::Vector2d& F_P, Eigen::Vector2d& c) const {
    const double tau = t - t_strike;
    double fy = 0.0;
    // The quintic smooth step 10 u^3 - 15 u^4 + 6 u^5: 0 to 1 with zero slope and
    // curvature at both ends.
    const auto step = [](double u) { return u * u * u * (10.0 + u * (-15.0 + 6.0 * u)); };
    if (tau > 0.0 && tau < T) {
      if (tau < rise)
        fy = peak * step(tau / rise);
      else if (tau > T - rise)
        fy = peak * step((T - tau) / rise);
      else
        fy = peak * (1.0 - 0.35 * std::pow(std::sin(M_PI * (tau - rise) / (T - 2.0 * rise)), 2));
    }
    F_P = Eigen::Vector2d(-0.2 * fy * std::cos(M_PI * tau / T), fy);
    c = Eigen::Vector2d(heel_x + travel * std::clamp(tau / T, 0.0, 1.0), 0.0);
  }

  /// The ankle moment on the foot about z [N m] at time t (papers_foot.hpp's equations).
  double ankleMoment(double t) const {
    const double theta0 = -0.1, A = 0.35, omega = 5.0;  // papers_foot.hpp's motion
    const double th = theta0 + A * std::sin(omega * t), thd = A * omega * std::cos(omega * t),
                 thdd = -A * omega * omega * std::sin(omega * t);
    const Eigen::Matrix2d Q = Eigen::Rotation2Dd(th).toRotationMatrix();
    const Eigen::Vector2d r = Q * foot.G_foot;  // ankle -> G
    const Eigen::Vector2d a_G(-thdd * r.y() - thd * thd * r.x(), thdd * r.x() - thd * thd * r.y());
    Eigen::Vector2d F_P, c;
    reaction(t, F_P, c);
    const Eigen::Vector2d F_A = foot.m * a_G - F_P - foot.m * foot.g;
    const Eigen::Vector2d x_G = foot.ankle_world + r;
    return foot.J_G * thdd - jle_test::cross2(foot.ankle_world - x_G, F_A) -
           jle_test::cross2(c - x_G, F_P);
  }
  double theta(double t) const { return -0.1 + 0.35 * std::sin(5.0 * t); }
};

jle::ForcePlateConfig groundPlate(double threshold) {
  jle::ForcePlateConfig p;
  p.name = "ground";
  p.link = "foot";
  // Plate x = world x, plate y = world -z, plate z = world y (the outward normal).
  p.R_world_plate << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  p.contact_threshold = threshold;
  return p;
}

// The plate's sample at t: what the foot applies to it, -F_P at c, plate frame, moment
// about its origin; zero where F_y < zero_below (the rule of versions before this one,
// which zeroed such samples and applied nothing below the threshold, is exactly the
// present code fed zeros there). True while the foot is on the plate (the stance).
bool plateSample(const ImpactScene& scene, const jle::ForcePlateConfig& plate, double t,
                 double zero_below, Vector3d& force, Vector3d& moment) {
  Eigen::Vector2d F_P, c;
  scene.reaction(t, F_P, c);
  const Vector3d f_world(-F_P.x(), -F_P.y(), 0.0);
  force = plate.R_world_plate.transpose() * f_world;
  moment = plate.R_world_plate.transpose() * Vector3d(c.x(), c.y(), 0.0).cross(f_world);
  if (F_P.y() < zero_below) {
    force.setZero();
    moment.setZero();
  }
  const double tau = t - scene.t_strike;
  return tau >= 0.0 && tau <= scene.T;
}

struct ImpactErrors {
  double stance_rms = 0.0, max = 0.0;  ///< [N m] ankle moment error over the stance
  int n = 0;
  void add(double error) {
    stance_rms += error * error;  // the sum of squares until finish()
    max = std::max(max, error);
    ++n;
  }
  ImpactErrors& finish() {
    stance_rms = std::sqrt(stance_rms / n);
    return *this;
  }
};

// The scene at 10 kHz through the estimator with `differentiator`.
ImpactErrors runEstimator(const jle::DifferentiatorConfig& differentiator, double threshold,
                          double zero_below) {
  const ImpactScene scene;
  const jle::Model<double> model = jle::modelFromUrdfString(scene.foot.urdf());
  jle::EstimatorConfig config;
  config.differentiator = differentiator;
  config.gravity_world = Vector3d(scene.foot.g.x(), scene.foot.g.y(), 0.0);
  jle::PlateInputConfig plate;
  plate.plate = groundPlate(threshold);
  config.plates.push_back(plate);
  jle::Estimator estimator(model, config);
  const int s = model.segmentOfJoint("ankle");
  ImpactErrors e;
  for (int k = 0; k <= 3500; ++k) {
    const double t = 1e-4 * k, q = scene.theta(t);
    Vector3d force, moment;
    plateSample(scene, plate.plate, t, zero_below, force, moment);
    EXPECT_TRUE(estimator.addPlateSample(0, t, force, moment));
    if (estimator.addJointSample(t, &q) != jle::SampleStatus::kPublished) continue;
    const double stamp = estimator.last().stamp();
    if (plateSample(scene, plate.plate, stamp, 0.0, force, moment))
      e.add(std::abs(estimator.last().data().effort[s] - scene.ankleMoment(stamp)));
  }
  EXPECT_GT(e.n, 2400);
  return e.finish();
}

// The scene at 10 kHz as joint_loads computes it: the exact q, q-dot, q-ddot and each
// plate sample's reaction (applyPlateReaction), no filter.
ImpactErrors runOffline(double threshold, double zero_below) {
  const ImpactScene scene;
  const jle::Model<double> model = jle::modelFromUrdfString(scene.foot.urdf());
  jle::Data<double> data(model);
  const jle::ForcePlateConfig plate = groundPlate(threshold);
  const int foot = model.frameIndex("foot"), s = model.segmentOfJoint("ankle");
  const Vector3d g(scene.foot.g.x(), scene.foot.g.y(), 0.0);
  ImpactErrors e;
  for (int k = 0; k <= 3500; ++k) {
    const double t = 1e-4 * k;
    Vector3d force, moment;
    if (!plateSample(scene, plate, t, zero_below, force, moment)) continue;
    jle::VectorX<double> q(1), qd(1), qdd(1);
    q << scene.theta(t);
    qd << 0.35 * 5.0 * std::cos(5.0 * t);  // papers_foot.hpp's motion
    qdd << -0.35 * 25.0 * std::sin(5.0 * t);
    jle::forwardKinematics(model, data, q, qd, qdd, g);
    jle::applyPlateReaction(model, data, foot, plate, jle::readForcePlate(plate, force, moment));
    jle::inverseDynamics(model, data);
    e.add(std::abs(data.effort[s] - scene.ankleMoment(t)));
  }
  return e.finish();
}

void report(const char* what, const ImpactErrors& zero, const ImpactErrors& now,
            const ImpactErrors& before) {
  std::printf(
      "%s: ankle moment error over the stance [N m]: threshold 0: RMS %.3g max %.3g; "
      "threshold 20 N: RMS %.3g max %.3g; the plate ignored below 20 N: RMS %.3g "
      "max %.3g\n",
      what, zero.stance_rms, zero.max, now.stance_rms, now.max, before.stance_rms, before.max);
}

// Heel strike and toe-off without a step: with the default threshold (20 N) the ankle
// moment's error over the stance is at most twice that of a threshold of 0, RMS and
// maximum. The rule of earlier versions (the plate ignored below 20 N, its samples
// zeroed before the filter) fails this: it leaves up to 20 N x 0.13 m = 2.6 N m out for
// the 3 ms each end spends below 20 N, and steps the filter's input by 20 N.
// - A centred Savitzky-Golay fit (5 samples, cubic: 0.2 ms of delay), whose own error on
//   this smooth scene is ~1e-6 N m, shows the rule's effect alone.
// - The default filter (constant-jerk Kalman): its own lag on the plate's rise (the
//   force channels are filtered like the joints') dominates, the same for every rule.
// - joint_loads (exact inputs, no filter): rounding alone with the new rule (a floor of
//   1e-9 N m for a ratio of roundings).
TEST(PlateContact, NoStepAtHeelStrikeAndToeOff) {
  jle::DifferentiatorConfig sg;
  sg.type = jle::DifferentiatorType::kSavitzkyGolay;
  sg.window = 5;
  sg.order = 3;
  sg.delay = 2;
  const ImpactErrors zero = runEstimator(sg, 0.0, 0.0), now = runEstimator(sg, 20.0, 0.0),
                     before = runEstimator(sg, 20.0, 20.0);
  report("Savitzky-Golay 5/3 centred", zero, now, before);
  EXPECT_LE(now.stance_rms, 2.0 * zero.stance_rms);
  EXPECT_LE(now.max, 2.0 * zero.max);
  EXPECT_GT(before.max, 2.0 * zero.max);
  EXPECT_GT(before.max, 1.0);

  const jle::DifferentiatorConfig kalman;  // the node's default
  const ImpactErrors k0 = runEstimator(kalman, 0.0, 0.0), k20 = runEstimator(kalman, 20.0, 0.0),
                     kb = runEstimator(kalman, 20.0, 20.0);
  report("default Kalman filter", k0, k20, kb);
  EXPECT_LE(k20.stance_rms, 2.0 * k0.stance_rms);
  EXPECT_LE(k20.max, 2.0 * k0.max);

  const ImpactErrors o0 = runOffline(0.0, 0.0), o20 = runOffline(20.0, 0.0),
                     ob = runOffline(20.0, 20.0);
  report("joint_loads, exact inputs", o0, o20, ob);
  EXPECT_LE(o20.stance_rms, 2.0 * o0.stance_rms + 1e-9);
  EXPECT_LE(o20.max, 2.0 * o0.max + 1e-9);
  EXPECT_GT(ob.max, 1.0);
}

// The offline path (joint_loads: the reading itself, no filter): below the threshold the
// reaction is the exact wrench of the reading, as with a threshold of 0, to rounding.
TEST(PlateContact, BelowTheThresholdTheExactWrenchActsWithoutACop) {
  const jle::ForcePlateConfig p = plate();
  jle::ForcePlateConfig zero = p;
  zero.contact_threshold = 0.0;
  // 15 N pressing at the COP (0.05, -0.02) of the plate's surface (h = 0.04) with a free
  // moment of 0.1 N m: about the plate origin M = c x f + (0, 0, 0.1).
  const Vector3d f(1.0, -2.0, -15.0), c(0.05, -0.02, 0.04);
  const Vector3d m = c.cross(f) + Vector3d(0.0, 0.0, 0.1);
  const jle::PlateReading below = jle::readForcePlate(p, f, m);
  EXPECT_TRUE(below.loaded);
  EXPECT_FALSE(below.contact);
  EXPECT_EQ(below.cop_plate, Vector3d::Zero());
  const jle::PlateReading exact = jle::readForcePlate(zero, f, m);
  ASSERT_TRUE(exact.contact);
  const Vector3d ankle(0.1, 0.0, 0.08);
  Vector3d F1, M1, F0, M0;
  jle::plateReactionInWorld(p, below, ankle, F1, M1);
  jle::plateReactionInWorld(zero, exact, ankle, F0, M0);
  // The reaction about the ankle by hand: -f at O + c, and the free moment -0.1 about z.
  const Vector3d cop_world = p.p_world_plate + c;
  const Vector3d M_hand = (cop_world - ankle).cross(-f) - Vector3d(0.0, 0.0, 0.1);
  EXPECT_EQ(F1, -f);
  EXPECT_NEAR((M1 - M_hand).norm(), 0.0, 1e-14);  // rounding of a few products of 0.1 m x 15 N
  EXPECT_NEAR((M1 - M0).norm(), 0.0, 1e-14);
  // Pulling or not finite: nothing acts.
  EXPECT_FALSE(jle::readForcePlate(p, Vector3d(0.0, 0.0, 5.0), Vector3d::Zero()).loaded);
}

}  // namespace
