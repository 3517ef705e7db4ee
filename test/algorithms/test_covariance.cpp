// The covariance of the published joint wrenches (Estimator::LastSample::covariance) against Monte
// Carlo: 10 000 noisy replays of one trajectory through the real Estimator, whose
// empirical covariance the propagated one must match; and the filters' noise gains
// against their closed forms.
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/ground_truth.hpp>
#include <jle_testing/random_models.hpp>

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace {

const std::string kData = JLE_TEST_DATA;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// ---------------------------------------------------------------------------------------
// Noise gains: the weights of the 3-point and 5-point fits are worked by hand.

Eigen::Matrix3d gainAfter(const jle::DifferentiatorConfig& config, int samples, double h) {
  jle::DifferentiatorBank bank(config, 1);
  for (int k = 0; k < samples; ++k) {
    const double x = 0.0;
    bank.update(k * h, &x);
  }
  return bank.noiseGain();
}

// The weights come from a QR of a scaled Vandermonde matrix: exact to some ulps of the
// largest weight, so each entry is compared relative to the scale of its row and column.
void expectGain(const Eigen::Matrix3d& G, const Eigen::Matrix3d& expected, double h) {
  const Eigen::Vector3d scale(1.0, 1.0 / h, 1.0 / (h * h));
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      EXPECT_NEAR(G(a, b), expected(a, b), 1e-9 * scale[a] * scale[b]) << a << "," << b;
}

TEST(NoiseGain, ThreePointCausal) {
  // x = x_n, x' = (3 x_n - 4 x_(n-1) + x_(n-2)) / 2h, x'' = (x_n - 2 x_(n-1) + x_(n-2)) / h^2.
  const double h = 1e-3;
  jle::DifferentiatorConfig c;
  c.type = jle::DifferentiatorType::kFiniteDifference;
  Eigen::Matrix3d expected;
  expected << 1.0, 1.5 / h, 1.0 / (h * h),        //
      1.5 / h, 6.5 / (h * h), 6.0 / (h * h * h),  // (9 + 16 + 1) / 4h^2, (3 + 8 + 1) / 2h^3
      1.0 / (h * h), 6.0 / (h * h * h), 6.0 / std::pow(h, 4);
  expectGain(gainAfter(c, 5, h), expected, h);
}

TEST(NoiseGain, ThreePointCentred) {
  // x = x_(n-1), x' = (x_n - x_(n-2)) / 2h, x'' as above.
  const double h = 2e-3;
  jle::DifferentiatorConfig c;
  c.type = jle::DifferentiatorType::kFiniteDifference;
  c.delay = 1;
  Eigen::Matrix3d expected;
  expected << 1.0, 0.0, -2.0 / (h * h),  //
      0.0, 0.5 / (h * h), 0.0,           //
      -2.0 / (h * h), 0.0, 6.0 / std::pow(h, 4);
  expectGain(gainAfter(c, 4, h), expected, h);
}

TEST(NoiseGain, SavitzkyGolayFivePointCentred) {
  // Quadratic fit of 5 samples at the centre: value (-3, 12, 17, 12, -3) / 35, rate
  // (-2, -1, 0, 1, 2) / 10h, second derivative (2, -1, -2, -1, 2) / 7h^2.
  const double h = 1e-2;
  jle::DifferentiatorConfig c;
  c.type = jle::DifferentiatorType::kSavitzkyGolay;
  c.window = 5;
  c.delay = 2;
  Eigen::Matrix3d expected;
  const double v02 = (-3.0 * 2 + 12.0 * -1 + 17.0 * -2 + 12.0 * -1 + -3.0 * 2) / (35.0 * 7.0);
  expected << 595.0 / 1225.0, 0.0, v02 / (h * h),  //
      0.0, 10.0 / (100.0 * h * h), 0.0,            //
      v02 / (h * h), 0.0, 14.0 / (49.0 * std::pow(h, 4));
  expectGain(gainAfter(c, 7, h), expected, h);
}

// The Kalman filter's gain has no short closed form: it is checked against the
// empirical covariance of many channels of pure white noise through the same bank.
TEST(NoiseGain, KalmanAgainstMonteCarlo) {
  for (jle::KalmanModel model :
       {jle::KalmanModel::kConstantAcceleration, jle::KalmanModel::kConstantJerk}) {
    jle::DifferentiatorConfig c;
    c.type = jle::DifferentiatorType::kKalman;
    c.kalman_model = model;
    c.process_noise = 1e4;
    c.measurement_noise = 1e-3;
    const int channels = 20000;
    jle::DifferentiatorBank bank(c, channels);
    jle::PortableRandom random(7);
    std::vector<double> x(static_cast<std::size_t>(channels));
    const double h = 1e-3;
    for (int k = 0; k < 400; ++k) {
      for (double& v : x) v = random.gaussian();
      bank.update(k * h, x.data());
      if (k != 3 && k != 399) continue;  // in the start-up, and settled
      Eigen::Matrix3d empirical = Eigen::Matrix3d::Zero();
      for (int ch = 0; ch < channels; ++ch) {
        const Eigen::Vector3d e(bank.value(ch), bank.rate(ch), bank.accel(ch));
        empirical += e * e.transpose();
      }
      empirical /= channels;
      const Eigen::Matrix3d G = bank.noiseGain();
      // A variance from 20 000 samples has a relative standard error of
      // sqrt(2 / 20000) = 1%: 6% is 6 of them.
      for (int a = 0; a < 3; ++a)
        EXPECT_NEAR(empirical(a, a) / G(a, a), 1.0, 0.06)
            << "model " << static_cast<int>(model) << " sample " << k << " entry " << a;
    }
  }
}

// ---------------------------------------------------------------------------------------
// Monte Carlo through the Estimator.

struct Scene {
  std::string name;
  std::string urdf;
  std::vector<std::string> wrench_links;
  jle::DifferentiatorConfig filter;
  double rate = 1000.0;       // [Hz]
  double position_noise = 0;  // [rad or m]
  double force_noise = 0;     // [N]
  double moment_noise = 0;    // [N m]
  std::vector<int> instants;  // sample indices at which the covariance is compared
};

void runMonteCarlo(const Scene& scene, int replays) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/" + scene.urdf);
  std::vector<jle::WrenchMotion> wrenches;
  for (std::size_t k = 0; k < scene.wrench_links.size(); ++k)
    wrenches.push_back(jle::randomWrench(scene.wrench_links[k], 100 + k));
  const jle::GroundTruth truth(model, jle::randomMotion(model, jle::MotionKind::kSines, 5.0, 11),
                               wrenches);
  jle::EstimatorConfig config;
  config.differentiator = scene.filter;
  config.savings.reuse_unchanged = false;
  for (const std::string& link : scene.wrench_links) {
    jle::WrenchInputConfig w;
    w.name = link;
    w.link = link;
    w.force_noise = scene.force_noise;
    w.moment_noise = scene.moment_noise;
    config.wrenches.push_back(w);
  }
  config.uncertainty.position_noise = scene.position_noise;

  // The clean readings, at k / rate (the wrenches sampled at the same instants).
  const int samples = scene.instants.back() + 1;
  std::vector<Eigen::VectorXd> q_clean(static_cast<std::size_t>(samples));
  std::vector<std::vector<Vector6>> w_clean(static_cast<std::size_t>(samples));
  Eigen::VectorXd qd, qdd;
  for (int k = 0; k < samples; ++k) {
    truth.coordinates(k / scene.rate, q_clean[k], qd, qdd);
    for (const jle::WrenchMotion& w : wrenches) w_clean[k].push_back(w.at(k / scene.rate));
  }

  const std::vector<int>& published = model.moving_segments;
  auto replay = [&](jle::Estimator& estimator, jle::PortableRandom* random,
                    const std::function<void(int)>& at_instant) {
    estimator.reset();
    Eigen::VectorXd q(model.nq);
    std::size_t next = 0;
    for (int k = 0; k < samples; ++k) {
      const double t = k / scene.rate;
      for (std::size_t i = 0; i < wrenches.size(); ++i) {
        Vector6 w = w_clean[k][i];
        if (random)
          for (int c = 0; c < 6; ++c)
            w[c] += (c < 3 ? scene.force_noise : scene.moment_noise) * random->gaussian();
        estimator.addWrench(static_cast<int>(i), t, w.head<3>(), w.tail<3>());
      }
      q = q_clean[k];
      if (random)
        for (int i = 0; i < model.nq; ++i) q[i] += scene.position_noise * random->gaussian();
      const jle::SampleStatus status = estimator.addJointSample(t, q.data());
      if (next < scene.instants.size() && k == scene.instants[next]) {
        ASSERT_EQ(status, jle::SampleStatus::kPublished) << "sample " << k;
        at_instant(static_cast<int>(next++));
      }
    }
  };

  // The propagated covariance, on the noise-free replay; and with linearize_state off,
  // to show how much the linearised q, q-dot part weighs.
  const std::size_t ni = scene.instants.size(), np = published.size();
  std::vector<std::vector<Matrix6>> propagated(ni, std::vector<Matrix6>(np));
  std::vector<std::vector<Matrix6>> qdd_only(ni, std::vector<Matrix6>(np));
  std::vector<std::vector<Vector6>> clean(ni, std::vector<Vector6>(np));
  std::vector<std::vector<double>> effort_variance(ni, std::vector<double>(np));
  {
    jle::EstimatorConfig c = config;
    c.uncertainty.enabled = true;
    c.uncertainty.period = 0.0;  // the propagation itself, at every sample
    jle::Estimator estimator(model, c);
    replay(estimator, nullptr, [&](int n) {
      for (std::size_t j = 0; j < np; ++j) {
        propagated[n][j] = estimator.last().covariance(published[j]);
        effort_variance[n][j] = estimator.last().effortVariance(published[j]);
        clean[n][j] << estimator.last().data().force[published[j]],
            estimator.last().data().moment[published[j]];
      }
    });
    c.uncertainty.linearize_state = false;
    jle::Estimator cheap(model, c);
    replay(cheap, nullptr, [&](int n) {
      for (std::size_t j = 0; j < np; ++j) qdd_only[n][j] = cheap.last().covariance(published[j]);
    });
  }

  // The Monte Carlo, with the covariance off (it plays no part in the loads).
  std::vector<std::vector<Vector6>> sum(ni, std::vector<Vector6>(np, Vector6::Zero()));
  std::vector<std::vector<Matrix6>> sum2(ni, std::vector<Matrix6>(np, Matrix6::Zero()));
  std::vector<std::vector<double>> effort_sum2(ni, std::vector<double>(np, 0.0));
  jle::Estimator estimator(model, config);
  jle::PortableRandom random(2024);
  const auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < replays; ++r) {
    replay(estimator, &random, [&](int n) {
      for (std::size_t j = 0; j < np; ++j) {
        const int s = published[j];
        Vector6 d;
        d << estimator.last().data().force[s], estimator.last().data().moment[s];
        d -= clean[n][j];
        sum[n][j] += d;
        sum2[n][j].noalias() += d * d.transpose();
        const double e =
            estimator.last().data().effort[s] - (model.joint_type[s] == jle::JointType::kRevolute
                                                     ? model.axis[s].dot(clean[n][j].tail<3>())
                                                     : model.axis[s].dot(clean[n][j].head<3>()));
        effort_sum2[n][j] += e * e;
      }
    });
    if (::testing::Test::HasFatalFailure()) return;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %d replays of %d samples in %.2f s\n", scene.name.c_str(), replays, samples,
              seconds);

  // A variance estimated from N = 10 000 Gaussian samples has a relative standard error
  // of sqrt(2 / N) = 1.4%: 10% is 7 of them, so a true agreement fails by chance with
  // negligible probability over the ~1000 terms compared, while a missing or doubled
  // contribution of a tenth of a term fails. Terms whose propagated variance is below
  // 1e-9 of the largest of their joint are exactly zero in theory (a massless,
  // unloaded link) and compared in absolute terms instead.
  const double tolerance = 0.10;
  double worst = 0.0, largest_state_share = 0.0;
  for (std::size_t n = 0; n < ni; ++n) {
    for (std::size_t j = 0; j < np; ++j) {
      const Vector6 mean = sum[n][j] / replays;
      const Matrix6 empirical = sum2[n][j] / replays - mean * mean.transpose();
      const Matrix6& P = propagated[n][j];
      const double top = P.diagonal().maxCoeff();
      std::printf("  %-8s t=%3d %-22s ratio empirical/propagated:", scene.name.c_str(),
                  scene.instants[n], model.joint_name[published[j]].c_str());
      for (int c = 0; c < 6; ++c) {
        if (P(c, c) <= 1e-9 * top) {
          std::printf("    (0)");
          EXPECT_LE(empirical(c, c), 1e-6 * top + 1e-20);
          continue;
        }
        const double ratio = empirical(c, c) / P(c, c);
        std::printf(" %6.3f", ratio);
        worst = std::max(worst, std::abs(ratio - 1.0));
        largest_state_share = std::max(largest_state_share, 1.0 - qdd_only[n][j](c, c) / P(c, c));
        EXPECT_NEAR(ratio, 1.0, tolerance) << scene.name << " t=" << scene.instants[n] << " joint "
                                           << model.joint_name[published[j]] << " component " << c;
      }
      const double ev = effort_sum2[n][j] / replays;
      std::printf("  effort %6.3f\n", effort_variance[n][j] > 0 ? ev / effort_variance[n][j] : 0.0);
      if (effort_variance[n][j] > 1e-9 * top) {
        EXPECT_NEAR(ev / effort_variance[n][j], 1.0, tolerance);
      }
    }
  }
  std::printf(
      "%s: worst |ratio - 1| = %.3f; largest share of the linearised q, q-dot part "
      "in a variance: %.3f\n",
      scene.name.c_str(), worst, largest_state_share);
}

