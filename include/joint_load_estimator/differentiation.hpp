// Online estimation of a signal's value, rate and second derivative from its samples:
// Savitzky-Golay fits (finite differences are the smallest of them) and Kalman filters.
// A bank filters many channels that share their sample times (all the joints of one
// JointState, the components of the wrenches resampled at the same stamps) at the cost
// of one set of coefficients.
#pragma once

#include <joint_load_estimator/bandwidth_selection.hpp>
#include <joint_load_estimator/eigen_abi.hpp>
#include <joint_load_estimator/spectral_cutoff.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Householder>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace jle {

enum class DifferentiatorType : std::uint8_t {
  kFiniteDifference,  ///< exact through order+1 points (3-point, 2nd order by default)
  kSavitzkyGolay,     ///< least-squares polynomial of `order` over `window` samples
  kKalman,            ///< white-noise acceleration or jerk model
  /// Kalman filters of `kalman_model` on a grid of bandwidths, the one whose innovations
  /// are the likeliest over the recent samples selected, the noise estimated online
  /// (bandwidth_selection.hpp).
  kAdaptive,
};

enum class KalmanModel : std::uint8_t {
  kConstantAcceleration,  ///< state (x, x', x''), white noise on x'''
  kConstantJerk,          ///< state (x, x', x'', x'''), white noise on x''''
};

/// The default is what the node runs (config/default.yaml): the constant-jerk Kalman
/// filter, its default process noise 1e4 (processNoise()), measurement noise 1e-4 rad. The adaptive
/// filter is an option: better on the accuracy study's scenes of real logs, worse on clean ones,
/// and its noise gain understates the q'' noise (README "Differentiators").
struct DifferentiatorConfig {
  DifferentiatorType type = DifferentiatorType::kKalman;
  /// Savitzky-Golay: samples in the fit and degree of the polynomial (2..5). The
  /// estimate describes the sample `delay` steps before the newest: 0 is causal,
  /// (window - 1) / 2 is centred. Finite differences use window = order + 1.
  int window = 9;
  int order = 2;
  int delay = 0;
  /// Kalman: spectral density of the white noise driving the highest derivative
  /// [unit^2 / s^(2n-1)] (0: the model's default, processNoise()), and standard
  /// deviation of the position measurement [unit].
  KalmanModel kalman_model = KalmanModel::kConstantJerk;
  double process_noise = 0.0;
  double measurement_noise = 1e-4;
  /// Kalman: delay [s] of the smoothed estimate behind the newest sample's stamp (0: the
  /// causal filter). With lag > 0 the filter runs forward as with 0 and remembers its
  /// states; the estimate of a sample is made once the newest stamp is `lag` after its
  /// own, within h (the median of the last 5 intervals): the sample nearest to newest -
  /// lag, kept from sample to sample while within h of it, so that at a steady rate each
  /// sample makes one estimate (at jittered stamps: within h plus the intervals' spread;
  /// where the rate drops or after a gap, the samples made overdue are due at once, up to
  /// the nearest: DifferentiatorBank::next()). A Rauch-Tung-Striebel backward pass from the newest
  /// sample smooths the next B estimates with the data that followed them, B half the
  /// samples pending (about two backward steps per sample). At least n samples (3 or 4,
  /// the model's state) follow an estimated sample: a lag shorter than n intervals is n.
  /// Adaptive: the same smoother, its process noise the selected filter's at each sample.
  double lag = 0.0;
  /// Kalman with a lag: the smoother's bandwidth set from the data (true): where the
  /// joint positions' spectrum so far meets its noise floor (SpectralCutoff::Rule::
  /// kNoiseFloor, as the offline zero-phase rule: coloured noise is not taken for motion;
  /// 2 s blocks, from the second one on), at least kLagFloor / lag; where the spectrum
  /// shows no floor (data without noise), the highest cutoff (max_bandwidth, at most 0.45
  /// of the rate, averaged to 500 Hz); as the process noise r^2 h (2 pi f)^(2n) (r
  /// measurement_noise, h the recent interval: the smoother's gain is 1/2 at f, as the
  /// zero-phase Butterworth of order n's at its cutoff), process_noise until the first
  /// choice. false: process_noise throughout.
  bool auto_bandwidth = false;
  /// Adaptive: the bandwidths [Hz] its filters span (the crossover of signal and noise
  /// spectra; log-spaced by kBandwidthRatio), and the standard deviation of the position
  /// noise [unit] if known (0: estimated online from the innovations), and the time
  /// constant [s] of the likelihood that selects the bandwidth.
  double min_bandwidth = 0.5;
  double max_bandwidth = 50.0;
  double noise = 0.0;
  double memory = 1.0;
  /// A gap between samples longer than this [s] restarts the filter (its memory no
  /// longer describes the signal).
  double max_gap = 0.5;
};

/// The process noise the Kalman filter of `c` runs with: c.process_noise, or where it is
/// 0 the model's default: 1e4 for constant jerk [unit^2/s^7], 10 for constant
/// acceleration [unit^2/s^5]. Both put the bandwidth (q / r^2)^(1 / (2n)) at 31.6 rad/s
/// with the default r = 1e-4; measured (accuracy study, 21 scenes, r = 1e-4): constant
/// acceleration with q = 10 is within 1.30x of its best q per scene on geometric mean
/// (2.12x at worst), where 1e4 was 5.3x (36.6x).
inline double processNoise(const DifferentiatorConfig& c) {
  constexpr double kConstantJerk = 1e4, kConstantAcceleration = 10.0;
  if (c.process_noise > 0.0) return c.process_noise;
  return c.kalman_model == KalmanModel::kConstantAcceleration ? kConstantAcceleration
                                                              : kConstantJerk;
}

/// Whether two configurations make the same filter (every field equal).
inline bool sameDifferentiator(const DifferentiatorConfig& a, const DifferentiatorConfig& b) {
  return a.type == b.type && a.window == b.window && a.order == b.order && a.delay == b.delay &&
         a.kalman_model == b.kalman_model && processNoise(a) == processNoise(b) &&
         a.measurement_noise == b.measurement_noise && a.lag == b.lag &&
         a.auto_bandwidth == b.auto_bandwidth && a.min_bandwidth == b.min_bandwidth &&
         a.max_bandwidth == b.max_bandwidth && a.noise == b.noise && a.memory == b.memory &&
         a.max_gap == b.max_gap;
}

