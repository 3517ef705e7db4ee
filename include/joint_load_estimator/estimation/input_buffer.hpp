// The samples of one wrench input (an F/T sensor, a force plate) between joint samples:
// a ring of timestamped 6-D values, read at a joint sample's time by linear
// interpolation, and the filtered wrench read back out of the filter bank. ROS-free.
#pragma once

#include <joint_load_estimator/filters/differentiation.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <vector>

namespace jle {

enum class StalePolicy : std::uint8_t;  // estimator.hpp

/// The latest samples of one 6-D input (force [N], moment [N m], in the input's own
/// frame), their staleness against a timeout, and the policy for a stale input. Memory
/// is allocated in the constructor only.
class InputBuffer {
 public:
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  /// Samples kept for the resampling.
  static constexpr int kHistory = 512;

  InputBuffer() = default;
  /// timeout [s]: a joint sample later than the newest sample by more than this finds the
  /// input stale; policy: what is read then (StalePolicy); max_hold [s]: with the hold
  /// policy, how long past the timeout the last value is held (zero after that).
  InputBuffer(double timeout, StalePolicy policy,
              double max_hold = std::numeric_limits<double>::infinity());

  /// A sample at time t [s]. Dropped (false) unless t is newer than the newest held and
  /// everything is finite.
  bool add(double t, const Vector6& value);
  /// The value at time t [s]: linear between the two samples around t, the newest past
  /// the newest, the oldest before the oldest, zero while there is no sample. No policy.
  Vector6 interpolate(double t) const;
  /// The value at time t [s] from the samples within half [s] of it: the line fitted to
  /// them (least squares) at t, where they lie on both sides of t (at least one at or
  /// before t, one after); else interpolate(t). A joint sample between slower F/T samples
  /// gets what lies around it, not one noisy point each (aliasing the sensor's noise).
  Vector6 centredAt(double t, double half) const;
  /// Whether a joint sample at time t [s] finds the input stale: no sample, or the newest
  /// older than the timeout.
  bool staleAt(double t) const;
  /// interpolate(t), or zero where zeroAt(t).
  Vector6 valueAt(double t) const;
  /// Whether the input reads as zero at t: stale under the kZero policy, or held past
  /// max_hold under kHold.
  bool zeroAt(double t) const;
  /// At the joint sample t [s]: valueAt(t) into out[0..6) and stale() updated. An input
  /// that no computed segment needs (needed false) is not read: out is left as it is and
  /// the input is not stale.
  /// half > 0: centredAt(t, half) instead of interpolate(t) (a delayed estimate, which has
  /// the samples after t).
  void resample(double t, bool needed, double* out, double half = 0.0);
  /// Whether the input was stale at the last resample() (true after a reset).
  bool stale() const { return stale_; }
  /// At the last resample(): the input read as zero (zeroAt).
  bool zeroed() const { return zeroed_; }
  /// Stale under the kStop policy: no loads may be published.
  bool stopped() const { return stale_ && stop_when_stale_; }
  /// Forgets every sample (a backward jump of time).
  void reset();

  double timeout() const { return timeout_; }
  /// Samples held, at most kHistory.
  int count() const { return count_; }

 private:
  // Index in the ring of the sample k steps before the newest.
  int ring(int k) const { return (head_ - 1 - k + 2 * kHistory) % kHistory; }

  double timeout_ = 0.1;
  bool zero_when_stale_ = false;                               // StalePolicy::kZero
  bool stop_when_stale_ = false;                               // StalePolicy::kStop
  double max_hold_ = std::numeric_limits<double>::infinity();  // StalePolicy::kHold
  bool zeroed_ = false;
  std::vector<double> times_;
  std::vector<Vector6> values_;
  int head_ = 0;
  int count_ = 0;
  bool stale_ = true;
};

/// The filtered wrench of the six bank channels channel..channel+5 (force, then moment)
/// at the bank's stamp: the value output, in the frame and units the samples were given.
inline Wrench<double> filteredWrench(const DifferentiatorBank& bank, int channel) {
  Wrench<double> w;
  w.force << bank.value(channel), bank.value(channel + 1), bank.value(channel + 2);
  w.moment << bank.value(channel + 3), bank.value(channel + 4), bank.value(channel + 5);
  return w;
}

}  // namespace jle