jle::DifferentiatorConfig savitzkyGolay(int window, int delay) {
  jle::DifferentiatorConfig c;
  c.type = jle::DifferentiatorType::kSavitzkyGolay;
  c.window = window;
  c.delay = delay;
  return c;
}

constexpr int kReplays = 10000;

// Savitzky-Golay, 9 samples, causal at 1 kHz (not the node's default filter: the constant-jerk
// Kalman filter's Monte Carlo through the node's path is test_covariance_pipeline): q-ddot's
// noise dominates, wrench noise on top.
TEST(CovarianceMonteCarlo, PandaSavitzkyGolay9Causal) {
  Scene s{"panda", "panda.urdf", {"panda_hand"}, savitzkyGolay(9, 0), 1000.0, 1e-4,
          0.5,     0.05,         {12, 20}};
  runMonteCarlo(s, kReplays);
}

// A long centred window at 100 Hz and a noisy encoder: q-ddot is so well smoothed that
// the linearised q and q-dot terms (gravity, Coriolis) carry a visible share.
TEST(CovarianceMonteCarlo, PandaLongWindow) {
  Scene s{"panda_lw", "panda.urdf", {"panda_hand"}, savitzkyGolay(41, 20), 100.0, 1e-2,
          0.0,        0.0,          {45, 60}};
  runMonteCarlo(s, kReplays);
}

