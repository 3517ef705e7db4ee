// The choice of the adaptive differentiator (DifferentiatorType::kAdaptive): which of its
// Kalman filters, one per bandwidth, describes the recent samples best, and the noise
// level of every channel, both from the filters' innovations (measurement minus
// prediction). ROS-free, allocation-free after construction.
#pragma once

#include <joint_load_estimator/eigen_abi.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace jle {

/// Per channel: the position noise estimated from the widest filter's innovations, and the
/// log-likelihood of every filter's innovations with exponential forgetting, evaluated
/// with the current noise estimate (the sums of squared innovations are kept, so that the
/// estimate of the first samples does not linger in the choice). The selected
/// filter is the median over the channels of each channel's likeliest one, so that a
/// minority of odd channels (a constant wrench, a noise-free synthetic one) does not
/// decide for the rest. Filters are numbered from the narrowest to the widest.
class BandwidthSelection {
 public:
  /// Time constant of the noise estimate's memory [s] (the first samples are averaged
  /// equally until there are this many seconds of them): a sensor's noise is a property
  /// of the sensor, and the widest filter's innovations are correlated, which leaves
  /// fewer independent ones than samples.
  static constexpr double kNoiseMemory = 5.0;
  /// Log-likelihood [nats] by which a filter narrower than the selected one may fall
  /// behind before it restarts from the selected one's state (after an impact its memory
  /// describes a motion that ended).
  static constexpr double kBehind = 10.0;
  /// Informative samples of a channel before its noise estimate takes part in the choice.
  static constexpr int kNoiseSamples = 16;
  /// E[log z^2] for a standard normal z (-gamma - log 2).
  static constexpr double kLogChiSquareMean = -1.2703628454614782;

  BandwidthSelection() = default;
  /// noise: the position noise's standard deviation [unit] if known, 0 to estimate it;
  /// memory: the time constant of the likelihood's memory [s].
  BandwidthSelection(int models, int channels, double noise, double memory)
      : models_(models),
        channels_(channels),
        fixed_variance_(noise * noise),
        memory_(memory),
        squares_(Eigen::MatrixXd::Zero(models, channels)),
        log_variances_(Eigen::VectorXd::Zero(models)),
        log_variance_(Eigen::VectorXd::Zero(channels)),
        noise_time_(Eigen::VectorXd::Zero(channels)),
        noise_samples_(Eigen::VectorXi::Zero(channels)),
        last_(Eigen::VectorXd::Constant(channels, std::nan(""))),
        best_per_channel_(Eigen::VectorXi::Zero(channels)) {
    reset();
  }

  /// A restart of the filters (a gap): the likelihoods start again, the widest is
  /// selected; the noise estimate stays (the sensor did not change).
  void reset() {
    squares_.setZero();
    log_variances_.setZero();
    best_ = models_ - 1;
  }

  /// The samples x (channels), the widest filter's innovations and their variance per
  /// unit noise variance when the signal is predicted exactly; dt [s] since the last
  /// sample. A sample equal to the channel's previous one (a quantised signal at rest, a
  /// constant channel) carries no information on the noise: its innovation is what is
  /// left of the filter's transient, not noise.
  void observeNoise(const double* x, const double* innovation, double variance, double dt) {
    if (fixed_variance_ > 0.0) return;
    for (int c = 0; c < channels_; ++c) {
      const bool repeated = x[c] == last_[c];
      last_[c] = x[c];
      const double z2 = innovation[c] * innovation[c] / variance;
      if (repeated || !(z2 > 0.0) || !std::isfinite(z2)) continue;
      noise_time_[c] += dt;
      ++noise_samples_[c];
      const double w = std::min(1.0, dt / std::min(noise_time_[c], kNoiseMemory));
      log_variance_[c] += w * (std::log(z2) - kLogChiSquareMean - log_variance_[c]);
    }
  }

  /// Filter m's innovations (channels) and their predicted variance per unit noise
  /// variance, dt [s] since the last sample.
  void score(int m, const double* innovation, double variance, double dt) {
    const double forget = std::exp(-dt / memory_);
    log_variances_[m] = forget * log_variances_[m] + std::log(variance);
    for (int c = 0; c < channels_; ++c)
      squares_(m, c) = forget * squares_(m, c) + innovation[c] * innovation[c] / variance;
  }

  /// The log-likelihood of filter m's recent innovations on channel c (up to a constant
  /// common to the filters), with the noise variance r2 of the channel.
  double logLikelihood(int m, int c, double r2) const {
    return -0.5 * (squares_(m, c) / r2 + log_variances_[m]);
  }

  /// Selects the filter after score() of every filter; returns it.
  int select() {
    int active = 0;
    for (int c = 0; c < channels_; ++c) {
      const double r2 = noiseVariance(c);
      if (!chooses(c)) continue;
      int best = models_ - 1;
      for (int m = models_ - 2; m >= 0; --m)
        if (logLikelihood(m, c, r2) > logLikelihood(best, c, r2)) best = m;
      best_per_channel_[active++] = best;
    }
    if (active == 0) return best_ = models_ - 1;
    // The upper median: with an even count, the wider of the two middle choices.
    int* first = best_per_channel_.data();
    std::nth_element(first, first + active / 2, first + active);
    return best_ = first[active / 2];
  }

  int selected() const { return best_; }

  /// Whether filter m has fallen kBehind behind the selected one on most channels.
  bool behind(int m) const {
    int behind = 0, active = 0;
    for (int c = 0; c < channels_; ++c) {
      if (!chooses(c)) continue;
      ++active;
      const double r2 = noiseVariance(c);
      if (logLikelihood(m, c, r2) < logLikelihood(best_, c, r2) - kBehind) ++behind;
    }
    return active > 0 && 2 * behind >= active;
  }

  /// Filter m restarted from the selected one's state: its likelihood is raised to
  /// kBehind below the selected one's.
  void restarted(int m) {
    for (int c = 0; c < channels_; ++c) {
      const double r2 = noiseVariance(c);
      if (!chooses(c)) continue;
      // squares such that logLikelihood(m) = logLikelihood(best) - kBehind
      const double target = logLikelihood(best_, c, r2) - kBehind;
      squares_(m, c) =
          std::min(squares_(m, c), std::max(0.0, r2 * (-2.0 * target - log_variances_[m])));
    }
  }

  /// The noise variance of channel c [unit^2]: the given one, else the estimate (0 while
  /// there is none).
  double noiseVariance(int c) const {
    if (fixed_variance_ > 0.0) return fixed_variance_;
    return noise_time_[c] > 0.0 ? std::exp(log_variance_[c]) : 0.0;
  }

  /// Whether channel c takes part in the choice: its noise is known, or estimated from
  /// kNoiseSamples informative samples.
  bool chooses(int c) const { return fixed_variance_ > 0.0 || noise_samples_[c] >= kNoiseSamples; }

 private:
  int models_ = 1;
  int channels_ = 0;
  int best_ = 0;
  double fixed_variance_ = 0.0;
  double memory_ = 1.0;
  Eigen::MatrixXd squares_;        // models x channels: forgotten sums of nu^2 / s
  Eigen::VectorXd log_variances_;  // per model: forgotten sum of log s
  Eigen::VectorXd log_variance_;   // per channel: log of the noise variance estimate
  Eigen::VectorXd noise_time_;     // per channel: seconds of informative innovations
  Eigen::VectorXi noise_samples_;  // per channel: their count
  Eigen::VectorXd last_;           // per channel: the previous sample
  Eigen::VectorXi best_per_channel_;
};

}  // namespace jle
