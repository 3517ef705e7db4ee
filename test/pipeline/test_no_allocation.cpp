// No heap allocation per timestep: the global operator new of this test binary counts
// its calls, and the per-sample paths (the core passes, the estimator with every
// differentiator) must not add to the count once their buffers are built.
#include <joint_load_estimator/estimation/estimator.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
// GCC 12 at -O1 under the sanitizers (tools/sanitize.sh) inlines these into gtest's
// `new TestClass` and pairs their free() with the library's operator new, not the one
// above (-Wmismatched-new-delete): both are replaced here, malloc with free.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

namespace {

const std::string kData = JLE_TEST_DATA;

TEST(NoAllocation, CorePassesOnTalos) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/talos_reduced.urdf");
  jle::Data<double> data(model);
  Eigen::VectorXd q = Eigen::VectorXd::Constant(model.nq, 0.2), qd = q, qdd = q;
  const Eigen::Vector3d g(0, 0, -9.80665), f(1, 2, 3), m(0.1, 0.2, 0.3);
  const int sole = model.frameIndex("left_sole_link");
  ASSERT_GT(g_allocations.load(), 100);  // the counter sees the model being built
  const long before = g_allocations;
  for (int k = 0; k < 1000; ++k) {
    q[0] = 1e-3 * k;
    jle::forwardKinematics(model, data, q, qd, qdd, g);
    jle::addExternalWrench(model, data, sole, f, m, jle::WrenchFrame::kWorld);
    jle::inverseDynamics(model, data);
    const jle::Wrench<double> w = jle::jointWrench(model, data, 5, jle::WrenchFrame::kParent);
    ASSERT_TRUE(w.force.allFinite());
  }
  EXPECT_EQ(g_allocations - before, 0);
}

// Finite differences, Savitzky-Golay, the constant-acceleration and the constant-jerk
// Kalman filters, the default (the constant-jerk Kalman filter), the adaptive filter
// causal and with a lag of 0.2 s (the smoother whose bandwidth the record's spectrum
// chooses, every block's transforms and scores included).
std::vector<jle::DifferentiatorConfig> eachDifferentiator() {
  std::vector<jle::DifferentiatorConfig> filters(7);
  filters[0].type = jle::DifferentiatorType::kFiniteDifference;
  filters[1].type = jle::DifferentiatorType::kSavitzkyGolay;
  filters[2].type = jle::DifferentiatorType::kKalman;
  filters[2].kalman_model = jle::KalmanModel::kConstantAcceleration;
  filters[2].process_noise = 1e3;
  filters[3].type = jle::DifferentiatorType::kKalman;
  filters[5].type = jle::DifferentiatorType::kAdaptive;
  filters[6].type = jle::DifferentiatorType::kAdaptive;
  filters[6].lag = 0.2;
  return filters;
}

TEST(NoAllocation, EstimatorWithEachDifferentiator) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/chains/panda_chain.urdf");
  const std::vector<jle::DifferentiatorConfig> filters = eachDifferentiator();
  for (std::size_t f = 0; f < filters.size(); ++f) {
    jle::EstimatorConfig config;
    config.differentiator = filters[f];
    jle::WrenchInputConfig ft;
    ft.name = "ft";
    ft.link = "panda_hand";
    config.wrenches.push_back(ft);
    jle::Estimator estimator(model, config);
    std::vector<double> q(static_cast<std::size_t>(model.nq), 0.0);
    long published = 0;
    long before = 0;
    const int n = 7000;  // three of the spectral choice's blocks (2.048 s) after its first
    for (int k = 0; k < n; ++k) {
      if (k == 100) before = g_allocations;  // buffers built, filters warm
      // Jittered stamps: the filters recompute their weights at every sample.
      const double t = 1e-3 * k + 2e-4 * std::sin(k);
      for (std::size_t i = 0; i < q.size(); ++i) q[i] = 0.5 * std::sin(t + i);
      estimator.addWrench(0, t, Eigen::Vector3d(1, 0, -5), Eigen::Vector3d(0, 0.1, 0));
      published += estimator.addJointSample(t, q.data()) == jle::SampleStatus::kPublished;
    }
    EXPECT_EQ(g_allocations - before, 0) << "differentiator " << f;
    EXPECT_GT(published, n - 400);  // the smoother's 200 samples pending at the end
  }
}

