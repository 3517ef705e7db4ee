// Online estimation of a signal's value, rate and second derivative from its samples:
// Savitzky-Golay fits (finite differences are the smallest of them) and Kalman filters.
// A bank filters many channels that share their sample times (all the joints of one
// JointState, the components of the wrenches resampled at the same stamps) at the cost
// of one set of coefficients.
#pragma once

#include <joint_load_estimator/filters/bandwidth_selection.hpp>
#include <joint_load_estimator/filters/spectral_cutoff.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/settings/differentiator_config.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

namespace jle {

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
  /// narrower smoother's response is longer than the lag (measured:
  /// docs/studies/differentiators.md).
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
  /// auto_bandwidth, the measured velocities' smoother (raiseOnly with a lag): a move
  /// faster than the spectrum so far shows (its 2 s blocks see it once it is over) leaves
  /// its trace in the innovations, which are then correlated from sample to sample; white
  /// noise, however loud, leaves none. Where the correlated part of the innovations
  /// (sum over the channels of e_k e_(k-1), averaged over kMissedMotionSeconds) exceeds
  /// the innovation variance that the spectrum's noise floor predicts, the filter runs at
  /// kMissedMotionBoost times its bandwidth, until it no longer does.
  static constexpr double kMissedMotionSeconds = 0.05;
  static constexpr double kMissedMotionBoost = 1.5;
  using SmallMatrix =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxOrder + 1, kMaxOrder + 1>;

  DifferentiatorBank(const DifferentiatorConfig& config, int channels);

  const DifferentiatorConfig& config() const { return config_; }
  int channels() const { return channels_; }
  /// Samples needed after a reset before the first estimate (a smoother: lag over the
  /// recent interval, plus one, at least n + 1; before its second sample that of the
  /// causal filter).
  int warmup() const;
  /// Samples the estimate describes behind the newest: Savitzky-Golay's `delay`, 0 for
  /// the causal filters; a smoother's pending(): the samples after its last estimate
  /// (lag over the interval at a steady rate), and an upper bound of the delay of any
  /// estimate still to come (before the first estimate: the samples taken).
  int delaySamples() const;
  /// Smoother: samples taken and not yet estimated. After update() returned true, next()
  /// makes the next one due at the same newest sample the estimate (true; false when
  /// none is): several are due at once where the rate drops or after a gap; one not
  /// taken is the estimate of a later update(), in order. finish() smooths them all with
  /// the data there is, after which each call of next() (true while one is left) makes
  /// the oldest of them the estimate (stamp(), value(), ...): the end of a stream.
  /// update() after finish() is a fresh start. A gap (max_gap) smooths the samples
  /// before it alike; they are estimated first, each when due by its stamp, then those
  /// after it: every sample is estimated once, in order.
  int pending() const;
  void finish();
  bool next();

  /// A fresh start: as constructed (auto_bandwidth: the spectra and the process noise
  /// too, so that a jump of time restarts as a new filter would).
  void reset();

 private:
  void resetFilter();

  // A gap: the smoother's pending estimates (and those still carried) into the carry,
  // and a fresh filter.
  void restart();

  // The oldest carried estimate, if any, as the estimate.
  bool emitCarry();