/// Checks a configuration once (the bank on construction, validate(EstimatorConfig) in
/// config.hpp); throws std::invalid_argument naming the parameter as config/default.yaml
/// spells it ("parameter 'differentiator/order' must be 2..5 ...").
inline void validate(const DifferentiatorConfig& c) {
  constexpr double kMaxLag = 10.0;  // [s] a smoother's delay: beyond it, an offline job
  const auto fail = [](const char* key, const std::string& what) {
    throw std::invalid_argument(std::string("parameter 'differentiator/") + key + "' " + what);
  };
  if (c.type == DifferentiatorType::kAdaptive) {
    if (!(c.min_bandwidth > 0.0) || !std::isfinite(c.min_bandwidth))
      fail("min_bandwidth", "must be finite and > 0 [Hz]");
    if (!(c.max_bandwidth >= c.min_bandwidth) || !std::isfinite(c.max_bandwidth))
      fail("max_bandwidth", "must be finite and >= min_bandwidth [Hz]");
    if (!(c.noise >= 0.0) || !std::isfinite(c.noise))
      fail("noise", "must be finite and >= 0 (0: estimated online)");
    if (!(c.memory > 0.0) || !std::isfinite(c.memory)) fail("memory", "must be finite and > 0 [s]");
    if (!(c.lag >= 0.0) || !(c.lag <= kMaxLag))
      fail("lag", "must be 0..10 [s] (0: the causal filter)");
  } else if (c.type == DifferentiatorType::kKalman) {
    if (!(c.process_noise >= 0.0) || !std::isfinite(c.process_noise))
      fail("process_noise", "must be finite and >= 0 (0: the model's default)");
    if (!(c.measurement_noise > 0.0) || !std::isfinite(c.measurement_noise))
      fail("measurement_noise", "must be finite and > 0");
    if (!(c.lag >= 0.0) || !(c.lag <= kMaxLag))
      fail("lag", "must be 0..10 [s] (0: the causal filter)");
    if (c.auto_bandwidth && (!(c.min_bandwidth > 0.0) || !std::isfinite(c.min_bandwidth)))
      fail("min_bandwidth", "must be finite and > 0 [Hz]");
    if (c.auto_bandwidth &&
        (!(c.max_bandwidth >= c.min_bandwidth) || !std::isfinite(c.max_bandwidth)))
      fail("max_bandwidth", "must be finite and >= min_bandwidth [Hz]");
  } else {
    if (c.lag != 0.0) fail("lag", "applies to types kalman and adaptive only (it must be 0)");
    if (c.order < 2 || c.order > 5)
      fail("order", "must be 2..5 (a second derivative needs a quadratic), it is " +
                        std::to_string(c.order));
    const int window = c.type == DifferentiatorType::kFiniteDifference ? c.order + 1 : c.window;
    if (window < c.order + 1 || window > 101)
      fail("window", "must be order+1..101, it is " + std::to_string(c.window));
    if (c.delay < 0 || c.delay >= window)
      fail("delay", "must be 0..window-1, it is " + std::to_string(c.delay));
  }
  if (!(c.max_gap > 0.0) || !std::isfinite(c.max_gap))
    fail("max_gap", "must be finite and > 0 [s]");
}

/// A bank of identical filters over `channels` signals sampled at common times.
/// update() takes the newest sample; after it returns true, stamp() is the time the
/// estimate describes (earlier than the newest sample by the configured delay) and
/// value/rate/accel(c) the estimate for channel c. Memory is allocated in the
/// constructor only. Times must increase: the caller resets on a backward jump and
/// drops duplicates (update() refuses them).
class DifferentiatorBank {
 public:
  static constexpr int kMaxOrder = 5;
  /// Adaptive: ratio of neighbouring bandwidths of its filters.
  static constexpr double kBandwidthRatio = 2.0;
  /// Adaptive with a lag: its smoother's bandwidth is at least kLagFloor / lag [Hz]: a
  /// narrower smoother's response is longer than the lag (measured: docs/differentiators.md).
  static constexpr double kLagFloor = 1.4;
  /// The record's GCV choice is used where kLagFloor / lag is at most this [Hz] (lag >=
  /// 0.14 s); with a shorter lag the likelihood's choice, measured better there.
  static constexpr double kHighestFloor = 10.0;
  /// auto_bandwidth: the blocks [s] of the probe that looks, until the spectrum's first
  /// choice (its second 2 s block), for data without noise: where a block's spectrum
  /// falls throughout (SpectralCutoff::fallsThroughout), the highest bandwidth from the
  /// probe's first block on (leg_running_200hz: 5.1 s of process_noise's 7.3 Hz cost
  /// 4.6x the best at the delay, now 1.1x; from its second block on, 1.7x); any other
  /// choice from so short a block (the motion's leakage hides a floor) is not taken.
  static constexpr double kProbeSeconds = 0.5;
  using SmallMatrix =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxOrder + 1, kMaxOrder + 1>;

  DifferentiatorBank(const DifferentiatorConfig& config, int channels)
      : config_(config), channels_(channels) {
    validate(config_);
    if (config_.type == DifferentiatorType::kFiniteDifference) {
      config_.window = config_.order + 1;
    }
    if (config_.type == DifferentiatorType::kKalman ||
        config_.type == DifferentiatorType::kAdaptive) {
      n_ = config_.kalman_model == KalmanModel::kConstantAcceleration ? 3 : 4;
      config_.window = 1;
      config_.delay = 0;
      state_.setZero(n_, channels_);
      P_.setZero(n_, n_);
      innovation_.setZero(channels_);
      if (config_.type == DifferentiatorType::kAdaptive) buildModels();
      if (config_.type == DifferentiatorType::kAdaptive && config_.lag > 0.0) buildSmoother();
      if (autoBandwidth()) chooseBandwidthFrom(channels_);
      if (smoothing()) allocateRing(1);
    } else {
      n_ = config_.order + 1;
      coeff_.setZero(3, config_.window);
      tau_prev_.setConstant(config_.window, std::nan(""));
    }
    times_.setZero(config_.window);
    values_.setZero(config_.window, channels_);
    out_.setZero(3, channels_);
  }

  const DifferentiatorConfig& config() const { return config_; }
  int channels() const { return channels_; }
  /// Samples needed after a reset before the first estimate (a smoother: lag over the
  /// recent interval, plus one, at least n + 1; before its second sample that of the
  /// causal filter).
  int warmup() const {
    if (delegating()) return smoother_.front().warmup();
    if (smoothing() && spacing_ > 0.0)
      return std::max(n_ + 1, static_cast<int>(std::lround(config_.lag / spacing_)) + 1);
    return isKalman() ? n_ : config_.window;
  }
  /// Samples the estimate describes behind the newest: Savitzky-Golay's `delay`, 0 for
  /// the causal filters; a smoother's pending(): the samples after its last estimate
  /// (lag over the interval at a steady rate), and an upper bound of the delay of any
  /// estimate still to come (before the first estimate: the samples taken).
  int delaySamples() const {
    if (delegating()) return smoother_.front().delaySamples();
    return smoothing() ? pending() : config_.delay;
  }
  /// Smoother: samples taken and not yet estimated. After update() returned true, next()
  /// makes the next one due at the same newest sample the estimate (true; false when
  /// none is): several are due at once where the rate drops or after a gap; one not
  /// taken is the estimate of a later update(), in order. finish() smooths them all with
  /// the data there is, after which each call of next() (true while one is left) makes
  /// the oldest of them the estimate (stamp(), value(), ...): the end of a stream.
  /// update() after finish() is a fresh start. A gap (max_gap) smooths the samples
  /// before it alike; they are estimated first, each when due by its stamp, then those
  /// after it: every sample is estimated once, in order.
  int pending() const {
    if (delegating()) return smoother_.front().pending();
    const int own = smoothing() && count_ > 0 ? index_ + 1 - emitted_ : 0;
    return own + carry_count_ - carry_next_;
  }
  void finish() {
    if (delegating()) smoother_.front().finish();
    if (finishing_ || !smoothing()) return;
    if (count_ > 0 && emitted_ <= index_) smoothBack(index_, emitted_, index_);
    smoothed_through_ = index_;
    finishing_ = true;
  }
  bool next() {
    if (delegating()) return takeSmoothed(smoother_.front().next());
    if (!finishing_) return smoothing() && taken_ > 0 && emitDue();
    if (emitCarry()) return true;
    if (count_ == 0 || emitted_ > index_) return false;
    emitSmoothed();
    return true;
  }

  void reset() {
    carry_count_ = carry_next_ = 0;
    recent_count_ = 0;
    spacing_ = 0.0;
    for (DifferentiatorBank& s : smoother_) s.reset();
    resetFilter();
  }