// The covariance of the loads (every source, the state linearised) allocates nothing
// per sample either; nor does uncertainty.period (extrapolated between computations).
TEST(NoAllocation, EstimatorWithCovariance) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/panda.urdf");
  for (int variant = 0; variant < 3; ++variant) {
    const bool linearize = variant != 1;
    jle::EstimatorConfig config;
    config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
    jle::WrenchInputConfig ft;
    ft.name = ft.link = "panda_hand";
    ft.force_noise = 0.5;
    ft.moment_noise = 0.05;
    config.wrenches.push_back(ft);
    config.uncertainty.enabled = true;
    config.uncertainty.position_noise = 1e-4;
    config.uncertainty.mass_fraction = 0.05;
    config.uncertainty.com_offset = 0.005;
    config.uncertainty.inertia_fraction = 0.05;
    config.uncertainty.linearize_state = linearize;
    config.uncertainty.period = variant == 2 ? 4e-3 : 0.0;
    config.precision = linearize ? jle::Precision::kDouble : jle::Precision::kFloat;
    jle::Estimator estimator(model, config);
    std::vector<double> q(static_cast<std::size_t>(model.nq), 0.0);
    long before = 0;
    for (int k = 0; k < 500; ++k) {
      if (k == 100) before = g_allocations;
      const double t = 1e-3 * k + 2e-4 * std::sin(k);
      for (std::size_t i = 0; i < q.size(); ++i) q[i] = 0.5 * std::sin(t + i);
      estimator.addWrench(0, t, Eigen::Vector3d(1, 0, -5), Eigen::Vector3d(0, 0.1, 0));
      estimator.addJointSample(t, q.data());
    }
    EXPECT_EQ(g_allocations - before, 0)
        << "linearize_state " << linearize << ", period " << config.uncertainty.period;
    EXPECT_GT(estimator.last().covariance(model.moving_segments[0])(5, 5), 0.0);
  }
}

// savings.planar: the planar 3x3 path and its per-sample fallback to 6x6.
TEST(NoAllocation, EstimatorOnThePlanarPath) {
  const jle::Model<double> arm = jle::modelFromUrdfFile(kData + "/urdf/planar_arm.urdf");
  jle::EstimatorConfig c;
  c.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay;
  c.gravity_world = Eigen::Vector3d(0, -9.80665, 0);
  jle::WrenchInputConfig w;
  w.name = w.link = "tool";
  c.wrenches.push_back(w);
  jle::Estimator estimator(arm, c);
  ASSERT_TRUE(estimator.layout().planar());
  std::vector<double> q(static_cast<std::size_t>(arm.nq), 0.0);
  long before = 0, planar = 0;
  for (int k = 0; k < 2000; ++k) {
    if (k == 100) before = g_allocations;
    const double t = 1e-3 * k;
    for (std::size_t i = 0; i < q.size(); ++i) q[i] = 0.5 * std::sin(t + i);
    // Out of the plane for 10 samples: the fallback must not allocate either.
    estimator.addWrench(0, t, Eigen::Vector3d(1, 0, k >= 1900 && k < 1910 ? 1.0 : 0.0),
                        Eigen::Vector3d(0, 0, 0.1));
    if (estimator.addJointSample(t, q.data()) == jle::SampleStatus::kPublished)
      planar += estimator.last().planar();
  }
  EXPECT_EQ(g_allocations - before, 0);
  EXPECT_GT(planar, 1700);
}