TEST(CovarianceMonteCarlo, TalosKalman) {
  jle::DifferentiatorConfig k;
  k.type = jle::DifferentiatorType::kKalman;
  k.process_noise = 1e4;
  k.kalman_model = jle::KalmanModel::kConstantAcceleration;
  k.measurement_noise = 1e-4;
  Scene s{"talos",
          "talos_reduced.urdf",
          {"left_sole_link", "right_sole_link", "gripper_left_base_link"},
          k,
          1000.0,
          1e-4,
          1.0,
          0.1,
          {15, 30}};
  runMonteCarlo(s, kReplays);
}

TEST(CovarianceMonteCarlo, TalosLongWindow) {
  Scene s{"talos_lw",
          "talos_reduced.urdf",
          {"left_sole_link"},
          savitzkyGolay(41, 20),
          100.0,
          1e-2,
          2.0,
          0.2,
          {45}};
  runMonteCarlo(s, kReplays);
}

// ---------------------------------------------------------------------------------------
// The propagation of the coordinate noise against the previous implementation's method,
// kept here as the reference: every column of d y / d(q, qd, qdd)_j by differences of
// complete passes of the core (q-ddot: the loads are linear in it, a unit step is exact
// to rounding; q, q-dot: central differences), Cov = sum_j J_j sigma^2 G J_j^T.

struct ReferenceScene {
  std::string urdf;
  std::string wrench_link;  // an applied input (its wrench moves with its link)
};