 private:
  void resetFilter() {
    count_ = 0;
    index_ = -1;
    emitted_ = 0;
    finishing_ = false;
    smoothed_through_ = -1;
    taken_ = 0;
    running_ = catching_up_ = false;
    pass_newest_ = emitted_steps_ = 0;
    emitted_carried_ = false;
    smoothed_gains_valid_ = false;
    head_ = 0;
    if (!isKalman()) tau_prev_.setConstant(std::nan(""));
    dt_prev_ = -1.0;  // a restarted filter is a fresh one, to the bit: no cached F, Q
    for (DifferentiatorBank& m : models_) m.reset();
    selection_.reset();
    spectral_.endBlock();
    probe_.endBlock();
  }

  // A gap: the smoother's pending estimates (and those still carried) into the carry,
  // and a fresh filter.
  void restart() {
    if (smoothing() && pending() > 0) {
      finish();
      const int left = carry_count_ - carry_next_;
      for (int k = 0; k < left; ++k) {
        carry_.col(k) = carry_.col(carry_next_ + k);
        carry_gains_.col(k) = carry_gains_.col(carry_next_ + k);
        carry_times_[k] = carry_times_[carry_next_ + k];
        carry_newest_[k] = carry_newest_[carry_next_ + k];
      }
      carry_count_ = left;
      carry_next_ = 0;
      const int total = left + (count_ > 0 ? index_ + 1 - emitted_ : 0);
      if (carry_.cols() < total) {
        carry_.conservativeResize(3 * channels_, total);
        carry_gains_.conservativeResize(9, total);
        carry_times_.conservativeResize(total);
        carry_newest_.conservativeResize(total);
      }
      while (count_ > 0 && emitted_ <= index_) {
        emitSmoothed();
        carry_.col(carry_count_) = Eigen::Map<const Eigen::VectorXd>(out_.data(), 3 * channels_);
        const Eigen::Matrix3d gain = smoothedNoiseGain();
        carry_gains_.col(carry_count_) = Eigen::Map<const Eigen::VectorXd>(gain.data(), 9);
        carry_newest_[carry_count_] = newest_used_;
        carry_times_[carry_count_++] = stamp_;
      }
    }
    resetFilter();
  }

  // The oldest carried estimate, if any, as the estimate.
  bool emitCarry() {
    if (carry_next_ >= carry_count_) return false;
    out_ = Eigen::Map<const Eigen::MatrixXd>(carry_.col(carry_next_).data(), 3, channels_);
    carried_gain_ = Eigen::Map<const Eigen::Matrix3d>(carry_gains_.col(carry_next_).data());
    emitted_carried_ = true;
    newest_used_ = carry_newest_[carry_next_];
    stamp_ = carry_times_[carry_next_++];
    if (carry_next_ == carry_count_) carry_count_ = carry_next_ = 0;
    return true;
  }

 public:
  /// Adaptive: the bandwidth [Hz] of the filter in use (with a lag of 0.14 s or more,
  /// the smoother's: SpectralCutoff's choice), and the position noise's
  /// standard deviation [unit] of channel c it assumes (estimated or given; 0 before the
  /// first estimate).
  /// auto_bandwidth: the smoother's bandwidth (where its gain is 1/2) [Hz]: the data's
  /// choice (chooseNoise), before it process_noise's at the recent interval (0 before
  /// an interval).
  double bandwidth() const {
    if (autoBandwidth() && auto_bandwidth_ > 0.0) return auto_bandwidth_;
    if (autoBandwidth()) return spacing_ > 0.0 ? bandwidthOf(config_.process_noise, spacing_) : 0.0;
    if (delegating() && spectral_.bandwidth() > 0.0) return spectral_.bandwidth();
    return bandwidths_.empty() ? 0.0 : bandwidths_[selection_.selected()];
  }
  double noise(int c) const {
    return models_.empty() ? 0.0 : std::sqrt(selection_.noiseVariance(c));
  }
  /// auto_bandwidth: the positions' spectrum's last choice [Hz] (0 before the first), and
  /// its noise floor [unit^2] (SpectralCutoff::floorLevel: 0 where none was found).
  double spectralCutoff() const { return autoBandwidth() ? spectral_.cutoff() : 0.0; }
  double noiseFloor() const { return autoBandwidth() ? spectral_.floorLevel() : 0.0; }
  /// auto_bandwidth: the process noise is only ever raised above process_noise's, never
  /// lowered (true), or set from the data both ways (false, the default). The measured
  /// velocities' filter raises only: a rate's spectrum falls more slowly than a
  /// position's, and its crossing of the floor from a block or two lies below the rate's
  /// bandwidth (accuracy study: arm_noise_1e-3, 1.46x -> 1.57x of the best when lowered).
  void raiseOnly(bool raise_only) { raise_only_ = raise_only; }
  /// Adaptive with a lag: only the first `channels` channels (e.g. the joint positions,
  /// not the wrenches filtered alike) choose the smoother's bandwidth. All by default.
  void chooseBandwidthFrom(int channels) {
    if (autoBandwidth()) {
      spectral_ = SpectralCutoff(std::min(channels, channels_), config_.min_bandwidth,
                                 config_.max_bandwidth, SpectralCutoff::Rule::kNoiseFloor);
      probe_ = SpectralCutoff(std::min(channels, channels_), config_.min_bandwidth,
                              config_.max_bandwidth, SpectralCutoff::Rule::kNoiseFloor,
                              kProbeSeconds, true);
      return;
    }
    if (!delegating()) return;
    const double floor = kLagFloor / config_.lag;
    spectral_ = SpectralCutoff(floor <= kHighestFloor ? std::min(channels, channels_) : 0,
                               std::max(config_.min_bandwidth, floor), config_.max_bandwidth);
  }

  /// Adds the sample (t [s], x[0..channels)). Returns true when an estimate is ready.
  /// Throws std::invalid_argument if t does not increase (the caller's duty).
  bool update(double t, const double* x) {
    if (finishing_ || (delegating() && smoother_.front().finishing_)) reset();
    if (count_ > 0) {
      const double dt = t - last_time_;
      if (!(dt > 0.0)) throw std::invalid_argument("differentiator: sample time does not increase");
      if (dt > config_.max_gap) restart();
    }
    last_time_ = t;
    newest_used_ = t;
    if (config_.type == DifferentiatorType::kKalman) return updateKalman(t, x);
    if (config_.type == DifferentiatorType::kAdaptive) return updateAdaptive(t, x);
    // Ring buffer of the last `window` samples.
    times_[head_] = t;
    for (int c = 0; c < channels_; ++c) values_(head_, c) = x[c];
    head_ = (head_ + 1) % config_.window;
    if (count_ < config_.window) ++count_;
    if (count_ < config_.window) return false;
    fitSavitzkyGolay();
    return true;
  }

  /// What the causal filter predicts for channel c at time t [s], later than its newest
  /// sample: Kalman, and adaptive's selected filter, the state propagated by the model (its
  /// value held across a gap longer than max_gap); Savitzky-Golay and finite differences
  /// the newest sample; 0 before any. Fed as a missing sample's measurement, it moves the
  /// estimate no more than the model does.
  double predict(int c, double t) const {
    if (count_ == 0) return 0.0;
    if (config_.type == DifferentiatorType::kAdaptive)
      return models_[selection_.selected()].predict(c, t);
    if (config_.type != DifferentiatorType::kKalman) return values_(ring(0), c);
    const double dt = t - last_time_;
    if (!(dt <= config_.max_gap)) return state_(0, c);
    double x = 0.0, power = 1.0;  // sum of state_(k) dt^k / k!
    for (int k = 0; k < n_; ++k) {
      x += power * state_(k, c);
      power *= dt / (k + 1);
    }
    return x;
  }