// The message path the node takes (jle::Pipeline with both streams, a sensor's wrench
// messages, joint states with names, velocities and efforts, every record with its side
// outputs) allocates nothing per message once its buffers are built and filled.
TEST(NoAllocation, PipelineWithBothStreams) {
  jle::ModelOptions options;
  options.keep_fixed_joints = {"panda_joint8"};
  const jle::Model<double> model =
      jle::modelFromUrdfFile(kData + "/urdf/chains/panda_chain.urdf", options);
  jle::Settings settings;  // both streams by default
  jle::WrenchInputConfig ft;
  ft.name = "ft";
  ft.sensor_joint = "panda_joint8";
  settings.estimator.wrenches.push_back(ft);
  jle::WrenchTopicSettings topic;
  topic.topic = "ft";
  settings.wrenches.push_back(topic);
  ASSERT_TRUE(settings.smoothed.enabled);
  jle::Pipeline pipeline(model, settings, nullptr);
  const std::vector<std::string> names = model.coordinate_names;
  std::vector<double> q(names.size()), qd(names.size()), effort(names.size());
  const std::string frame = "panda_link8";
  long published = 0, smoothed = 0, before = 0;
  const int n = 3000;
  for (int k = 0; k < n; ++k) {
    if (k == 1000) before = g_allocations;  // buffers built, both streams' filters warm
    const double t = 1e-3 * k + 2e-4 * std::sin(k);
    const jle::Stamp stamp = 1700000000000000000 + static_cast<jle::Stamp>(std::llround(1e9 * t));
    for (std::size_t i = 0; i < q.size(); ++i) {
      q[i] = 0.5 * std::sin(t + i);
      qd[i] = 0.5 * std::cos(t + i);
      effort[i] = 0.1 * i;
    }
    pipeline.onWrench(0, stamp, stamp, frame, Eigen::Vector3d(1, 0, -5),
                      Eigen::Vector3d(0, 0.1, 0));
    published +=
        pipeline.onJointState(stamp, stamp, names, q, qd, effort) == jle::Outcome::kPublished;
    while (pipeline.takeDrained()) ++published;
    smoothed += pipeline.smoothedPublished();
    while (pipeline.takeDrainedSmoothed()) ++smoothed;
  }
  EXPECT_EQ(g_allocations - before, 0);
  EXPECT_GT(published, n - 50);
  EXPECT_GT(smoothed, n - 300);  // 0.2 s pending at the end
  EXPECT_TRUE(pipeline.record().inputs[0].used);
}

// Joint states split over two publishers (four joints and two, at one stamp: merged into
// one sample) alternate between two layouts of names: each bound once, then no
// allocation either. (One cached layout, rebound at every message, allocated the names
// longer than a string's small buffer beyond the shorter layout's end at every instant.)
TEST(NoAllocation, PipelineWithSplitPublishers) {
  const jle::Model<double> model = jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf");
  jle::Pipeline pipeline(model, jle::Settings(), nullptr);
  // The publishers' own orders; the names longer than a string's small buffer
  // (shoulder_pan_joint, shoulder_lift_joint) past the shorter layout's end.
  const std::vector<std::string> a = {"elbow_joint", "wrist_1_joint", "shoulder_pan_joint",
                                      "shoulder_lift_joint"},
                                 b = {"wrist_2_joint", "wrist_3_joint"};
  std::vector<double> qa(a.size()), qb(b.size());
  const std::vector<double> none;
  long published = 0, before = 0;
  const int n = 3000;
  for (int k = 0; k < n; ++k) {
    if (k == 1000) before = g_allocations;
    const double t = 1e-3 * k;
    const jle::Stamp stamp = 1700000000000000000 + static_cast<jle::Stamp>(std::llround(1e9 * t));
    for (std::size_t i = 0; i < qa.size(); ++i) qa[i] = 0.5 * std::sin(t + i);
    for (std::size_t i = 0; i < qb.size(); ++i) qb[i] = 0.5 * std::sin(t + 4 + i);
    pipeline.onJointState(stamp, stamp, a, qa, none, none);
    while (pipeline.takeDrained()) ++published;
    published += pipeline.onJointState(stamp, stamp, b, qb, none, none) == jle::Outcome::kPublished;
    while (pipeline.takeDrained()) ++published;
  }
  EXPECT_EQ(g_allocations - before, 0);
  EXPECT_GT(published, n - 50);
  EXPECT_EQ(pipeline.counters().held_samples, 0);
}

}  // namespace
