#include <joint_load_estimator/estimator.hpp>

#include <joint_load_estimator/kinematics.hpp>

#include <cmath>
#include <stdexcept>

namespace jle {
namespace {

constexpr int kWrenchHistory = 512;  // samples kept per wrench input for resampling

// Vector part of a quaternion product a * b.
Eigen::Vector3d productVector(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  // (w, x, y, z) layout.
  const Eigen::Vector3d av = a.tail<3>(), bv = b.tail<3>();
  return a[0] * bv + b[0] * av + av.cross(bv);
}

}  // namespace

const char* toString(SampleStatus status) {
  switch (status) {
    case SampleStatus::kPublished: return "published";
    case SampleStatus::kWarmingUp: return "warming up";
    case SampleStatus::kDecimated: return "decimated";
    case SampleStatus::kDuplicate: return "duplicate stamp";
    case SampleStatus::kOutOfOrder: return "out-of-order stamp";
    case SampleStatus::kNonFinite: return "non-finite value";
    case SampleStatus::kStale: return "stale wrench input";
  }
  return "?";
}

Estimator::Estimator(const Model<double>& model, const EstimatorConfig& config)
    : model_(model),
      config_(config),
      data_(model_),
      bank_(config.differentiator,
            model.nq + (model.floating_base ? 7 : 0) + 6 * static_cast<int>(config.wrenches.size())),
      q_(VectorX<double>::Zero(model.nq)),
      qd_(VectorX<double>::Zero(model.nq)),
      qdd_(VectorX<double>::Zero(model.nq)) {
  if (config_.decimation < 1) throw std::invalid_argument("decimation must be at least 1");
  if (!config_.gravity_world.allFinite()) throw std::invalid_argument("gravity is not finite");
  base_channel_ = model_.nq;
  wrench_channel_ = base_channel_ + (model_.floating_base ? 7 : 0);
  for (const WrenchInputConfig& c : config_.wrenches) {
    Input input;
    input.config = c;
    input.frame = model_.frameIndex(c.link);  // throws naming the link
    if (!(c.sign == 1.0 || c.sign == -1.0))
      throw std::invalid_argument("wrench input '" + c.name + "': sign must be +1 or -1");
    if (!(c.timeout > 0.0))
      throw std::invalid_argument("wrench input '" + c.name + "': timeout must be positive");
    input.times.assign(kWrenchHistory, 0.0);
    input.values.assign(kWrenchHistory, Eigen::Matrix<double, 6, 1>::Zero());
    inputs_.push_back(input);
  }
  channels_.assign(static_cast<std::size_t>(bank_.channels()), 0.0);
}

void Estimator::reset() {
  bank_.reset();
  for (Input& input : inputs_) {
    input.count = 0;
    input.head = 0;
    input.stale = true;
  }
  have_last_ = false;
  sample_count_ = 0;
}

bool Estimator::addWrench(int k, double t, const Eigen::Vector3d& force,
                          const Eigen::Vector3d& moment) {
  Input& input = inputs_.at(static_cast<std::size_t>(k));
  if (!std::isfinite(t) || !force.allFinite() || !moment.allFinite()) return false;
  if (input.count > 0) {
    const double newest = input.times[(input.head + kWrenchHistory - 1) % kWrenchHistory];
    if (!(t > newest)) return false;
  }
  input.times[input.head] = t;
  input.values[input.head] << input.config.sign * force, input.config.sign * moment;
  input.head = (input.head + 1) % kWrenchHistory;
  if (input.count < kWrenchHistory) ++input.count;
  return true;
}

Eigen::Matrix<double, 6, 1> Estimator::sampleInput(Input& input, double t) {
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  auto at = [&](int k) { return (input.head - 1 - k + 2 * kWrenchHistory) % kWrenchHistory; };
  if (input.count == 0) {
    input.stale = true;
    return Vector6::Zero();
  }
  const int newest = at(0);
  if (t >= input.times[newest]) {
    input.stale = t - input.times[newest] > input.config.timeout;
    if (input.stale && input.config.stale_policy == StalePolicy::kZero) return Vector6::Zero();
    return input.values[newest];
  }
  input.stale = false;
  // Newest first: the bracketing pair is almost always the first or second.
  for (int k = 1; k < input.count; ++k) {
    const int older = at(k), newer = at(k - 1);
    if (input.times[older] <= t) {
      const double s = (t - input.times[older]) / (input.times[newer] - input.times[older]);
      return (1.0 - s) * input.values[older] + s * input.values[newer];
    }
  }
  return input.values[at(input.count - 1)];  // older than all we hold
}

SampleStatus Estimator::addJointSample(double t, const double* q, const BasePose* base) {
  if (model_.floating_base && base == nullptr)
    throw std::invalid_argument("a floating-base model needs the base pose with each sample");
  if (!std::isfinite(t)) return SampleStatus::kNonFinite;
  for (int i = 0; i < model_.nq; ++i)
    if (!std::isfinite(q[i])) return SampleStatus::kNonFinite;
  if (base && !(base->position.allFinite() && base->orientation.coeffs().allFinite() &&
                base->orientation.norm() > 0.0))
    return SampleStatus::kNonFinite;
  if (have_last_) {
    if (t == last_t_) return SampleStatus::kDuplicate;
    if (t < last_t_) return SampleStatus::kOutOfOrder;
  }
  have_last_ = true;
  last_t_ = t;

  for (int i = 0; i < model_.nq; ++i) channels_[static_cast<std::size_t>(i)] = q[i];
  if (model_.floating_base) {
    // Quaternion components are smooth in time once the sign is kept continuous.
    Eigen::Quaterniond o = base->orientation.normalized();
    if (o.coeffs().dot(last_orientation_.coeffs()) < 0.0) o.coeffs() *= -1.0;
    last_orientation_ = o;
    double* b = &channels_[static_cast<std::size_t>(base_channel_)];
    b[0] = base->position.x();
    b[1] = base->position.y();
    b[2] = base->position.z();
    b[3] = o.w();
    b[4] = o.x();
    b[5] = o.y();
    b[6] = o.z();
  }
  for (std::size_t k = 0; k < inputs_.size(); ++k) {
    const Eigen::Matrix<double, 6, 1> w = sampleInput(inputs_[k], t);
    for (int j = 0; j < 6; ++j)
      channels_[static_cast<std::size_t>(wrench_channel_) + 6 * k + static_cast<std::size_t>(j)] = w[j];
  }
  // A gap restarts the bank inside update(); the decimation phase restarts with it.
  const bool ready = bank_.update(t, channels_.data());
  if (!ready) {
    sample_count_ = 0;
    return SampleStatus::kWarmingUp;
  }
  if (sample_count_++ % config_.decimation != 0) return SampleStatus::kDecimated;
  for (const Input& input : inputs_)
    if (input.stale && input.config.stale_policy == StalePolicy::kStop) return SampleStatus::kStale;

  stamp_ = bank_.stamp();
  for (int i = 0; i < model_.nq; ++i) {
    q_[i] = bank_.value(i);
    qd_[i] = bank_.rate(i);
    qdd_[i] = bank_.accel(i);
  }
  BaseState<double> base_state;
  if (model_.floating_base) {
    const int b = base_channel_;
    base_state.p_world_base << bank_.value(b), bank_.value(b + 1), bank_.value(b + 2);
    base_state.v_world << bank_.rate(b), bank_.rate(b + 1), bank_.rate(b + 2);
    base_state.a_world << bank_.accel(b), bank_.accel(b + 1), bank_.accel(b + 2);
    Eigen::Vector4d quat, quat_rate, quat_accel;
    for (int j = 0; j < 4; ++j) {
      quat[j] = bank_.value(b + 3 + j);
      quat_rate[j] = bank_.rate(b + 3 + j);
      quat_accel[j] = bank_.accel(b + 3 + j);
    }
    const double norm = quat.norm();
    quat /= norm;
    quat_rate /= norm;
    quat_accel /= norm;
    const Eigen::Vector4d conj(quat[0], -quat[1], -quat[2], -quat[3]);
    // q' = 1/2 w q  =>  w = 2 vec(q' q*);  alpha = 2 vec(q'' q*) (the rest is scalar).
    base_state.omega_world = 2.0 * productVector(quat_rate, conj);
    base_state.alpha_world = 2.0 * productVector(quat_accel, conj);
    base_state.R_world_base =
        Eigen::Quaterniond(quat[0], quat[1], quat[2], quat[3]).toRotationMatrix();
  }
  forwardKinematics(model_, data_, q_, qd_, qdd_, config_.gravity_world, base_state);
  for (std::size_t k = 0; k < inputs_.size(); ++k) {
    const std::size_t c = static_cast<std::size_t>(wrench_channel_) + 6 * k;
    const Eigen::Vector3d f(bank_.value(static_cast<int>(c)), bank_.value(static_cast<int>(c + 1)),
                            bank_.value(static_cast<int>(c + 2)));
    const Eigen::Vector3d m(bank_.value(static_cast<int>(c + 3)),
                            bank_.value(static_cast<int>(c + 4)),
                            bank_.value(static_cast<int>(c + 5)));
    addExternalWrench(model_, data_, inputs_[k].frame, f, m, WrenchFrame::kLocal);
  }
  inverseDynamics(model_, data_);
  return SampleStatus::kPublished;
}

Wrench<double> Estimator::appliedWrench(int k) const {
  Wrench<double> w;
  const int c = wrench_channel_ + 6 * k;
  w.force << bank_.value(c), bank_.value(c + 1), bank_.value(c + 2);
  w.moment << bank_.value(c + 3), bank_.value(c + 4), bank_.value(c + 5);
  return w;
}

}  // namespace jle