  double stamp() const { return stamp_; }
  /// The stamp [s] of the newest sample the estimate used: the newest sample itself, but
  /// for a smoother the one its backward pass started from.
  double newestUsed() const { return newest_used_; }
  double value(int c) const { return out_(0, c); }
  double rate(int c) const { return out_(1, c); }
  double accel(int c) const { return out_(2, c); }

  /// Noise gain of the last estimate: the covariance of (value, rate, accel) per unit
  /// variance of white noise on the samples (the same for every channel). Savitzky-Golay
  /// and finite differences: C C^T of the weights C (3 x window) in use. Kalman: the
  /// noise part of the estimation error, S_k = A_k S_(k-1) A_k^T + K_k K_k^T with
  /// A_k = (I - K_k H) F_k from S = diag(1, 0, ..) at the first sample: exact through the
  /// start-up, and at a steady rate the fixed point of the discrete Lyapunov equation,
  /// after which it is kept (cached) while dt and the gain stay. Adaptive: the selected
  /// filter's (pooled over the channels: the selection is common to the bank), which is
  /// exact for the filter that made the estimate, restarts from another one included.
  /// A smoother (lag > 0): the smoothed estimate's, which the samples after it shrink:
  /// with m the backward steps from the pass's newest sample to the estimate, the
  /// estimate's noise is P_m e_f + r_m (e_f the forward filter's noise there, r_m that
  /// of the m measurements after it), from P_0 = I, r_0 = 0 by
  /// r_(k+1) = G (P_k K (P_k K)^T + r_k) G^T, P_(k+1) = I - G F + G P_k A, and the gain is
  /// P_m S P_m^T + r_m; exact at a steady rate (its gains settled: then computed once for
  /// every m), and until the filter has settled the forward filter's (larger). An
  /// estimate carried over a gap keeps the one it was made with.
  Eigen::Matrix3d noiseGain() const {
    if (delegating()) return smoother_.front().noiseGain();
    if (config_.type == DifferentiatorType::kAdaptive)
      return models_[selection_.selected()].noiseGain();
    if (config_.type == DifferentiatorType::kKalman && smoothing() && emitted_carried_)
      return carried_gain_;
    if (config_.type == DifferentiatorType::kKalman && smoothing()) return smoothedNoiseGain();
    if (config_.type == DifferentiatorType::kKalman) return S_.topLeftCorner(3, 3);
    Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
    for (int k = 0; k < config_.window; ++k) {
      const Eigen::Vector3d c = coeff_.col(k);
      G.noalias() += c * c.transpose();
    }
    return G;
  }

 private:
  // A Kalman smoother of its own (its ring), or an adaptive one's (smoother_).
  bool smoothing() const {
    return config_.type == DifferentiatorType::kKalman && config_.lag > 0.0;
  }
  bool delegating() const { return !smoother_.empty(); }

  // Adaptive with a lag: a Kalman smoother in unit measurement noise whose process noise
  // follows the selected filter's at every sample (the backward gains of a time-varying
  // model are exact as well: each sample's is remembered).
  void buildSmoother() {
    DifferentiatorConfig k = config_;
    k.type = DifferentiatorType::kKalman;
    k.measurement_noise = 1.0;
    k.process_noise = 1.0;
    smoother_.emplace_back(k, channels_);
    chooseBandwidthFrom(channels_);
  }

  // The smoother's estimate, if `ready`, as this bank's.
  bool takeSmoothed(bool ready) {
    if (!ready) return false;
    const DifferentiatorBank& s = smoother_.front();
    out_ = s.out_;
    stamp_ = s.stamp_;
    newest_used_ = s.newest_used_;
    return true;
  }

  bool autoBandwidth() const {
    return config_.type == DifferentiatorType::kKalman && config_.auto_bandwidth &&
           config_.lag > 0.0;
  }

  // auto_bandwidth: SpectralCutoff's choice, at least kLagFloor / lag, as the process
  // noise (dt: the last interval, where the recent median is not known yet); at least
  // process_noise's if raise_only_. A floor that the spectrum does not come down to (the
  // highest cutoff) is taken from two blocks on only; a spectrum that falls throughout
  // (no noise to remove: leg_running_200hz) at once.
  void chooseNoise(double dt) {
    if (!(spectral_.cutoff() > 0.0)) return;
    if (spectral_.blocks() < 2 && spectral_.atHighest() && !spectral_.fallsThroughout()) return;
    setBandwidth(spectral_.cutoff(), dt);
  }

  // auto_bandwidth: the process noise of bandwidth f [Hz], at least kLagFloor / lag.
  void setBandwidth(double f, double dt) {
    f = std::max(f, kLagFloor / config_.lag);
    const double h = spacing_ > 0.0 ? spacing_ : dt;
    const double r = config_.measurement_noise;
    const double q = r * r * h * std::pow(2.0 * M_PI * f, 2 * n_);
    setProcessNoise(raise_only_ ? std::max(q, default_q_) : q);
    auto_bandwidth_ = bandwidthOf(config_.process_noise, h);
  }

  // auto_bandwidth: the sample (t, x) to the spectrum, and until its first choice to the
  // probe's (dt: the last interval).
  void addSpectra(double t, const double* x, double dt) {
    if (spectral_.add(t, x, state_.data() + 1, n_)) chooseNoise(dt);
    if (spectral_.cutoff() > 0.0 || auto_bandwidth_ > 0.0) return;
    if (probe_.add(t, x, state_.data() + 1, n_) && probe_.fallsThroughout())
      setBandwidth(probe_.cutoff(), dt);
  }

  // The bandwidth [Hz] of process noise q at interval h [s]: where r^2 h (2 pi f)^(2n)
  // is q.
  double bandwidthOf(double q, double h) const {
    const double r = config_.measurement_noise;
    return std::pow(q / (r * r * h), 0.5 / n_) / (2.0 * M_PI);
  }

  // A new process noise from the next sample on (F and Q recomputed, the gain unsettled).
  void setProcessNoise(double q) {
    if (q == config_.process_noise) return;
    config_.process_noise = q;
    dt_prev_ = -1.0;
  }

  // noiseGain() of the smoothed estimate emitted last (emitted_steps_ backward steps).
  Eigen::Matrix3d smoothedNoiseGain() const {
    if (!(gain_settled_ && noise_settled_)) return S_.topLeftCorner(3, 3);
    const std::size_t m = static_cast<std::size_t>(std::max(emitted_steps_, 0));
    if (!smoothed_gains_valid_ || smoothed_gains_.size() <= m) {
      const int n = n_;
      const SmallMatrix& G = backward_gain_;
      const SmallMatrix A = F_ - K_ * F_.row(0);  // (I - K H) F
      const SmallMatrix I = SmallMatrix::Identity(n, n);
      const SmallMatrix base = I - G * F_;
      SmallMatrix P = I, r = SmallMatrix::Zero(n, n);
      // Every step count the ring can hold (its capacity reserved: no allocation).
      smoothed_gains_.resize(std::max<std::size_t>(m + 1, static_cast<std::size_t>(ring_size_)));
      for (std::size_t k = 0; k < smoothed_gains_.size(); ++k) {
        if (k > 0) {
          const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxOrder + 1, 1> PK = P * K_;
          r = G * (PK * PK.transpose() + r) * G.transpose();
          P = base + G * P * A;
        }
        smoothed_gains_[k] = (P * S_ * P.transpose() + r).topLeftCorner(3, 3);
      }
      smoothed_gains_valid_ = true;
    }
    return smoothed_gains_[m];
  }

