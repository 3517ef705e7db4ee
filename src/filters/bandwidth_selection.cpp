// The adaptive differentiator's choice of bandwidth of bandwidth_selection.hpp.
#include <joint_load_estimator/filters/bandwidth_selection.hpp>

#include <algorithm>
#include <cmath>

namespace jle {

BandwidthSelection::BandwidthSelection(int models, int channels, double noise, double memory)
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

void BandwidthSelection::reset() {
  squares_.setZero();
  log_variances_.setZero();
  best_ = models_ - 1;
}

void BandwidthSelection::observeNoise(const double* x, const double* innovation, double variance,
                                      double dt) {
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

void BandwidthSelection::score(int m, const double* innovation, double variance, double dt) {
  const double forget = std::exp(-dt / memory_);
  log_variances_[m] = forget * log_variances_[m] + std::log(variance);
  for (int c = 0; c < channels_; ++c)
    squares_(m, c) = forget * squares_(m, c) + innovation[c] * innovation[c] / variance;
}

int BandwidthSelection::select() {
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

bool BandwidthSelection::behind(int m) const {
  int behind = 0, active = 0;
  for (int c = 0; c < channels_; ++c) {
    if (!chooses(c)) continue;
    ++active;
    const double r2 = noiseVariance(c);
    if (logLikelihood(m, c, r2) < logLikelihood(best_, c, r2) - kBehind) ++behind;
  }
  return active > 0 && 2 * behind >= active;
}

void BandwidthSelection::restarted(int m) {
  for (int c = 0; c < channels_; ++c) {
    const double r2 = noiseVariance(c);
    if (!chooses(c)) continue;
    // squares such that logLikelihood(m) = logLikelihood(best) - kBehind
    const double target = logLikelihood(best_, c, r2) - kBehind;
    squares_(m, c) =
        std::min(squares_(m, c), std::max(0.0, r2 * (-2.0 * target - log_variances_[m])));
  }
}

double BandwidthSelection::noiseVariance(int c) const {
  if (fixed_variance_ > 0.0) return fixed_variance_;
  return noise_time_[c] > 0.0 ? std::exp(log_variance_[c]) : 0.0;
}

}  // namespace jle