 public:
  /// Adaptive: the bandwidth [Hz] of the filter in use (with a lag of 0.14 s or more,
  /// the smoother's: SpectralCutoff's choice), and the position noise's
  /// standard deviation [unit] of channel c it assumes (estimated or given; 0 before the
  /// first estimate).
  /// auto_bandwidth: the smoother's bandwidth (where its gain is 1/2) [Hz]: the data's
  /// choice (chooseNoise), before it process_noise's at the recent interval (0 before
  /// an interval).
  double bandwidth() const;
  double noise(int c) const {
    return models_.empty() ? 0.0 : std::sqrt(selection_.noiseVariance(c));
  }
  /// auto_bandwidth: the positions' spectrum's last choice [Hz] (0 before the first), and
  /// its noise floor [unit^2] (SpectralCutoff::floorLevel: 0 where none was found).
  double spectralCutoff() const { return autoBandwidth() ? spectral_.cutoff() : 0.0; }
  double noiseFloor() const { return autoBandwidth() ? spectral_.floorLevel() : 0.0; }
  /// auto_bandwidth: the probe's (0.5 s blocks) last choice [Hz] and noise floor, until the
  /// spectrum's first choice (0 before the probe's first).
  double probeCutoff() const { return autoBandwidth() ? probe_.cutoff() : 0.0; }
  double probeFloor() const { return autoBandwidth() ? probe_.floorLevel() : 0.0; }
  /// auto_bandwidth: the process noise is only ever raised above process_noise's, never
  /// lowered (true), or set from the data both ways (false, the default). The measured
  /// velocities' filter raises only: a rate's spectrum falls more slowly than a
  /// position's, and its crossing of the floor from a block or two lies below the rate's
  /// bandwidth (accuracy study, the smoothed default set both ways, so without its boost
  /// (followMotion) either: arm_noise_1e-3 0.0165 -> 0.0194 N m, 1.33x -> 1.56x the best at its
  /// delay; arm_noise_1e-4 0.0080 -> 0.0096; arm_coloured_1khz 0.0231 -> 0.0226). A causal filter
  /// (lag 0) raises only in any case; with raiseOnly (a rate's filter) to where the spectrum meets
  /// its floor, without it (positions) only where it shows none (accuracy study, the immediate
  /// default: lowered by its own spectrum, the velocities' filter cost panda 0.049 -> 0.107 N m).
  void raiseOnly(bool raise_only) { raise_only_ = raise_only; }
  /// Adaptive with a lag: only the first `channels` channels (e.g. the joint positions,
  /// not the wrenches filtered alike) choose the smoother's bandwidth. All by default.
  void chooseBandwidthFrom(int channels);

  /// Adds the sample (t [s], x[0..channels)). Returns true when an estimate is ready.
  /// Throws std::invalid_argument if t does not increase (the caller's duty).
  bool update(double t, const double* x);

  /// What the causal filter predicts for channel c at time t [s], later than its newest
  /// sample: Kalman, and adaptive's selected filter, the state propagated by the model (its
  /// value held across a gap longer than max_gap); Savitzky-Golay and finite differences
  /// the newest sample; 0 before any. Fed as a missing sample's measurement, it moves the
  /// estimate no more than the model does.
  double predict(int c, double t) const;

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
  Eigen::Matrix3d noiseGain() const;

 private:
  // A Kalman smoother of its own (its ring), or an adaptive one's (smoother_).
  bool smoothing() const {
    return config_.type == DifferentiatorType::kKalman && config_.lag > 0.0;
  }
  bool delegating() const { return !smoother_.empty(); }

  // Adaptive with a lag: a Kalman smoother in unit measurement noise whose process noise
  // follows the selected filter's at every sample (the backward gains of a time-varying
  // model are exact as well: each sample's is remembered).
  void buildSmoother();

  // The smoother's estimate, if `ready`, as this bank's.
  bool takeSmoothed(bool ready);

  bool autoBandwidth() const;

  // auto_bandwidth: SpectralCutoff's choice, at least kLagFloor / lag, as the process
  // noise (dt: the last interval, where the recent median is not known yet); at least
  // process_noise's if raise_only_. A floor that the spectrum does not come down to (the
  // highest cutoff) is taken from two blocks on only; a spectrum that falls throughout
  // (no noise to remove: leg_running_200hz) at once.
  void chooseNoise(double dt);

  // auto_bandwidth, a smoother before the data's first choice: process_noise's bandwidth
  // at the recent interval raised to kLagFloor / lag where it is below (process_noise is
  // a density: its bandwidth falls with the rate, 400 is 8 Hz at 1 kHz and 6 Hz at 100 Hz).
  void startAtLagFloor(double dt);

  // auto_bandwidth: the process noise of bandwidth f [Hz], at least kLagFloor / lag.
  void setBandwidth(double f, double dt);

