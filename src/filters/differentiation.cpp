// The filter bank of differentiation.hpp: Savitzky-Golay fits, Kalman filters and
// smoothers, the adaptive bank. Compiled once here (the header declares).
#include <joint_load_estimator/filters/differentiation.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Householder>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jle {

DifferentiatorBank::DifferentiatorBank(const DifferentiatorConfig& config, int channels)
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
    last_innovation_.setZero(channels_);
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

int DifferentiatorBank::warmup() const {
  if (delegating()) return smoother_.front().warmup();
  if (smoothing() && spacing_ > 0.0)
    return std::max(n_ + 1, static_cast<int>(std::lround(config_.lag / spacing_)) + 1);
  return isKalman() ? n_ : config_.window;
}

int DifferentiatorBank::delaySamples() const {
  if (delegating()) return smoother_.front().delaySamples();
  return smoothing() ? pending() : config_.delay;
}

int DifferentiatorBank::pending() const {
  if (delegating()) return smoother_.front().pending();
  const int own = smoothing() && count_ > 0 ? index_ + 1 - emitted_ : 0;
  return own + carry_count_ - carry_next_;
}

void DifferentiatorBank::finish() {
  if (delegating()) smoother_.front().finish();
  if (finishing_ || !smoothing()) return;
  if (count_ > 0 && emitted_ <= index_) smoothBack(index_, emitted_, index_);
  smoothed_through_ = index_;
  finishing_ = true;
}

bool DifferentiatorBank::next() {
  if (delegating()) return takeSmoothed(smoother_.front().next());
  if (!finishing_) return smoothing() && taken_ > 0 && emitDue();
  if (emitCarry()) return true;
  if (count_ == 0 || emitted_ > index_) return false;
  emitSmoothed();
  return true;
}

void DifferentiatorBank::reset() {
  carry_count_ = carry_next_ = 0;
  recent_count_ = 0;
  spacing_ = 0.0;
  for (DifferentiatorBank& s : smoother_) s.reset();
  endMissedMotion();
  if (autoBandwidth() && spectra_used_) {
    spectra_used_ = false;
    auto_bandwidth_ = 0.0;
    setProcessNoise(initial_q_);
    chooseBandwidthFrom(spectral_channels_);  // fresh spectra (allocates: a jump is rare)
  }
  resetFilter();
}

void DifferentiatorBank::resetFilter() {
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
  endMissedMotion();
}