void expectMatchesReference(const ReferenceScene& scene, bool linearize_state) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/" + scene.urdf);
  const jle::WrenchMotion wrench = jle::randomWrench(scene.wrench_link, 17);
  const jle::GroundTruth truth(model, jle::randomMotion(model, jle::MotionKind::kSines, 5.0, 23),
                               {wrench});
  jle::EstimatorConfig config;
  config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
  config.savings.reuse_unchanged = false;
  jle::WrenchInputConfig w;
  w.name = w.link = scene.wrench_link;
  config.wrenches.push_back(w);
  config.uncertainty.enabled = true;
  config.uncertainty.period = 0.0;  // the propagation itself, at every sample
  config.uncertainty.position_noise = 1e-3;
  config.uncertainty.linearize_state = linearize_state;
  jle::Estimator estimator(model, config);
  jle::DifferentiatorBank bank(config.differentiator, 1);  // the same times: the same gain
  Eigen::VectorXd q, qd, qdd;
  const double h_t = 1e-3;
  for (int k = 0; k < 30; ++k) {
    const double t = 0.5 + k * h_t;
    const Vector6 wr = wrench.at(t);
    estimator.addWrench(0, t, wr.head<3>(), wr.tail<3>());
    truth.coordinates(t, q, qd, qdd);
    ASSERT_EQ(estimator.addJointSample(t, q.data()),
              k < 8 ? jle::SampleStatus::kWarmingUp : jle::SampleStatus::kPublished);
    const double x = 0.0;
    bank.update(t, &x);
  }
  const Eigen::Matrix3d Sigma = 1e-6 * bank.noiseGain();
  const jle::Wrench<double> applied = estimator.last().appliedWrench(0);
  const int frame = model.frameIndex(scene.wrench_link);
  jle::Data<double> data(model);
  auto loads = [&](const Eigen::VectorXd& q_, const Eigen::VectorXd& qd_,
                   const Eigen::VectorXd& qdd_, std::vector<Vector6>& y) {
    jle::forwardKinematics(model, data, q_, qd_, qdd_, Eigen::Vector3d(0.0, 0.0, -9.80665));
    jle::addExternalWrench(model, data, frame, applied.force, applied.moment,
                           jle::WrenchFrame::kLocal);
    jle::inverseDynamics(model, data);
    y.resize(static_cast<std::size_t>(model.nsegments()));
    for (int i = 0; i < model.nsegments(); ++i) y[i] << data.force[i], data.moment[i];
  };
  const Eigen::VectorXd q0 = estimator.last().q(), qd0 = estimator.last().qd(),
                        qdd0 = estimator.last().qdd();
  const int n = model.nsegments();
  std::vector<Matrix6> reference(static_cast<std::size_t>(n), Matrix6::Zero());
  std::vector<Vector6> y0, yp, ym;
  loads(q0, qd0, qdd0, y0);
  // Central differences: truncation h^2 / 6 times the third derivative (1e-10 for angles
  // of order 1), rounding eps |y| / h (1e-11 |y|): far below the 1e-8 allowed below.
  const double h = 1e-5;
  for (int j = 0; j < model.nq; ++j) {
    std::vector<Eigen::Matrix<double, 6, 3>> J(static_cast<std::size_t>(n),
                                               Eigen::Matrix<double, 6, 3>::Zero());
    Eigen::VectorXd a = qdd0;
    a[j] += 1.0;
    loads(q0, qd0, a, yp);
    for (int i = 0; i < n; ++i) J[i].col(2) = yp[i] - y0[i];
    if (linearize_state) {
      Eigen::VectorXd b = q0, c = q0;
      b[j] += h;
      c[j] -= h;
      loads(b, qd0, qdd0, yp);
      loads(c, qd0, qdd0, ym);
      for (int i = 0; i < n; ++i) J[i].col(0) = (yp[i] - ym[i]) / (2.0 * h);
      b = qd0;
      c = qd0;
      b[j] += h;
      c[j] -= h;
      loads(q0, b, qdd0, yp);
      loads(q0, c, qdd0, ym);
      for (int i = 0; i < n; ++i) J[i].col(1) = (yp[i] - ym[i]) / (2.0 * h);
      for (int i = 0; i < n; ++i) reference[i] += J[i] * Sigma * J[i].transpose();
    } else {
      for (int i = 0; i < n; ++i)
        reference[i] += Sigma(2, 2) * J[i].col(2) * J[i].col(2).transpose();
    }
  }
  // q-ddot only: both exact, the same sums in another order (1e-12). With q and q-dot:
  // the reference's central differences (1e-8). Each entry relative to the standard
  // deviations of its row and column.
  const double tolerance = linearize_state ? 1e-8 : 1e-12;
  double worst = 0.0;
  for (int i : model.moving_segments) {
    const Matrix6& P = estimator.last().covariance(i);
    const Matrix6& R = reference[i];
    for (int a = 0; a < 6; ++a)
      for (int b = 0; b < 6; ++b) {
        const double scale = std::sqrt(R(a, a) * R(b, b)) + 1e-300;
        worst = std::max(worst, std::abs(P(a, b) - R(a, b)) / scale);
        EXPECT_NEAR(P(a, b), R(a, b), tolerance * scale)
            << scene.urdf << " " << model.joint_name[i] << " (" << a << "," << b << ")";
      }
  }
  std::printf("%s, linearize_state %d: worst relative difference to the reference %.1e\n",
              scene.urdf.c_str(), linearize_state ? 1 : 0, worst);
}

TEST(CovarianceReference, PandaWithMimicFingers) {
  expectMatchesReference({"panda.urdf", "panda_hand"}, true);
  expectMatchesReference({"panda.urdf", "panda_hand"}, false);
}

TEST(CovarianceReference, Talos) {
  expectMatchesReference({"talos_reduced.urdf", "left_sole_link"}, true);
  expectMatchesReference({"talos_reduced.urdf", "left_sole_link"}, false);
}

// uncertainty.period: the covariance is computed for a published sample at least a period
// after the last computed one (and for the first three, and after a gap of more than 3
// periods); a sample in between gets the quadratic through the last three computed
// covariances at their stamps (Lagrange). Checked against that formula applied to the
// covariances of an estimator computing at every sample (the computed samples must be
// those exactly), at 1 kHz, at 100 Hz and at irregular stamps with a gap; and the error of
// the efforts' sigma against the exact one measured for periods of 2 to 160 ms, holding
// C_0, the line through the last two and the quadratic.
// Trajectories: 2 s of randomMotion kSines (2 or 3 sines per joint, 0.1 to 0.6 Hz,
// amplitudes 0.05 to 0.3 rad).

// The weights of the last three computed (stamps t[0] > t[1] > t[2]) at the stamp x:
// Lagrange's basis polynomials through the 1, 2 or 3 newest (order 0: held, 1: line,
// 2: quadratic), each the product over the other nodes of (x - t_m) / (t_k - t_m).
Eigen::Vector3d extrapolationWeights(int order, const double t[3], double x) {
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (int k = 0; k <= order; ++k) {
    w[k] = 1.0;
    for (int m = 0; m <= order; ++m)
      if (m != k) w[k] *= (x - t[m]) / (t[k] - t[m]);
  }
  return w;
}