  bool isKalman() const {
    return config_.type == DifferentiatorType::kKalman ||
           config_.type == DifferentiatorType::kAdaptive;
  }

  // Adaptive: one Kalman filter per bandwidth from min_bandwidth to max_bandwidth (the
  // ratio kBandwidthRatio, the last one at max_bandwidth), in unit measurement noise
  // (the gain depends on process / measurement noise only); their process noise is set
  // from the first interval (tuneModels).
  void buildModels() {
    const double span = std::log(config_.max_bandwidth / config_.min_bandwidth);
    const int count = 1 + static_cast<int>(std::ceil(span / std::log(kBandwidthRatio) - 1e-9));
    DifferentiatorConfig k = config_;
    k.type = DifferentiatorType::kKalman;
    k.measurement_noise = 1.0;
    k.process_noise = 1.0;
    k.lag = 0.0;  // causal: with a lag, smoother_ smooths
    for (int m = 0; m < count; ++m) {
      bandwidths_.push_back(
          std::min(config_.max_bandwidth, config_.min_bandwidth * std::pow(kBandwidthRatio, m)));
      models_.emplace_back(k, channels_);
    }
    selection_ = BandwidthSelection(count, channels_, config_.noise, config_.memory);
  }

  // The process noise of every filter for samples h [s] apart: the density q at which
  // the signal's spectrum q / w^(2n) meets the noise's, h (unit noise), at 2 pi f.
  void tuneModels(double h) {
    tuned_h_ = h;
    for (std::size_t m = 0; m < models_.size(); ++m) {
      models_[m].config_.process_noise = h * std::pow(2.0 * M_PI * bandwidths_[m], 2 * n_);
      models_[m].dt_prev_ = -1.0;
    }
  }

  bool updateAdaptive(double t, const double* x) {
    const double dt = t - prev_t_;
    if (count_ == 1) tuneModels(dt);
    if (delegating()) {
      const Eigen::MatrixXd& widest = models_.back().out_;  // 3 x channels
      spectral_.add(t, x, widest.data() + 1, static_cast<int>(widest.rows()));
    }
    for (DifferentiatorBank& m : models_) m.update(t, x);
    prev_t_ = t;
    stamp_ = t;
    // The innovations describe the noise once the filters predict from data alone.
    if (count_ > n_) selectModel(dt, x);
    if (count_ <= n_) ++count_;
    if (delegating()) {
      DifferentiatorBank& s = smoother_.front();
      s.setProcessNoise(spectral_.bandwidth() > 0.0
                            ? tuned_h_ * std::pow(2.0 * M_PI * spectral_.bandwidth(), 2 * n_)
                            : models_[selection_.selected()].config_.process_noise);
      return takeSmoothed(s.update(t, x));
    }
    out_ = models_[selection_.selected()].out_;
    return count_ >= n_;
  }

  // The noise from the widest filter (the least disturbed by the motion), the likeliest
  // filter, and the narrower ones left far behind restarted from it.
  void selectModel(double dt, const double* x) {
    const DifferentiatorBank& widest = models_.back();
    selection_.observeNoise(x, widest.innovation_.data(), widest.noise_innovation_, dt);
    const int count = static_cast<int>(models_.size());
    for (int m = 0; m < count; ++m)
      selection_.score(m, models_[m].innovation_.data(), models_[m].innovation_variance_, dt);
    const int best = selection_.select();
    for (int m = 0; m < best; ++m) {
      if (!selection_.behind(m)) continue;
      models_[m].adopt(models_[best]);
      selection_.restarted(m);
    }
  }

  // The state and noise gain of another filter of the same model and channels.
  void adopt(const DifferentiatorBank& other) {
    state_ = other.state_;
    S_ = other.S_;
    noise_settled_ = false;
    out_ = other.out_;
  }

  // Index in the ring of the sample k steps before the newest.
  int ring(int k) const { return (head_ - 1 - k + 2 * config_.window) % config_.window; }

  void fitSavitzkyGolay() {
    const int w = config_.window;
    stamp_ = times_[ring(config_.delay)];
    // Times centred on the window and scaled to [-1, 1], so that the Vandermonde matrix
    // stays well conditioned at any rate and any offset of the clock.
    const double newest = times_[ring(0)], oldest = times_[ring(w - 1)];
    const double mid = 0.5 * (newest + oldest), half = 0.5 * (newest - oldest);
    if (!sameSpacing(mid, half)) {
      factorVandermonde();
      weightsAt((stamp_ - mid) / half, half);
      tau_prev_.head(w) = tau_.head(w);
      half_prev_ = half;
    }
    out_.setZero();
    for (int k = 0; k < w; ++k) out_.noalias() += coeff_.col(k) * values_.row(ring(k));
  }

  // Fills tau_ with the window's times centred on mid and scaled by half; whether they
  // have the same spacing as at the last fit (a steady rate: the weights are reused).
  // "Same" means every sample within kSameSpacing of where the last fit had it: stamps
  // are integers of nanoseconds, so a smaller difference is the rounding of the double
  // time axis (its ulp is 1e-13 s at 1000 s), not information about the signal.
  bool sameSpacing(double mid, double half) {
    constexpr double kSameSpacing = 1e-10;  // [s]
    const int w = config_.window;
    bool same = std::abs(half - half_prev_) <= kSameSpacing;
    for (int k = 0; k < w; ++k) {
      const double tau = (times_[ring(k)] - mid) / half;
      same = same && std::abs(tau - tau_prev_[k]) * half <= kSameSpacing;
      tau_[k] = tau;
    }
    return same;
  }

  // Least squares by Householder QR of the Vandermonde V (w x n) of tau_, V = Q R: the
  // weights of derivative d are row d of E pinv(V) = (Q R^-T E^T)^T, where row d of
  // E evaluates the d-th derivative of 1, tau, ..., tau^(n-1) at the stamp. Their
  // error grows like cond(V), where the normal equations' grows like cond(V)^2: with
  // one 1 us interval among 1 ms ones, the 3-point difference (V square) lost a
  // factor 250 over what its inputs allow, and 1.3e6 at 0.1 ns (docs/stability.md).
  // The centring and scaling keep cond(V) small for any spacing that is not
  // degenerate, at any offset of the clock. The estimate is a fixed linear
  // combination of the window: coeff row d . x is the d-th derivative at the stamp.
  // Factored in place in V_: R on and above the diagonal, the reflectors' essential
  // parts below, their coefficients in h_.
  void factorVandermonde() {
    const int w = config_.window;
    V_.resize(w, n_);
    for (int k = 0; k < w; ++k) {
      double p = 1.0;
      for (int j = 0; j < n_; ++j, p *= tau_[k]) V_(k, j) = p;
    }
    for (int j = 0; j < n_; ++j) {
      double beta;
      V_.col(j).tail(w - j).makeHouseholderInPlace(h_[j], beta);
      V_(j, j) = beta;
      if (j + 1 < n_)
        V_.bottomRightCorner(w - j, n_ - j - 1)
            .applyHouseholderOnTheLeft(V_.col(j).tail(w - j - 1), h_[j], work_.data());
    }
  }