  // The measured velocities' smoother (raise_only_ with a lag), after a sample's update
  // (dt: its interval): the innovations' correlated part against the noise floor, and the
  // bandwidth kMissedMotionBoost times the chosen one while it exceeds it
  // (kMissedMotionSeconds).
  void followMotion(double dt);

  // The chosen process noise again, the innovations' memory cleared (a reset, a gap).
  void endMissedMotion();

  // auto_bandwidth: the sample (t, x) to the spectrum, and until its first choice to the
  // probe's (dt: the last interval).
  void addSpectra(double t, const double* x, double dt);

  // The bandwidth [Hz] of process noise q at interval h [s]: where r^2 h (2 pi f)^(2n)
  // is q.
  double bandwidthOf(double q, double h) const;

  // A new process noise from the next sample on (F and Q recomputed, the gain unsettled).
  void setProcessNoise(double q);

  // noiseGain() of the smoothed estimate emitted last (emitted_steps_ backward steps).
  Eigen::Matrix3d smoothedNoiseGain() const;

  bool isKalman() const;

  // Adaptive: one Kalman filter per bandwidth from min_bandwidth to max_bandwidth (the
  // ratio kBandwidthRatio, the last one at max_bandwidth), in unit measurement noise
  // (the gain depends on process / measurement noise only); their process noise is set
  // from the first interval (tuneModels).
  void buildModels();

  // The process noise of every filter for samples h [s] apart: the density q at which
  // the signal's spectrum q / w^(2n) meets the noise's, h (unit noise), at 2 pi f.
  void tuneModels(double h);

  bool updateAdaptive(double t, const double* x);

  // The noise from the widest filter (the least disturbed by the motion), the likeliest
  // filter, and the narrower ones left far behind restarted from it.
  void selectModel(double dt, const double* x);

  // The state and noise gain of another filter of the same model and channels.
  void adopt(const DifferentiatorBank& other);

  // Index in the ring of the sample k steps before the newest.
  int ring(int k) const { return (head_ - 1 - k + 2 * config_.window) % config_.window; }

  void fitSavitzkyGolay();

  // Fills tau_ with the window's times centred on mid and scaled by half; whether they
  // have the same spacing as at the last fit (a steady rate: the weights are reused).
  // "Same" means every sample within kSameSpacing of where the last fit had it: stamps
  // are integers of nanoseconds, so a smaller difference is the rounding of the double
  // time axis (its ulp is 1e-13 s at 1000 s), not information about the signal.
  bool sameSpacing(double mid, double half);

  // Least squares by Householder QR of the Vandermonde V (w x n) of tau_, V = Q R: the
  // weights of derivative d are row d of E pinv(V) = (Q R^-T E^T)^T, where row d of
  // E evaluates the d-th derivative of 1, tau, ..., tau^(n-1) at the stamp. Their
  // error grows like cond(V), where the normal equations' grows like cond(V)^2: with
  // one 1 us interval among 1 ms ones, the 3-point difference (V square) lost a
  // factor 250 over what its inputs allow, and 1.3e6 at 0.1 ns (docs/studies/stability.md).
  // The centring and scaling keep cond(V) small for any spacing that is not
  // degenerate, at any offset of the clock. The estimate is a fixed linear
  // combination of the window: coeff row d . x is the d-th derivative at the stamp.
  // Factored in place in V_: R on and above the diagonal, the reflectors' essential
  // parts below, their coefficients in h_.
  void factorVandermonde();

  // The weights coeff_ (3 x w) of the value, rate and acceleration at the scaled stamp
  // te from the factors of factorVandermonde(); half: the time scale [s].
  void weightsAt(double te, double half);

  bool updateKalman(double t, const double* x);

  // Smoother: the ring of the forward filter's states, predictions and backward gains,
  // sized for twice the lag at the first interval dt [s] (a first interval up to twice
  // the rate's needs no growth), allocated only when a restart needs more than the last
  // start did.
  void startSmoother(double dt);

  // The ring at `size` columns (one allocation): the samples from the oldest not yet
  // estimated to the newest moved to their slots at the new length.
  void growRing(int size);