// The rule, replayed on the stamps (a stamp difference is compared with the period to
// a millionth of it, the rounding of the time axis): per published sample, -1 if computed, else the
// index of its entry in `nodes` (the three computed samples it is extrapolated from, newest first).
struct Schedule {
  std::vector<int> node_of;
  std::vector<std::array<std::size_t, 3>> nodes;
};
Schedule schedule(const std::vector<double>& stamps, double period) {
  Schedule s;
  std::vector<std::size_t> history;  // newest first
  for (std::size_t b = 0; b < stamps.size(); ++b) {
    if (!history.empty()) {
      const double since = stamps[b] - stamps[history[0]];
      if (!(since > 0.0 && since <= 3.0 * period)) history.clear();
    }
    if (period > 0.0 && history.size() == 3 &&
        stamps[b] - stamps[history[0]] < (1.0 - 1e-6) * period) {  // to rounding: 1e-6 period
      s.node_of.push_back(static_cast<int>(s.nodes.size()));
      s.nodes.push_back({history[0], history[1], history[2]});
      continue;
    }
    s.node_of.push_back(-1);
    // Kept as a node only a period after the last one (or as the first).
    if (!history.empty() && stamps[b] - stamps[history[0]] < (1.0 - 1e-6) * period) continue;
    history.insert(history.begin(), b);
    if (history.size() > 3) history.pop_back();
  }
  return s;
}

struct ExtrapolationError {
  double worst = 0.0, mean = 0.0;
  int clamped = 0;    // extrapolated effort variances below 0
  long samples = 0;   // extrapolated samples
  std::string where;  // the joint and stamp of the worst
};

// Over the samples the schedule does not compute: the effort variance from its three
// nodes (order 0: held, 1: line, 2: quadratic), relative sigma error against the exact one.
ExtrapolationError extrapolationError(const std::vector<double>& stamps,
                                      const std::vector<std::vector<double>>& var,
                                      const std::vector<std::string>& names, double period,
                                      int order) {
  const Schedule s = schedule(stamps, period);
  ExtrapolationError e;
  long count = 0;
  for (std::size_t b = 0; b < stamps.size(); ++b) {
    if (s.node_of[b] < 0) continue;
    ++e.samples;
    const std::array<std::size_t, 3>& n = s.nodes[static_cast<std::size_t>(s.node_of[b])];
    const double t[3] = {stamps[n[0]], stamps[n[1]], stamps[n[2]]};
    const Eigen::Vector3d w = extrapolationWeights(order, t, stamps[b]);
    for (std::size_t i = 0; i < var[b].size(); ++i) {
      if (var[b][i] <= 0.0) continue;
      const double v = w[0] * var[n[0]][i] + w[1] * var[n[1]][i] + w[2] * var[n[2]][i];
      if (v < 0.0) ++e.clamped;
      const double err = std::abs(std::sqrt(std::max(v, 0.0) / var[b][i]) - 1.0);
      if (err > e.worst) {
        e.worst = err;
        e.where = names[i] + " at " + std::to_string(stamps[b]) + " s";
      }
      e.mean += err;
      ++count;
    }
  }
  if (count) e.mean /= count;
  return e;
}

// The default (config/default.yaml) and the bounds asserted on its worst sigma error.
// Measured at 1 kHz (docs/studies/uncertainty.md): 0.0020 (Panda), 0.0265 (Talos); per robot,
// 0.003 and 0.03 (the 3% the default was chosen by). At 100 Hz (the same trajectory):
// 0.0030 (Panda) and 0.0021 (Talos), held to the 1 kHz bound over both robots, 0.03
// (the composition of the variances differs with the rate: at 100 Hz the q-ddot noise is
// 10^4 times smaller, so the smoother state-dependent terms weigh more; Panda's error
// is then a little larger than at 1 kHz, Talos' much smaller). The trajectory has no
// noise, so the measurement is deterministic to rounding; the bounds leave room for other
// compilers only. They fail if the extrapolation degrades: the line through two gives
// 0.014 and 0.20 at 18 ms and 1 kHz, holding 0.072 and 0.22; a period taken as a sample
// count (18 samples at 100 Hz = 180 ms) gives 100% (variances clamped).
constexpr double kDefaultPeriod = 0.018;
constexpr double kExtrapolationBound[2] = {0.003, 0.03};  // panda, talos at 1 kHz
constexpr double kAnyRateBound = 0.03;                    // both, at any rate

enum class Stamps { k1kHz, k100Hz, kIrregular };