  // The weights coeff_ (3 x w) of the value, rate and acceleration at the scaled stamp
  // te from the factors of factorVandermonde(); half: the time scale [s].
  void weightsAt(double te, double half) {
    const int w = config_.window;
    const Vandermonde& QR = V_;
    // Y = R^-T E^T (n x 3) by forward substitution.
    Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxOrder + 1, 3> Y(n_, 3);
    for (int j = 0; j < n_; ++j) {
      Y(j, 0) = std::pow(te, j);
      Y(j, 1) = j >= 1 ? j * std::pow(te, j - 1) : 0.0;
      Y(j, 2) = j >= 2 ? j * (j - 1) * std::pow(te, j - 2) : 0.0;
      for (int i = 0; i < j; ++i) Y.row(j) -= QR(i, j) * Y.row(i);
      Y.row(j) /= QR(j, j);
    }
    // coeff^T = Q [Y; 0] (w x 3): the reflectors H_{n-1} .. H_0 applied in turn,
    // H_j = I - h_j v_j v_j^T with v_j = (0 .. 0, 1, QR(j+1 .., j)).
    coeff_t_.setZero(w, 3);
    coeff_t_.topRows(n_) = Y;
    for (int j = n_ - 1; j >= 0; --j) {
      const int len = w - j - 1;
      Eigen::Matrix<double, 1, 3> vx =
          coeff_t_.row(j) + QR.col(j).segment(j + 1, len).transpose() * coeff_t_.bottomRows(len);
      vx *= h_[j];
      coeff_t_.row(j) -= vx;
      coeff_t_.bottomRows(len).noalias() -= QR.col(j).segment(j + 1, len) * vx;
    }
    coeff_ = coeff_t_.transpose();
    coeff_.row(1) /= half;
    coeff_.row(2) /= half * half;
  }

  bool updateKalman(double t, const double* x) {
    const int n = n_;
    running_ = taken_ > 0;  // smoother: whether the last sample made an estimate
    taken_ = 0;
    if (count_ == 0) {
      startKalman(t, x);
      return smoothing() && emitDue();
    }
    const double dt = t - prev_t_;
    prev_t_ = t;
    const bool changed = discretize(dt);
    // Predict, then update with the position measurement: the gain is the same for
    // every channel, so the covariance is propagated once; at a steady rate it reaches
    // its fixed point (the Riccati recursion converges), after which the gain stays.
    const bool steady = !changed && gain_settled_;
    if (!steady) updateKalmanGain();
    // Noise gain: kept once it no longer changes under a settled gain.
    if (!(steady && noise_settled_)) {
      updateNoiseGain(steady);
      smoothed_gains_valid_ = false;
    }
    double* predicted = nullptr;
    if (smoothing()) {
      if (index_ == 0) startSmoother(dt);
      // The samples from the oldest not yet estimated to this one (rarely: a faster rate
      // than the first interval's, a gap's carry, or a drop's backlog).
      if (index_ + 2 - emitted_ > ring_size_) growRing(2 * (index_ + 2 - emitted_));
      predicted = rememberGain();
    }
    if (n == 3)
      kalmanChannels<3>(x, predicted);
    else
      kalmanChannels<4>(x, predicted);
    stamp_ = t;
    if (count_ < n) ++count_;
    if (autoBandwidth() && count_ >= n) addSpectra(t, x, dt);
    if (smoothing()) return smoothStep(t, dt);
    return count_ >= n;
  }

  // Smoother: the ring of the forward filter's states, predictions and backward gains,
  // sized for twice the lag at the first interval dt [s] (a first interval up to twice
  // the rate's needs no growth), allocated only when a restart needs more than the last
  // start did.
  void startSmoother(double dt) {
    constexpr double kMostExpected = 1 << 20;  // [samples] beyond: grown as they come
    const double expected = std::min(config_.lag / dt, kMostExpected);
    const int size = 2 * std::max(n_ + 1, static_cast<int>(std::lround(expected)) + 1);
    if (filtered_.cols() < size) allocateRing(size);
    ring_size_ = static_cast<int>(filtered_.cols());
  }

  // The ring at `size` columns (one allocation): the samples from the oldest not yet
  // estimated to the newest moved to their slots at the new length.
  void growRing(int size) {
    const auto grow = [&](auto& m, Eigen::Index rows) {
      std::decay_t<decltype(m)> grown(rows, size);
      for (int j = emitted_; j <= index_; ++j) grown.col(j % size) = m.col(j % ring_size_);
      m.swap(grown);
    };
    grow(filtered_, filtered_.rows());
    grow(predicted_, predicted_.rows());
    grow(smoothed_, smoothed_.rows());
    grow(gains_, gains_.rows());
    Eigen::VectorXd times(size);
    for (int j = emitted_; j <= index_; ++j) times[j % size] = ring_times_[j % ring_size_];
    ring_times_.swap(times);
    smoothed_gains_.reserve(static_cast<std::size_t>(size));
    smoothed_gains_valid_ = false;
    ring_size_ = size;
  }

  // The ring's columns; the first sample's (slot 0) is kept.
  void allocateRing(int size) {
    const Eigen::Index states = static_cast<Eigen::Index>(n_) * channels_;
    filtered_.conservativeResize(states, size);
    predicted_.conservativeResize(states, size);
    smoothed_.conservativeResize(3 * channels_, size);
    gains_.conservativeResize(n_ * n_, size);
    ring_times_.conservativeResize(size);
    smoothed_gains_.reserve(static_cast<std::size_t>(size));
    back_.resize(states);
    if (carry_.cols() < size) {
      carry_.conservativeResize(3 * channels_, size);
      carry_gains_.conservativeResize(9, size);
      carry_times_.conservativeResize(size);
      carry_newest_.conservativeResize(size);
    }
  }

  // The backward gain G_(k-1) = P_(k-1|k-1) F_k^T P_(k|k-1)^-1 of the sample before this
  // one into the ring (computed with the filter's gain, kept while it is settled), and
  // where this sample's prediction goes.
  double* rememberGain() {
    const int slot = (index_ + 1) % ring_size_;
    gains_.col((index_) % ring_size_) =
        Eigen::Map<const Eigen::VectorXd>(backward_gain_.data(), n_ * n_);
    return predicted_.col(slot).data();
  }

  // After the forward step of sample index_ + 1 (time t, dt after the last): its state
  // into the ring, the recent interval, and the estimate if one is due.
  bool smoothStep(double t, double dt) {
    ++index_;  // the sample whose forward step was just taken
    const int slot = index_ % ring_size_;
    filtered_.col(slot) =
        Eigen::Map<const Eigen::VectorXd>(state_.data(), static_cast<Eigen::Index>(n_) * channels_);
    ring_times_[slot] = t;
    noteInterval(dt);
    return emitDue();
  }

  // spacing_: the median of the last kRecent intervals (a gap or a burst does not move
  // it; a change of rate does, in kRecent / 2 samples).
  void noteInterval(double dt) {
    recent_[recent_count_++ % kRecent] = dt;
    const int k = std::min(recent_count_, kRecent);
    double sorted[kRecent];
    for (int i = 0; i < k; ++i) {
      int j = i;
      for (; j > 0 && sorted[j - 1] > recent_[i]; --j) sorted[j] = sorted[j - 1];
      sorted[j] = recent_[i];
    }
    spacing_ = k % 2 == 1 ? sorted[k / 2] : 0.5 * (sorted[k / 2 - 1] + sorted[k / 2]);
  }