  // The ring's columns; the first sample's (slot 0) is kept.
  void allocateRing(int size);

  // The backward gain G_(k-1) = P_(k-1|k-1) F_k^T P_(k|k-1)^-1 of the sample before this
  // one into the ring (computed with the filter's gain, kept while it is settled), and
  // where this sample's prediction goes.
  double* rememberGain();

  // After the forward step of sample index_ + 1 (time t, dt after the last): its state
  // into the ring, the recent interval, and the estimate if one is due.
  bool smoothStep(double t, double dt);

  // spacing_: the median of the last kRecent intervals (a gap or a burst does not move
  // it; a change of rate does, in kRecent / 2 samples).
  void noteInterval(double dt);

  // The next estimate (the oldest carried over a gap, else the oldest of its own, which
  // needs n samples after it) if due at the newest sample, stamp t_N. With t_j its stamp
  // and u the recent interval (spacing_: what waiting one more sample adds to the
  // delay): due if t_N - t_j >= lag - u after a sample that made an estimate, >= lag -
  // u / 2 (the nearest) after one that made none or at a start: the hysteresis keeps
  // one estimate per sample at a steady rate, jitter included. After an estimate
  // already taken at this sample, only if that first one was overdue (t_N - t_j >
  // lag + its interval to the next pending sample: a drop of the rate, a gap), and
  // then each with t_N - t_j >= lag - u / 2 (the nearest).
  bool emitDue();

  // The interval [s] from the next sample to estimate to the one after it (the recent
  // interval when it is the last pending one).
  double pendingInterval(bool carried) const;

  // The oldest of its own samples not yet estimated as the estimate, after a backward
  // pass from the newest over it and the next ones, half the pending samples, if the
  // last pass did not reach it.
  void emitOwn();

  // Rauch-Tung-Striebel from sample `newest` (the filtered state) back to `oldest`:
  // x_s(t) = x_f(t) + G_t (x_s(t+1) - x_p(t+1)); value, rate and accel of every
  // sample from oldest to last into the ring smoothed_.
  void smoothBack(int newest, int oldest, int last);

  template <int N>
  void smoothChannels(int newest, int oldest, int last);

  template <int N>
  void writeSmoothed(int t, const double* back);

  void emitSmoothed();

  // The first sample: the state starts at the measurement, at rest, with a wide prior on
  // the derivatives.
  void startKalman(double t, const double* x);

  // Exact discretisation for this dt [s]: F = exp(A dt) of the integrator chain, Q the
  // integrated white noise of density q on the highest derivative. Recomputed (true)
  // only when dt changes by more than the time axis resolves (see sameSpacing).
  bool discretize(double dt);

  // The covariance P_ predicted and updated, and the gain K_ (settled once it no longer
  // changes).
  void updateKalmanGain();

  // The noise gain S_ = A S_ A^T + K K^T with A = (I - K H) F (noiseGain()).
  void updateNoiseGain(bool steady);

  // x <- F x + K (measurement - (F x)_0) for every channel, at fixed size N, and the
  // estimate (x, x', x'') into out_ in the same pass. F = exp(A dt) of the integrator
  // chain is upper triangular with F(i, i + d) = dt^d / d!: the products by its zeros
  // and ones are skipped, the other terms added in the full product's order.
  template <int N>
  void kalmanChannels(const double* x, double* predicted);

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
  double initial_q_ = config_.process_noise;  // auto_bandwidth: as configured (reset())
  int spectral_channels_ = 0;                 // auto_bandwidth: chooseBandwidthFrom's
  bool spectra_used_ = false;                 // auto_bandwidth: a sample since the last reset
  bool raise_only_ = false;  // auto_bandwidth: never below process_noise's (raiseOnly)
  // followMotion: the chosen process noise (without the boost), the last innovations
  // (channels), the correlated part's running mean per unit predicted innovation
  // variance, and whether the bandwidth is boosted.
  double chosen_q_ = 0.0;
  Eigen::VectorXd last_innovation_;
  double missed_motion_ = 0.0;
  bool boosted_ = false;
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