// Replays the trajectory at the stamps through an estimator computing every sample and
// through two with periods (7 ms and the default) and one with the default and
// diagonal_only: the computed samples must equal the exact ones, the others the formula.
// Returns the stamps and exact effort variances of the published samples.
void checkPeriod(const std::string& urdf, Stamps kind, std::vector<double>& published,
                 std::vector<std::vector<double>>& var, std::vector<std::string>& names,
                 double jitter = 0.0) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/" + urdf);
  const jle::GroundTruth truth(model, jle::randomMotion(model, jle::MotionKind::kSines, 5.0, 31),
                               {});
  std::vector<double> stamps;
  if (kind == Stamps::kIrregular) {
    // dt uniform in 1 ms (1 +- jitter), and a 100 ms gap at 1 s (over 3 periods: the
    // history starts again; under the filter's max_gap of 0.5 s: the filter goes on).
    jle_test::Random rng(7);
    const jle_test::UniformIn dt(1e-3 * (1.0 - jitter), 1e-3 * (1.0 + jitter));
    for (double t = 0.0; t<2.0; t += t> 1.0 && t < 1.0015 ? 0.1 : dt(rng)) stamps.push_back(t);
  } else {
    const double h = kind == Stamps::k1kHz ? 1e-3 : 1e-2;
    for (int k = 0; k * h < 2.0 - 1e-9; ++k) stamps.push_back(k * h);
  }
  jle::EstimatorConfig config;
  config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
  config.savings.reuse_unchanged = false;
  config.uncertainty.enabled = true;
  config.uncertainty.period = 0.0;
  // The schedule by the stamps alone (the noise-gain guard is tested on its own below).
  config.uncertainty.gain_tolerance = 1e300;
  config.uncertainty.position_noise = 1e-4;
  config.uncertainty.mass_fraction = 0.05;
  config.uncertainty.com_offset = 0.005;
  config.uncertainty.inertia_fraction = 0.1;
  jle::Estimator every(model, config);
  const double periods[3] = {0.007, kDefaultPeriod, kDefaultPeriod};
  std::vector<jle::Estimator> sparse;
  sparse.reserve(3);
  for (int c = 0; c < 3; ++c) {
    config.uncertainty.period = periods[c];
    config.uncertainty.diagonal_only = c == 2;
    sparse.emplace_back(model, config);
  }
  const std::vector<int>& segments = every.layout().dynamicsSegments();
  std::vector<std::vector<Matrix6>> cov;  // per published sample, per computed segment
  published.clear();
  var.clear();
  names.clear();
  for (int i : model.moving_segments) names.push_back(model.joint_name[i]);
  // The schedules are replayed on the published stamps as they come (a schedule's
  // decision for a sample depends only on the stamps up to it).
  Eigen::VectorXd q, qd, qdd;
  long checked_extrapolated = 0;
  for (double t : stamps) {
    truth.coordinates(t, q, qd, qdd);
    const jle::SampleStatus s = every.addJointSample(t, q.data());
    for (jle::Estimator& d : sparse) ASSERT_EQ(d.addJointSample(t, q.data()), s);
    if (s != jle::SampleStatus::kPublished) continue;
    published.push_back(every.last().stamp());
    std::vector<Matrix6> row;
    for (int i : segments) row.push_back(every.last().covariance(i));
    cov.push_back(row);
    std::vector<double> v;
    for (int i : model.moving_segments) v.push_back(every.last().effortVariance(i));
    var.push_back(v);
    const std::size_t b = cov.size() - 1;
    for (std::size_t c = 0; c < 3; ++c) {
      const jle::Estimator& d = sparse[c];
      const Schedule sch = schedule(published, periods[c]);
      const bool computed = sch.node_of[b] < 0;
      std::array<std::size_t, 3> n = {b, b, b};
      Eigen::Vector3d w(1.0, 0.0, 0.0);
      if (!computed) {
        n = sch.nodes[static_cast<std::size_t>(sch.node_of[b])];
        const double tn[3] = {published[n[0]], published[n[1]], published[n[2]]};
        w = extrapolationWeights(2, tn, published[b]);
      }
      for (std::size_t m = 0; m < segments.size(); ++m) {
        const Matrix6& P = d.last().covariance(segments[m]);
        if (computed && c < 2) {  // the same code on the same inputs
          EXPECT_EQ(P, cov[b][m]) << urdf << " sample " << b;
          continue;
        }
        // The formula, entry by entry, with its clamp (a negative variance: its row and
        // column zeroed); diagonal_only: its diagonal (the same variances summed in
        // another order: 1e-12 relative, see the reference test). Full: rounding, some
        // ulps of the terms (the weights reach a few hundred right after the start,
        // whose three nodes are one sample apart).
        Matrix6 E = cov[b][m];
        if (!computed) E = w[0] * cov[n[0]][m] + w[1] * cov[n[1]][m] + w[2] * cov[n[2]][m];
        if (c == 2) E = Matrix6(E.diagonal().asDiagonal());
        for (int r = 0; r < 6; ++r)
          if (E(r, r) < 0.0) E.row(r).setZero(), E.col(r).setZero();
        const double tolerance = c == 2 ? 1e-11 : 1e-12;
        for (int r = 0; r < 6; ++r) {
          EXPECT_GE(P(r, r), 0.0);
          for (int col = 0; col < 6; ++col) {
            const double scale =
                tolerance *
                    (std::abs(w[0] * cov[n[0]][m](r, col)) + std::abs(w[1] * cov[n[1]][m](r, col)) +
                     std::abs(w[2] * cov[n[2]][m](r, col)) + std::abs(cov[b][m](r, col))) +
                1e-300;
            EXPECT_NEAR(P(r, col), E(r, col), scale) << urdf << " sample " << b;
            EXPECT_NEAR(P(r, col), P(col, r), scale) << urdf << " sample " << b;  // symmetric
          }
        }
        if (!computed) ++checked_extrapolated;
      }
      // The effort variance follows the matrix: u^T C u is linear in C, so it is the
      // same extrapolation of the exact effort variances (clamped at 0).
      for (std::size_t i = 0; i < names.size() && !computed; ++i) {
        const double v_e =
            std::max(0.0, w[0] * var[n[0]][i] + w[1] * var[n[1]][i] + w[2] * var[n[2]][i]);
        EXPECT_NEAR(d.last().effortVariance(model.moving_segments[i]), v_e,
                    1e-12 * (std::abs(w[0] * var[n[0]][i]) + std::abs(w[1] * var[n[1]][i]) +
                             std::abs(w[2] * var[n[2]][i])) +
                        1e-300)
            << urdf << " " << names[i] << " sample " << b;
      }
    }
  }
  EXPECT_GT(checked_extrapolated, kind == Stamps::k100Hz ? 100 : 1000) << urdf;
}

void printErrors(const std::string& label, const std::vector<double>& published,
                 const std::vector<std::vector<double>>& var,
                 const std::vector<std::string>& names) {
  std::printf(
      "%s: period [ms] | hold worst, mean | line worst, mean | quadratic worst, "
      "mean, clamped | extrapolated samples | where the worst (hold; line; quadratic)\n",
      label.c_str());
  for (int ms : {2, 4, 8, 10, 12, 16, 17, 18, 20, 24, 32, 50, 100, 160}) {
    ExtrapolationError e[3];
    for (int order = 0; order < 3; ++order)
      e[order] = extrapolationError(published, var, names, ms * 1e-3, order);
    std::printf("%s period %3d | %.4f %.5f | %.4f %.5f | %.4f %.6f %d | %ld | %s; %s; %s\n",
                label.c_str(), ms, e[0].worst, e[0].mean, e[1].worst, e[1].mean, e[2].worst,
                e[2].mean, e[2].clamped, e[2].samples, e[0].where.c_str(), e[1].where.c_str(),
                e[2].where.c_str());
  }
}