  // The next estimate (the oldest carried over a gap, else the oldest of its own, which
  // needs n samples after it) if due at the newest sample, stamp t_N. With t_j its stamp
  // and u the recent interval (spacing_: what waiting one more sample adds to the
  // delay): due if t_N - t_j >= lag - u after a sample that made an estimate, >= lag -
  // u / 2 (the nearest) after one that made none or at a start: the hysteresis keeps
  // one estimate per sample at a steady rate, jitter included. After an estimate
  // already taken at this sample, only if that first one was overdue (t_N - t_j >
  // lag + its interval to the next pending sample: a drop of the rate, a gap), and
  // then each with t_N - t_j >= lag - u / 2 (the nearest).
  bool emitDue() {
    if (taken_ > 0 && !catching_up_) return false;
    const bool carried = carry_next_ < carry_count_;
    if (!carried && !(count_ > 0 && index_ - emitted_ >= n_)) return false;
    const double t = carried ? carry_times_[carry_next_] : ring_times_[emitted_ % ring_size_];
    const double delay = last_time_ - t, lag = config_.lag, u = spacing_;
    if (delay < lag - (taken_ == 0 && running_ ? u : 0.5 * u)) return false;
    if (taken_++ == 0) catching_up_ = delay > lag + pendingInterval(carried);
    if (carried)
      emitCarry();
    else
      emitOwn();
    return true;
  }

  // The interval [s] from the next sample to estimate to the one after it (the recent
  // interval when it is the last pending one).
  double pendingInterval(bool carried) const {
    if (carried && carry_next_ + 1 < carry_count_)
      return carry_times_[carry_next_ + 1] - carry_times_[carry_next_];
    if (!carried && emitted_ < index_)
      return ring_times_[(emitted_ + 1) % ring_size_] - ring_times_[emitted_ % ring_size_];
    return spacing_;
  }

  // The oldest of its own samples not yet estimated as the estimate, after a backward
  // pass from the newest over it and the next ones, half the pending samples, if the
  // last pass did not reach it.
  void emitOwn() {
    if (emitted_ > smoothed_through_) {
      const int block = std::max(1, (index_ - emitted_) / 2);
      smoothed_through_ = std::min(index_, emitted_ + block - 1);
      smoothBack(index_, emitted_, smoothed_through_);
    }
    emitSmoothed();
  }

  // Rauch-Tung-Striebel from sample `newest` (the filtered state) back to `oldest`:
  // x_s(t) = x_f(t) + G_t (x_s(t+1) - x_p(t+1)); value, rate and accel of every
  // sample from oldest to last into the ring smoothed_.
  void smoothBack(int newest, int oldest, int last) {
    if (n_ == 3)
      smoothChannels<3>(newest, oldest, last);
    else
      smoothChannels<4>(newest, oldest, last);
  }

  template <int N>
  void smoothChannels(int newest, int oldest, int last) {
    pass_newest_ = newest;
    pass_newest_time_ = ring_times_[newest % ring_size_];
    double* back = back_.data();
    const double* start = filtered_.col(newest % ring_size_).data();
    for (int i = 0; i < N * channels_; ++i) back[i] = start[i];
    if (newest <= last) writeSmoothed<N>(newest, back);
    // The states of all the channels as N x channels matrices, a fixed-size product per
    // channel (no temporary on the heap).
    using States = Eigen::Map<Eigen::Matrix<double, N, Eigen::Dynamic>>;
    using ConstStates = Eigen::Map<const Eigen::Matrix<double, N, Eigen::Dynamic>>;
    States x(back, N, channels_);
    for (int t = newest - 1; t >= oldest; --t) {
      const ConstStates f(filtered_.col(t % ring_size_).data(), N, channels_);
      const ConstStates p(predicted_.col((t + 1) % ring_size_).data(), N, channels_);
      const Eigen::Map<const Eigen::Matrix<double, N, N>> g(gains_.col(t % ring_size_).data());
      for (int c = 0; c < channels_; ++c) {
        const Eigen::Matrix<double, N, 1> d = x.col(c) - p.col(c);
        x.col(c).noalias() = f.col(c) + g * d;
      }
      if (t <= last) writeSmoothed<N>(t, back);
    }
  }

  template <int N>
  void writeSmoothed(int t, const double* back) {
    double* out = smoothed_.col(t % ring_size_).data();
    for (int c = 0; c < channels_; ++c)
      for (int i = 0; i < 3; ++i) out[3 * c + i] = back[N * c + i];
  }

  void emitSmoothed() {
    emitted_steps_ = pass_newest_ - emitted_;
    emitted_carried_ = false;
    const int slot = emitted_ % ring_size_;
    out_ = Eigen::Map<const Eigen::MatrixXd>(smoothed_.col(slot).data(), 3, channels_);
    stamp_ = ring_times_[slot];
    newest_used_ = pass_newest_time_;
    ++emitted_;
  }

  // The first sample: the state starts at the measurement, at rest, with a wide prior on
  // the derivatives.
  void startKalman(double t, const double* x) {
    const int n = n_;
    state_.setZero();
    for (int c = 0; c < channels_; ++c) state_(0, c) = x[c];
    P_.setZero();
    const double r2 = config_.measurement_noise * config_.measurement_noise;
    P_(0, 0) = r2;
    for (int i = 1; i < n; ++i) P_(i, i) = 1e12 * r2;
    K_.setZero(n);
    gain_settled_ = false;
    S_.setZero(n, n);
    S_(0, 0) = 1.0;  // the state starts at the measurement
    noise_settled_ = false;
    prev_t_ = t;
    count_ = 1;
    stamp_ = t;
    if (smoothing()) {
      index_ = 0;
      emitted_ = 0;
      ring_size_ = 1;
      filtered_.col(0) = Eigen::Map<const Eigen::VectorXd>(
          state_.data(), static_cast<Eigen::Index>(n_) * channels_);
      ring_times_[0] = t;
    }
    out_.topRows(std::min(3, n)) = state_.topRows(std::min(3, n));
  }

