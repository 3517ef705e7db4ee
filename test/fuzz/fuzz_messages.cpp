// libFuzzer target: the node's message path without ROS. The fuzz bytes decode into a
// stream of JointState-like messages (names from a small alphabet with unknown and
// repeated ones, NaN / inf / huge values, empty and mismatched arrays, duplicate and
// backward stamps), wrench samples and resets, fed like the node feeds them: the size
// checks of EstimatorNode::onJointState, jle::JointStateMap, then
// jle::Estimator::addJointSample / addWrench. Checks the documented status of every
// sample (kNonFinite, kDuplicate, kOutOfOrder against a shadow of the last accepted
// stamp). Built by build_and_run.sh.
#include <joint_load_estimator/estimator.hpp>
#include <joint_load_estimator/ros/message_inputs.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

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
  // A value from a table of the interesting ones, or the next 8 bytes as a double.
  double value() {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    static const double kTable[] = {0.0,   0.1,  -0.5,  1.0,    3.14159, -2.0,   1e-300,
                                    1e300, -1e300, 1e6, -0.0,  kInf,    -kInf,
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

const char* const kNames[] = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                              "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint",
                              "wrist_3_link-tool0_fixed_joint",  // fixed: not a coordinate
                              "unknown_joint",      "",            "elbow_joint "};
constexpr std::size_t kNameCount = sizeof kNames / sizeof kNames[0];

const jle::Model<double>& model() {
  static const jle::Model<double> m =
      jle::modelFromUrdfFile(JLE_FUZZ_DATA "/urdf/chains/ur5_chain.urdf");
  return m;
}

// An oracle failure: names the check, then aborts (the fuzzer's crash).
#define JLE_FUZZ_CHECK(ok) \
  do { \
    if (!(ok)) { \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #ok); \
      std::abort(); \
    } \
  } while (false)

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Bytes in(data, size);
  const jle::Model<double>& m = model();

  // The configuration from the first bytes.
  jle::EstimatorConfig config;
  const std::uint8_t c0 = in.byte();
  switch (c0 % 3) {
    case 0: config.differentiator.type = jle::DifferentiatorType::kSavitzkyGolay; break;
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
  if (config.differentiator.type == jle::DifferentiatorType::kSavitzkyGolay) {
    config.differentiator.window = 5;
    config.differentiator.delay = (c0 >> 2) % 3;
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

  std::unique_ptr<jle::Estimator> estimator;
  try {
    estimator = std::make_unique<jle::Estimator>(m, config);
  } catch (const std::invalid_argument&) {
    return 0;  // a configuration the estimator refuses (documented)
  }
  jle::JointStateMap map(m, jle::publishedSegments(m, config.joints));

  double t = 100.0;
  double last_accepted = 0.0;
  bool have_last = false;
  double last_wrench = -std::numeric_limits<double>::infinity();
  bool have_wrench = false;
  std::vector<std::string> names;
  std::vector<double> position, effort;

  for (int op = 0; op < 400 && !in.empty(); ++op) {
    const std::uint8_t kind = in.byte();
    // The time step of this message.
    switch (in.byte() % 8) {
      case 0: break;             // duplicate stamp
      case 1: t -= 0.01; break;  // backward
      case 2: t += 1.0; break;   // a gap: the filters restart
      case 3: t = in.value(); break;
      default: t += 0.002 * (1 + in.byte() % 8); break;
    }
    if (kind % 8 == 7) {
      estimator->reset();  // forgets the joint and the wrench history
      have_last = false;
      have_wrench = false;
      continue;
    }
    if (kind % 8 == 6) {  // a wrench sample
      Eigen::Vector3d f, mo;
      for (int i = 0; i < 3; ++i) f[i] = in.value();
      for (int i = 0; i < 3; ++i) mo[i] = in.value();
      const bool taken = estimator->addWrench(0, t, f, mo);
      const bool valid = std::isfinite(t) && f.allFinite() && mo.allFinite() &&
                         (!have_wrench || t > last_wrench);
      JLE_FUZZ_CHECK(taken == valid);
      if (taken) {
        last_wrench = t;
        have_wrench = true;
      }
      continue;
    }
    // A joint-state message.
    const std::size_t n = in.byte() % 9;
    names.resize(n);
    for (std::string& s : names) s = kNames[in.byte() % kNameCount];
    const std::uint8_t shape = in.byte();
    std::size_t np = n, ne = (shape & 1) ? n : 0;
    if ((shape & 6) == 2) np = n + 1;
    if ((shape & 6) == 4 && n > 0) np = n - 1;
    if ((shape & 24) == 8) ne = n + 2;
    position.resize(np);
    effort.resize(ne);
    for (double& v : position) v = (shape & 32) ? in.value() : 0.1 * (in.byte() % 32);
    for (double& v : effort) v = in.value();

    // EstimatorNode::onJointState: sizes, then finiteness, are checked before anything.
    if (position.size() != n || (!effort.empty() && effort.size() != n)) continue;
    bool finite = true;
    for (double v : position) finite = finite && std::isfinite(v);
    for (double v : effort) finite = finite && std::isfinite(v);
    if (!finite && !(shape & 64)) continue;  // else: let the estimator see it

    const int unknown = map.update(names, position, effort);
    JLE_FUZZ_CHECK(unknown >= -1 && unknown < static_cast<int>(n));
    if (unknown >= 0) {
      const std::string& u = names[static_cast<std::size_t>(unknown)];
      JLE_FUZZ_CHECK(u == "unknown_joint" || u.empty() || u == "elbow_joint " ||
            u == "wrist_3_link-tool0_fixed_joint");
    }
    JLE_FUZZ_CHECK(map.q().size() == static_cast<std::size_t>(m.nq));
    if (map.firstMissing() >= 0) continue;

    bool q_finite = true;
    for (double v : map.q()) q_finite = q_finite && std::isfinite(v);
    const jle::SampleStatus status = estimator->addJointSample(t, map.q().data());
    if (!std::isfinite(t) || !q_finite) {
      JLE_FUZZ_CHECK(status == jle::SampleStatus::kNonFinite);
      continue;
    }
    JLE_FUZZ_CHECK(status != jle::SampleStatus::kNonFinite);
    if (have_last && t == last_accepted) {
      JLE_FUZZ_CHECK(status == jle::SampleStatus::kDuplicate);
      continue;
    }
    if (have_last && t < last_accepted) {
      JLE_FUZZ_CHECK(status == jle::SampleStatus::kOutOfOrder);
      continue;
    }
    JLE_FUZZ_CHECK(status != jle::SampleStatus::kDuplicate && status != jle::SampleStatus::kOutOfOrder);
    have_last = true;
    last_accepted = t;
    if (status == jle::SampleStatus::kPublished) {
      JLE_FUZZ_CHECK(std::isfinite(estimator->stamp()) && estimator->stamp() <= t);
      JLE_FUZZ_CHECK(estimator->q().size() == m.nq);
    }
  }
  return 0;
}