// The error depends on the period, not on the rate: the default stays within the bound
// measured at 1 kHz when the same trajectory is sampled at 100 Hz.
TEST(CovariancePeriod, ExtrapolatesAtAnyRateWithinTheBound) {
  int robot = 0;
  for (const std::string urdf : {"panda.urdf", "talos_reduced.urdf"}) {
    for (Stamps kind : {Stamps::k1kHz, Stamps::k100Hz}) {
      std::vector<double> published;
      std::vector<std::vector<double>> var;
      std::vector<std::string> names;
      checkPeriod(urdf, kind, published, var, names);
      const std::string label = urdf + (kind == Stamps::k1kHz ? " 1kHz" : " 100Hz");
      printErrors(label, published, var, names);
      const ExtrapolationError q = extrapolationError(published, var, names, kDefaultPeriod, 2);
      const ExtrapolationError hold = extrapolationError(published, var, names, kDefaultPeriod, 0);
      std::printf("%s default %.0f ms: quadratic worst %.5f (%s), mean %.6f, clamped %d\n",
                  label.c_str(), kDefaultPeriod * 1e3, q.worst, q.where.c_str(), q.mean, q.clamped);
      EXPECT_GT(q.samples, kind == Stamps::k1kHz ? 1500 : 90) << label;
      EXPECT_LE(q.worst, kind == Stamps::k1kHz ? kExtrapolationBound[robot] : kAnyRateBound)
          << label;
      EXPECT_LT(q.worst, hold.worst) << label;
      EXPECT_EQ(q.clamped, 0) << label;
    }
    ++robot;
  }
}

// Irregular stamps and a 100 ms gap: the formula at the actual stamps (checkPeriod), the
// history restarted after the gap. dt is 1 ms +- 50% (nodes far from equally spaced) and
// +- 1%. The errors printed are not bounded: the filter's weights, so its noise gain and
// the exact covariance, change with every spacing (by about the jitter, sample to
// sample), and most with the gap inside the window; that, not the extrapolation, is most
// of the error (holding C_0 does about as badly). docs/studies/uncertainty.md gives the numbers.
TEST(CovariancePeriod, IrregularStampsAndAGap) {
  for (const std::string urdf : {"panda.urdf", "talos_reduced.urdf"}) {
    for (double jitter : {0.5, 0.01}) {
      std::vector<double> published;
      std::vector<std::vector<double>> var;
      std::vector<std::string> names;
      checkPeriod(urdf, Stamps::kIrregular, published, var, names, jitter);
      printErrors(urdf + " jitter " + std::to_string(jitter), published, var, names);
      // The gap: the history starts again, so every sample of the two periods after it is
      // computed (its three nodes a period apart), and the next one is extrapolated
      // (checkPeriod asserted that the estimator follows the schedule).
      const Schedule s = schedule(published, kDefaultPeriod);
      std::size_t after = 1;
      while (published[after] - published[after - 1] < 0.05) ++after;
      std::size_t b = after;
      for (; published[b] - published[after] < (2.0 - 1e-6) * kDefaultPeriod; ++b)
        EXPECT_LT(s.node_of[b], 0) << urdf;
      // The third node is the first sample a period after the second: extrapolation
      // resumes within the third period.
      bool resumed = false;
      for (; !resumed && published[b] - published[after] < 3.0 * kDefaultPeriod; ++b)
        resumed = s.node_of[b] >= 0;
      EXPECT_TRUE(resumed) << urdf;
    }
  }
}

