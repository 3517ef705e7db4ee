// The choice of the adaptive differentiator (DifferentiatorType::kAdaptive): which of its
// Kalman filters, one per bandwidth, describes the recent samples best, and the noise
// level of every channel, both from the filters' innovations (measurement minus
// prediction). ROS-free, allocation-free after construction.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>

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
  BandwidthSelection(int models, int channels, double noise, double memory);

  /// A restart of the filters (a gap): the likelihoods start again, the widest is
  /// selected; the noise estimate stays (the sensor did not change).
  void reset();

  /// The samples x (channels), the widest filter's innovations and their variance per
  /// unit noise variance when the signal is predicted exactly; dt [s] since the last
  /// sample. A sample equal to the channel's previous one (a quantised signal at rest, a
  /// constant channel) carries no information on the noise: its innovation is what is
  /// left of the filter's transient, not noise.
  void observeNoise(const double* x, const double* innovation, double variance, double dt);

  /// Filter m's innovations (channels) and their predicted variance per unit noise
  /// variance, dt [s] since the last sample.
  void score(int m, const double* innovation, double variance, double dt);

  /// The log-likelihood of filter m's recent innovations on channel c (up to a constant
  /// common to the filters), with the noise variance r2 of the channel.
  double logLikelihood(int m, int c, double r2) const {
    return -0.5 * (squares_(m, c) / r2 + log_variances_[m]);
  }

  /// Selects the filter after score() of every filter; returns it.
  int select();

  int selected() const { return best_; }

  /// Whether filter m has fallen kBehind behind the selected one on most channels.
  bool behind(int m) const;

  /// Filter m restarted from the selected one's state: its likelihood is raised to
  /// kBehind below the selected one's.
  void restarted(int m);

  /// The noise variance of channel c [unit^2]: the given one, else the estimate (0 while
  /// there is none).
  double noiseVariance(int c) const;

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
