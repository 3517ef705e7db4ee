#include <joint_load_estimator/estimation/input_buffer.hpp>

#include <joint_load_estimator/estimation/estimator.hpp>  // StalePolicy

#include <cmath>
#include <limits>

namespace jle {

InputBuffer::InputBuffer(double timeout, StalePolicy policy, double max_hold)
    : timeout_(timeout),
      zero_when_stale_(policy == StalePolicy::kZero),
      stop_when_stale_(policy == StalePolicy::kStop),
      max_hold_(policy == StalePolicy::kHold ? max_hold : std::numeric_limits<double>::infinity()),
      times_(kHistory, 0.0),
      values_(kHistory, Vector6::Zero()) {}

bool InputBuffer::add(double t, const Vector6& value) {
  if (!std::isfinite(t) || !value.allFinite()) return false;
  if (count_ > 0 && !(t > times_[ring(0)])) return false;
  times_[head_] = t;
  values_[head_] = value;
  head_ = (head_ + 1) % kHistory;
  if (count_ < kHistory) ++count_;
  return true;
}

InputBuffer::Vector6 InputBuffer::interpolate(double t) const {
  if (count_ == 0) return Vector6::Zero();
  if (t >= times_[ring(0)]) return values_[ring(0)];
  // Newest first: the bracketing pair is almost always the first or second.
  for (int k = 1; k < count_; ++k) {
    const int older = ring(k), newer = ring(k - 1);
    if (times_[older] <= t) {
      const double s = (t - times_[older]) / (times_[newer] - times_[older]);
      return (1.0 - s) * values_[older] + s * values_[newer];
    }
  }
  return values_[ring(count_ - 1)];  // older than all we hold
}

InputBuffer::Vector6 InputBuffer::centredAt(double t, double half) const {
  // Sums over the samples within half of t, newest first, in u = time - t.
  double n = 0.0, su = 0.0, suu = 0.0;
  Vector6 sx = Vector6::Zero(), sux = Vector6::Zero();
  bool before = false, after = false;
  for (int k = 0; k < count_; ++k) {
    const double u = times_[ring(k)] - t;
    if (u > half) continue;
    if (u < -half) break;
    (u > 0.0 ? after : before) = true;
    n += 1.0;
    su += u;
    suu += u * u;
    sx += values_[ring(k)];
    sux += u * values_[ring(k)];
  }
  const double det = n * suu - su * su;
  if (!before || !after || !(det > 0.0)) return interpolate(t);
  return (suu * sx - su * sux) / det;  // the line's intercept at u = 0
}

bool InputBuffer::staleAt(double t) const { return count_ == 0 || t - times_[ring(0)] > timeout_; }

bool InputBuffer::zeroAt(double t) const {
  if (!staleAt(t)) return false;
  return zero_when_stale_ || count_ == 0 || t - times_[ring(0)] > timeout_ + max_hold_;
}

InputBuffer::Vector6 InputBuffer::valueAt(double t) const {
  if (zeroAt(t)) return Vector6::Zero();
  return interpolate(t);
}

void InputBuffer::resample(double t, bool needed, double* out, double half) {
  if (!needed) {  // pruned away: never stale, never read
    stale_ = false;
    zeroed_ = false;
    return;
  }
  stale_ = staleAt(t);
  zeroed_ = zeroAt(t);
  const Vector6 value = zeroed_      ? Vector6::Zero()
                        : half > 0.0 ? centredAt(t, half)
                                     : interpolate(t);
  for (int j = 0; j < 6; ++j) out[j] = value[j];
}

void InputBuffer::reset() {
  head_ = 0;
  count_ = 0;
  stale_ = true;
  zeroed_ = !stop_when_stale_;
}

}  // namespace jle