// Inertial parameters: the propagated covariance against the loads of 10 000 models
// whose masses, centres of mass and inertias are drawn from the stated uncertainty,
// at the state the estimator held (the core's own passes on each perturbed model).
TEST(CovarianceMonteCarlo, InertialParametersTalos) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/talos_reduced.urdf");
  const jle::GroundTruth truth(model, jle::randomMotion(model, jle::MotionKind::kSines, 5.0, 3),
                               {jle::randomWrench("left_sole_link", 5)});
  jle::EstimatorConfig config;
  config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
  config.savings.reuse_unchanged = false;
  jle::WrenchInputConfig w;
  w.name = w.link = "left_sole_link";
  config.wrenches.push_back(w);
  config.uncertainty.enabled = true;
  config.uncertainty.period = 0.0;  // the propagation itself, at every sample
  config.uncertainty.mass_fraction = 0.1;
  config.uncertainty.com_offset = 0.01;
  config.uncertainty.inertia_fraction = 0.2;
  jle::Estimator estimator(model, config);
  Eigen::VectorXd q, qd, qdd;
  for (int k = 0; k < 20; ++k) {
    const double t = 1.0 + k * 1e-3;
    const Vector6 wr = truth.wrenches()[0].at(t);
    estimator.addWrench(0, t, wr.head<3>(), wr.tail<3>());
    truth.coordinates(t, q, qd, qdd);
    estimator.addJointSample(t, q.data());
  }
  // The same variances with only the 6 diagonal terms asked for.
  jle::EstimatorConfig diagonal = config;
  diagonal.uncertainty.diagonal_only = true;
  jle::Estimator estimator_diagonal(model, diagonal);
  for (int k = 0; k < 20; ++k) {
    const double t = 1.0 + k * 1e-3;
    const Vector6 wr = truth.wrenches()[0].at(t);
    estimator_diagonal.addWrench(0, t, wr.head<3>(), wr.tail<3>());
    truth.coordinates(t, q, qd, qdd);
    estimator_diagonal.addJointSample(t, q.data());
  }

  const jle::Wrench<double> applied = estimator.last().appliedWrench(0);
  const int frame = model.frameIndex("left_sole_link");
  const std::vector<int>& published = model.moving_segments;
  const std::size_t np = published.size();
  std::vector<Vector6> sum(np, Vector6::Zero());
  std::vector<Matrix6> sum2(np, Matrix6::Zero());
  jle::PortableRandom random(99);
  const int replays = 10000;
  jle::Model<double> perturbed = model;
  jle::Data<double> data(model);
  for (int r = 0; r < replays; ++r) {
    for (int i = 0; i < model.nsegments(); ++i) {
      perturbed.mass[i] = model.mass[i] * (1.0 + 0.1 * random.gaussian());
      for (int a = 0; a < 3; ++a) perturbed.com[i][a] = model.com[i][a] + 0.01 * random.gaussian();
      perturbed.inertia_com[i] = model.inertia_com[i] * (1.0 + 0.2 * random.gaussian());
    }
    jle::forwardKinematics(perturbed, data, estimator.last().q(), estimator.last().qd(),
                           estimator.last().qdd(), Eigen::Vector3d(0.0, 0.0, -9.80665));
    jle::addExternalWrench(perturbed, data, frame, applied.force, applied.moment,
                           jle::WrenchFrame::kLocal);
    jle::inverseDynamics(perturbed, data);
    for (std::size_t j = 0; j < np; ++j) {
      const int s = published[j];
      Vector6 d;
      d << data.force[s] - estimator.last().data().force[s],
          data.moment[s] - estimator.last().data().moment[s];
      sum[j] += d;
      sum2[j].noalias() += d * d.transpose();
    }
  }
  double worst = 0.0;
  for (std::size_t j = 0; j < np; ++j) {
    const int s = published[j];
    const Vector6 mean = sum[j] / replays;
    const Matrix6 empirical = sum2[j] / replays - mean * mean.transpose();
    const Matrix6& P = estimator.last().covariance(s);
    // diagonal_only: the same variances (same sums in another order: 1e-12 relative).
    for (int c = 0; c < 6; ++c)
      EXPECT_NEAR(estimator_diagonal.last().covariance(s)(c, c), P(c, c), 1e-12 * P(c, c) + 1e-300);
    EXPECT_EQ(estimator_diagonal.last().covariance(s)(0, 1), 0.0);
    const double top = P.diagonal().maxCoeff();
    for (int c = 0; c < 6; ++c) {
      if (P(c, c) <= 1e-9 * top) continue;  // zero in theory (see runMonteCarlo)
      const double ratio = empirical(c, c) / P(c, c);
      worst = std::max(worst, std::abs(ratio - 1.0));
      // 10%: over 7 standard errors of a variance from 10 000 samples (see runMonteCarlo);
      // the centre of mass enters the moment quadratically, which the propagation
      // linearises: with 1 cm offsets its neglected part is far below that.
      EXPECT_NEAR(ratio, 1.0, 0.10) << model.joint_name[s] << " component " << c;
    }
  }
  std::printf("inertial parameters (talos): worst |ratio - 1| = %.3f over %zu joints\n", worst, np);
}

}  // namespace

// The noise-gain guard: with jittery stamps (dt = 1 ms +- 1%, Savitzky-Golay: its weights,
// so its noise gain, change with every spacing) a sample whose gain moved by more than
// gain_tolerance since the last node is computed, not extrapolated. Bound: the
// extrapolation bound measured at 1 kHz, plus the nodes' own gain differences (each
// within the tolerance of its successor, so a variance off by up to the tolerance per
// node) carried by the quadratic's weights (|w0| + |w1| + |w2| <= 3 + 3 + 1 = 7 for up
// to a period ahead) and halved for sigma: + 3.5 x tolerance = 7% for 0.02. Without the
// guard the error reached 164% (docs/studies/uncertainty.md). With regular stamps the guard
// never fires: one sample in a period is computed.
TEST(CovariancePeriod, NoiseGainGuardFollowsJitteryStamps) {
  int robot = 0;
  for (const std::string urdf : {"panda.urdf", "talos_reduced.urdf"}) {
    const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/" + urdf);
    const jle::GroundTruth truth(model, jle::randomMotion(model, jle::MotionKind::kSines, 5.0, 31),
                                 {});
    for (double jitter : {0.0, 0.01}) {
      jle::EstimatorConfig config;
      config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
      config.savings.reuse_unchanged = false;
      config.uncertainty.enabled = true;
      config.uncertainty.position_noise = 1e-4;
      config.uncertainty.mass_fraction = 0.05;
      config.uncertainty.period = 0.0;
      jle::Estimator exact(model, config);
      config.uncertainty.period = kDefaultPeriod;
      jle::Estimator guarded(model, config);
      jle_test::Random rng(11);
      const jle_test::UniformIn dt(1e-3 * (1.0 - jitter), 1e-3 * (1.0 + jitter));
      Eigen::VectorXd q, qd, qdd;
      double worst = 0.0;
      long published = 0, equal = 0;
      for (double t = 0.0; t < 2.0; t += dt(rng)) {
        truth.coordinates(t, q, qd, qdd);
        const jle::SampleStatus s = exact.addJointSample(t, q.data());
        ASSERT_EQ(guarded.addJointSample(t, q.data()), s);
        if (s != jle::SampleStatus::kPublished) continue;
        ++published;
        bool same = true;
        for (int i : model.moving_segments) {
          const double ve = exact.last().effortVariance(i), vg = guarded.last().effortVariance(i);
          same = same && ve == vg;
          if (ve > 0.0) worst = std::max(worst, std::abs(std::sqrt(vg / ve) - 1.0));
        }
        equal += same;
      }
      std::printf("%s jitter %.2f: worst sigma error %.5f, %ld of %ld samples computed\n",
                  urdf.c_str(), jitter, worst, equal, published);
      EXPECT_LE(worst, kExtrapolationBound[robot] + 3.5 * config.uncertainty.gain_tolerance)
          << urdf << " jitter " << jitter;
      // Regular stamps: the guard never fires (one computed sample in 18, and the first).
      if (jitter == 0.0) {
        EXPECT_LT(equal, published / 10) << urdf;
      }
    }
    ++robot;
  }
}