void DifferentiatorBank::restart() {
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

bool DifferentiatorBank::emitCarry() {
  if (carry_next_ >= carry_count_) return false;
  out_ = Eigen::Map<const Eigen::MatrixXd>(carry_.col(carry_next_).data(), 3, channels_);
  carried_gain_ = Eigen::Map<const Eigen::Matrix3d>(carry_gains_.col(carry_next_).data());
  emitted_carried_ = true;
  newest_used_ = carry_newest_[carry_next_];
  stamp_ = carry_times_[carry_next_++];
  if (carry_next_ == carry_count_) carry_count_ = carry_next_ = 0;
  return true;
}

double DifferentiatorBank::bandwidth() const {
  if (autoBandwidth() && auto_bandwidth_ > 0.0) return auto_bandwidth_;
  const double h = spacing_ > 0.0 ? spacing_ : dt_prev_;  // the causal filter: the last interval
  if (autoBandwidth()) return h > 0.0 ? bandwidthOf(processNoise(config_), h) : 0.0;
  if (delegating() && spectral_.bandwidth() > 0.0) return spectral_.bandwidth();
  return bandwidths_.empty() ? 0.0 : bandwidths_[selection_.selected()];
}

void DifferentiatorBank::chooseBandwidthFrom(int channels) {
  if (autoBandwidth()) {
    spectral_channels_ = channels;
    spectral_ = SpectralCutoff(std::min(channels, channels_), config_.min_bandwidth,
                               config_.max_bandwidth, SpectralCutoff::Rule::kNoiseFloor);
    probe_ =
        SpectralCutoff(std::min(channels, channels_), config_.min_bandwidth, config_.max_bandwidth,
                       SpectralCutoff::Rule::kNoiseFloor, kProbeSeconds, true);
    return;
  }
  if (!delegating()) return;
  const double floor = kLagFloor / config_.lag;
  spectral_ = SpectralCutoff(floor <= kHighestFloor ? std::min(channels, channels_) : 0,
                             std::max(config_.min_bandwidth, floor), config_.max_bandwidth);
}

bool DifferentiatorBank::update(double t, const double* x) {
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

double DifferentiatorBank::predict(int c, double t) const {
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

Eigen::Matrix3d DifferentiatorBank::noiseGain() const {
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

void DifferentiatorBank::buildSmoother() {
  DifferentiatorConfig k = config_;
  k.type = DifferentiatorType::kKalman;
  k.measurement_noise = 1.0;
  k.process_noise = 1.0;
  smoother_.emplace_back(k, channels_);
  chooseBandwidthFrom(channels_);
}

bool DifferentiatorBank::takeSmoothed(bool ready) {
  if (!ready) return false;
  const DifferentiatorBank& s = smoother_.front();
  out_ = s.out_;
  stamp_ = s.stamp_;
  newest_used_ = s.newest_used_;
  return true;
}

bool DifferentiatorBank::autoBandwidth() const {
  return config_.type == DifferentiatorType::kKalman && config_.auto_bandwidth;
}

void DifferentiatorBank::chooseNoise(double dt) {
  if (!(spectral_.cutoff() > 0.0)) return;
  if (spectral_.blocks() < 2 && spectral_.atHighest() && !spectral_.fallsThroughout()) return;
  // The causal filter of positions takes only a spectrum without a floor (data without
  // noise: the highest); a crossing (noisy impacts) costs it more noise than its lag gains
  // (accuracy study, positions only: arm_impact_200hz 3.87 -> 4.88 N m, overshoot 85 ->
  // 315 %). That of the measured velocities (raiseOnly) takes it.
  if (!smoothing() && !raise_only_ && !spectral_.fallsThroughout()) return;
  setBandwidth(spectral_.cutoff(), dt);
}

void DifferentiatorBank::setBandwidth(double f, double dt) {
  if (smoothing()) f = std::max(f, kLagFloor / config_.lag);
  const double h = spacing_ > 0.0 ? spacing_ : dt;
  const double r = config_.measurement_noise;
  const double q = r * r * h * std::pow(2.0 * M_PI * f, 2 * n_);
  // The causal filter only ever raises its bandwidth: lowered, its lag grows with it.
  chosen_q_ = raise_only_ || !smoothing() ? std::max(q, default_q_) : q;
  setProcessNoise(boosted_ ? chosen_q_ * std::pow(kMissedMotionBoost, 2 * n_) : chosen_q_);
  auto_bandwidth_ = bandwidthOf(chosen_q_, h);
}

void DifferentiatorBank::followMotion(double dt) {
  const double floor = spectral_.floorLevel();  // 0: no floor (data without noise), none yet
  if (!(floor > 0.0) || !(auto_bandwidth_ > 0.0)) return;
  const int channels = std::min(spectral_channels_, channels_);
  double correlated = 0.0;
  for (int c = 0; c < channels; ++c) {
    correlated += innovation_[c] * last_innovation_[c];
    last_innovation_[c] = innovation_[c];
  }
  const double a = std::min(1.0, dt / kMissedMotionSeconds);
  missed_motion_ += a * (correlated / (floor * innovation_variance_) - missed_motion_);
  const bool boost = missed_motion_ > 1.0;
  if (boost == boosted_) return;
  boosted_ = boost;
  setProcessNoise(boost ? chosen_q_ * std::pow(kMissedMotionBoost, 2 * n_) : chosen_q_);
}

void DifferentiatorBank::endMissedMotion() {
  missed_motion_ = 0.0;
  last_innovation_.setZero();
  if (!boosted_) return;
  boosted_ = false;
  setProcessNoise(chosen_q_);
}

void DifferentiatorBank::startAtLagFloor(double dt) {
  if (!(spacing_ > 0.0) || bandwidthOf(config_.process_noise, spacing_) >= kLagFloor / config_.lag)
    return;
  setBandwidth(0.0, dt);  // the floor
  auto_bandwidth_ = 0.0;  // not the data's choice: the probe goes on
}

void DifferentiatorBank::addSpectra(double t, const double* x, double dt) {
  spectra_used_ = true;
  if (spectral_.add(t, x, state_.data() + 1, n_)) chooseNoise(dt);
  if (spectral_.cutoff() > 0.0 || auto_bandwidth_ > 0.0) return;
  if (probe_.add(t, x, state_.data() + 1, n_) && probe_.fallsThroughout())
    setBandwidth(probe_.cutoff(), dt);
}

double DifferentiatorBank::bandwidthOf(double q, double h) const {
  const double r = config_.measurement_noise;
  return std::pow(q / (r * r * h), 0.5 / n_) / (2.0 * M_PI);
}

void DifferentiatorBank::setProcessNoise(double q) {
  if (q == config_.process_noise) return;
  config_.process_noise = q;
  dt_prev_ = -1.0;
}

Eigen::Matrix3d DifferentiatorBank::smoothedNoiseGain() const {
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

bool DifferentiatorBank::isKalman() const {
  return config_.type == DifferentiatorType::kKalman ||
         config_.type == DifferentiatorType::kAdaptive;
}

void DifferentiatorBank::buildModels() {
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

void DifferentiatorBank::tuneModels(double h) {
  tuned_h_ = h;
  for (std::size_t m = 0; m < models_.size(); ++m) {
    models_[m].config_.process_noise = h * std::pow(2.0 * M_PI * bandwidths_[m], 2 * n_);
    models_[m].dt_prev_ = -1.0;
  }
}

bool DifferentiatorBank::updateAdaptive(double t, const double* x) {
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

void DifferentiatorBank::selectModel(double dt, const double* x) {
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

void DifferentiatorBank::adopt(const DifferentiatorBank& other) {
  state_ = other.state_;
  S_ = other.S_;
  noise_settled_ = false;
  out_ = other.out_;
}

void DifferentiatorBank::fitSavitzkyGolay() {
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

bool DifferentiatorBank::sameSpacing(double mid, double half) {
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

void DifferentiatorBank::factorVandermonde() {
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

void DifferentiatorBank::weightsAt(double te, double half) {
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

bool DifferentiatorBank::updateKalman(double t, const double* x) {
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
  if (autoBandwidth() && raise_only_ && smoothing() && count_ >= n) followMotion(dt);
  if (smoothing()) return smoothStep(t, dt);
  return count_ >= n;
}

void DifferentiatorBank::startSmoother(double dt) {
  constexpr double kMostExpected = 1 << 20;  // [samples] beyond: grown as they come
  const double expected = std::min(config_.lag / dt, kMostExpected);
  const int size = 2 * std::max(n_ + 1, static_cast<int>(std::lround(expected)) + 1);
  if (filtered_.cols() < size) allocateRing(size);
  ring_size_ = static_cast<int>(filtered_.cols());
}

void DifferentiatorBank::growRing(int size) {
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

void DifferentiatorBank::allocateRing(int size) {
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

double* DifferentiatorBank::rememberGain() {
  const int slot = (index_ + 1) % ring_size_;
  gains_.col((index_) % ring_size_) =
      Eigen::Map<const Eigen::VectorXd>(backward_gain_.data(), n_ * n_);
  return predicted_.col(slot).data();
}

bool DifferentiatorBank::smoothStep(double t, double dt) {
  ++index_;  // the sample whose forward step was just taken
  const int slot = index_ % ring_size_;
  filtered_.col(slot) =
      Eigen::Map<const Eigen::VectorXd>(state_.data(), static_cast<Eigen::Index>(n_) * channels_);
  ring_times_[slot] = t;
  noteInterval(dt);
  if (autoBandwidth() && auto_bandwidth_ == 0.0) startAtLagFloor(dt);
  return emitDue();
}

void DifferentiatorBank::noteInterval(double dt) {
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

bool DifferentiatorBank::emitDue() {
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

double DifferentiatorBank::pendingInterval(bool carried) const {
  if (carried && carry_next_ + 1 < carry_count_)
    return carry_times_[carry_next_ + 1] - carry_times_[carry_next_];
  if (!carried && emitted_ < index_)
    return ring_times_[(emitted_ + 1) % ring_size_] - ring_times_[emitted_ % ring_size_];
  return spacing_;
}

void DifferentiatorBank::emitOwn() {
  if (emitted_ > smoothed_through_) {
    const int block = std::max(1, (index_ - emitted_) / 2);
    smoothed_through_ = std::min(index_, emitted_ + block - 1);
    smoothBack(index_, emitted_, smoothed_through_);
  }
  emitSmoothed();
}

void DifferentiatorBank::smoothBack(int newest, int oldest, int last) {
  if (n_ == 3)
    smoothChannels<3>(newest, oldest, last);
  else
    smoothChannels<4>(newest, oldest, last);
}

template <int N>
void DifferentiatorBank::smoothChannels(int newest, int oldest, int last) {
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
void DifferentiatorBank::writeSmoothed(int t, const double* back) {
  double* out = smoothed_.col(t % ring_size_).data();
  for (int c = 0; c < channels_; ++c)
    for (int i = 0; i < 3; ++i) out[3 * c + i] = back[N * c + i];
}

void DifferentiatorBank::emitSmoothed() {
  emitted_steps_ = pass_newest_ - emitted_;
  emitted_carried_ = false;
  const int slot = emitted_ % ring_size_;
  out_ = Eigen::Map<const Eigen::MatrixXd>(smoothed_.col(slot).data(), 3, channels_);
  stamp_ = ring_times_[slot];
  newest_used_ = pass_newest_time_;
  ++emitted_;
}

void DifferentiatorBank::startKalman(double t, const double* x) {
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
    filtered_.col(0) =
        Eigen::Map<const Eigen::VectorXd>(state_.data(), static_cast<Eigen::Index>(n_) * channels_);
    ring_times_[0] = t;
  }
  out_.topRows(std::min(3, n)) = state_.topRows(std::min(3, n));
}

bool DifferentiatorBank::discretize(double dt) {
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

void DifferentiatorBank::updateKalmanGain() {
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
  gain_settled_ = count_ >= n_ && (K - K_).cwiseAbs().maxCoeff() <= 1e-15 * K.cwiseAbs().maxCoeff();
  K_ = K;
}

void DifferentiatorBank::updateNoiseGain(bool steady) {
  const SmallMatrix& F = F_;
  noise_innovation_ = (F.row(0) * S_ * F.row(0).transpose()).value() + 1.0;
  SmallMatrix A = -K_ * F.row(0);
  A += F;  // (I - K H) F with H = (1, 0, ..)
  SmallMatrix S = A * S_ * A.transpose();
  S += K_ * K_.transpose();
  noise_settled_ = steady && (S - S_).cwiseAbs().maxCoeff() <= 1e-14 * S.cwiseAbs().maxCoeff();
  S_ = S;
}

template <int N>
void DifferentiatorBank::kalmanChannels(const double* x, double* predicted) {
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

}  // namespace jle