  // Exact discretisation for this dt [s]: F = exp(A dt) of the integrator chain, Q the
  // integrated white noise of density q on the highest derivative. Recomputed (true)
  // only when dt changes by more than the time axis resolves (see sameSpacing).
  bool discretize(double dt) {
    if (std::abs(dt - dt_prev_) <= 1e-10) return false;
    const int n = n_;
    double fact[2 * kMaxOrder + 2], dt_pow[2 * kMaxOrder + 2];
    fact[0] = 1.0;
    dt_pow[0] = 1.0;
    for (int i = 1; i < 2 * kMaxOrder + 2; ++i) {
      fact[i] = fact[i - 1] * i;
      dt_pow[i] = dt_pow[i - 1] * dt;
    }
    F_.setIdentity(n, n);
    Q_.resize(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) F_(i, j) = dt_pow[j - i] / fact[j - i];
    const double q = processNoise(config_);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const int a = n - 1 - i, b = n - 1 - j;
        Q_(i, j) = q * dt_pow[a + b + 1] / (fact[a] * fact[b] * (a + b + 1));
      }
    dt_prev_ = dt;
    return true;
  }

  // The covariance P_ predicted and updated, and the gain K_ (settled once it no longer
  // changes).
  void updateKalmanGain() {
    const SmallMatrix& F = F_;
    const SmallMatrix& Q = Q_;
    const SmallMatrix FP = F * P_;  // F P_(k-1|k-1)
    P_ = FP * F.transpose() + Q;
    // Smoother: G = P_(k-1|k-1) F^T P_(k|k-1)^-1, as G^T = P_(k|k-1)^-1 F P_(k-1|k-1).
    if (smoothing()) backward_gain_ = P_.ldlt().solve(FP).transpose();
    const double r2 = config_.measurement_noise * config_.measurement_noise;
    const double S = P_(0, 0) + r2;
    innovation_variance_ = S / r2;
    const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxOrder + 1, 1> K = P_.col(0) / S;
    P_ -= K * P_.row(0);
    P_ = 0.5 * (P_ + P_.transpose()).eval();
    gain_settled_ =
        count_ >= n_ && (K - K_).cwiseAbs().maxCoeff() <= 1e-15 * K.cwiseAbs().maxCoeff();
    K_ = K;
  }

  // The noise gain S_ = A S_ A^T + K K^T with A = (I - K H) F (noiseGain()).
  void updateNoiseGain(bool steady) {
    const SmallMatrix& F = F_;
    noise_innovation_ = (F.row(0) * S_ * F.row(0).transpose()).value() + 1.0;
    SmallMatrix A = -K_ * F.row(0);
    A += F;  // (I - K H) F with H = (1, 0, ..)
    SmallMatrix S = A * S_ * A.transpose();
    S += K_ * K_.transpose();
    noise_settled_ = steady && (S - S_).cwiseAbs().maxCoeff() <= 1e-14 * S.cwiseAbs().maxCoeff();
    S_ = S;
  }

  // x <- F x + K (measurement - (F x)_0) for every channel, at fixed size N, and the
  // estimate (x, x', x'') into out_ in the same pass. F = exp(A dt) of the integrator
  // chain is upper triangular with F(i, i + d) = dt^d / d!: the products by its zeros
  // and ones are skipped, the other terms added in the full product's order.
  template <int N>
  void kalmanChannels(const double* x, double* predicted) {
    double f[N], k[N];
    for (int d = 0; d < N; ++d) {
      f[d] = F_(0, d);
      k[d] = K_[d];
    }
    double* state = state_.data();
    double* out = out_.data();
    double* innovation = innovation_.data();
    for (int c = 0; c < channels_; ++c, state += N, out += 3) {
      double s[N];
      for (int i = 0; i < N; ++i) {
        double v = state[i];
        for (int j = i + 1; j < N; ++j) v += f[j - i] * state[j];
        s[i] = v;
      }
      if (predicted)
        for (int i = 0; i < N; ++i) predicted[N * c + i] = s[i];
      const double e = x[c] - s[0];
      innovation[c] = e;
      for (int i = 0; i < N; ++i) state[i] = s[i] + k[i] * e;
      for (int i = 0; i < 3; ++i) out[i] = state[i];
    }
  }

  DifferentiatorConfig config_;
  int channels_;
  int n_ = 3;
  int count_ = 0;
  int head_ = 0;
  // Smoother: index of the newest sample since the start (-1: none), of the next to
  // estimate, of the last whose smoothed estimate is in the ring, whether finish() was
  // called, the ring's length (its capacity); estimates taken at the newest sample,
  // whether the sample before made one, whether the first taken was overdue; the last
  // kRecent intervals [s], how many were taken, and their median [s].
  int index_ = -1;
  int emitted_ = 0;
  int smoothed_through_ = -1;
  bool finishing_ = false;
  int ring_size_ = 1;
  int taken_ = 0;
  bool running_ = false;
  bool catching_up_ = false;
  static constexpr int kRecent = 5;
  double recent_[kRecent] = {};
  int recent_count_ = 0;
  double spacing_ = 0.0;
  double auto_bandwidth_ = 0.0;               // [Hz] auto_bandwidth: the spectrum's (0: none yet)
  double default_q_ = processNoise(config_);  // auto_bandwidth: the least process noise
  bool raise_only_ = false;  // auto_bandwidth: never below process_noise's (raiseOnly)
  SmallMatrix backward_gain_;
  // Per remembered sample (column: slot index % ring_size_): the filtered state
  // (n x channels, channel-major), the prediction before its measurement, the backward
  // gain to the next sample (n x n column-major), the smoothed (value, rate, accel) x
  // channels, and its time [s]; back_: the backward pass's running state.
  Eigen::MatrixXd filtered_, predicted_, gains_, smoothed_;
  Eigen::VectorXd ring_times_, back_;
  // Smoother: estimates made at a gap from the samples before it, (value, rate, accel)
  // x channels per column, their times [s], how many, and the next to publish.
  Eigen::MatrixXd carry_, carry_gains_;         // carry_gains_: their noise gains (3x3 per column)
  Eigen::VectorXd carry_times_, carry_newest_;  // carry_newest_: their newestUsed()
  // Smoother's noise gain: the newest sample of the last backward pass, the steps from
  // it to the estimate emitted last or whether that one was carried (and its gain), and
  // the gains by steps at a steady rate (smoothedNoiseGain()).
  int pass_newest_ = 0;
  double pass_newest_time_ = 0.0;
  int emitted_steps_ = 0;
  bool emitted_carried_ = false;
  Eigen::Matrix3d carried_gain_ = Eigen::Matrix3d::Zero();
  mutable std::vector<Eigen::Matrix3d> smoothed_gains_;
  mutable bool smoothed_gains_valid_ = false;
  int carry_count_ = 0;
  int carry_next_ = 0;
  double last_time_ = 0.0;
  double stamp_ = 0.0;
  double newest_used_ = 0.0;
  double prev_t_ = 0.0;
  double half_prev_ = 0.0;
  double dt_prev_ = -1.0;  // Kalman: dt of F_ and Q_
  SmallMatrix F_, Q_;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxOrder + 1, 1> K_;  // Kalman gain
  bool gain_settled_ = false;
  SmallMatrix S_;  // Kalman noise gain (noiseGain())
  bool noise_settled_ = false;
  Eigen::VectorXd times_;
  Eigen::MatrixXd values_;  // window x channels
  Eigen::MatrixXd coeff_;   // 3 x window
  Eigen::MatrixXd out_;     // 3 x channels
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 101, 1> tau_{101};
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 101, 1> tau_prev_;
  using Vandermonde = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 101, kMaxOrder + 1>;
  Vandermonde V_;
  Eigen::Matrix<double, kMaxOrder + 1, 1> h_;     // Householder coefficients
  Eigen::Matrix<double, kMaxOrder + 1, 1> work_;  // workspace of applyHouseholderOnTheLeft
  Eigen::Matrix<double, Eigen::Dynamic, 3, 0, 101, 3> coeff_t_;  // w x 3
  Eigen::MatrixXd state_;                                        // Kalman: n x channels
  SmallMatrix P_;
  // Kalman: the last measurements minus their predictions (channels), their predicted
  // variance, and that of their noise part alone, per unit measurement variance.
  Eigen::VectorXd innovation_;
  double innovation_variance_ = 1.0;
  double noise_innovation_ = 1.0;
  // Adaptive: the filters from the narrowest to the widest, their bandwidths [Hz], and
  // the choice among them.
  std::vector<DifferentiatorBank> models_;
  std::vector<double> bandwidths_;
  BandwidthSelection selection_;
  // Adaptive with a lag: the smoother that makes the estimates (one, or none), its
  // bandwidth's choice, and the first interval the filters were tuned for [s].
  std::vector<DifferentiatorBank> smoother_;
  SpectralCutoff spectral_;
  SpectralCutoff probe_;  // auto_bandwidth: short blocks until spectral_'s first choice
  double tuned_h_ = 0.0;
};

}  // namespace jle
