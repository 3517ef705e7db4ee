// The running spectrum and its cutoff rules of spectral_cutoff.hpp.
#include <joint_load_estimator/filters/spectral_cutoff.hpp>

#include <algorithm>
#include <cmath>
#include <complex>

namespace jle {

Fft::Fft(int capacity) : capacity_(capacity), twiddle_(static_cast<std::size_t>(capacity / 2)) {
  for (int k = 0; k < capacity / 2; ++k)
    twiddle_[static_cast<std::size_t>(k)] = std::polar(1.0, -2.0 * M_PI * k / capacity);
}

void Fft::transform(std::complex<double>* x, int n) const {
  for (int i = 1, j = 0; i < n; ++i) {  // bit reversal
    int bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(x[i], x[j]);
  }
  for (int len = 2; len <= n; len <<= 1) {
    const int step = capacity_ / len;
    for (int start = 0; start < n; start += len)
      for (int k = 0; k < len / 2; ++k) {
        const std::complex<double> a = x[start + k];
        const std::complex<double> b =
            x[start + k + len / 2] * twiddle_[static_cast<std::size_t>(k * step)];
        x[start + k] = a + b;
        x[start + k + len / 2] = a - b;
      }
  }
}

SpectralCutoff::SpectralCutoff(int channels, double lowest, double highest, Rule rule,
                               double block_seconds, bool first_block)
    : channels_(channels),
      lowest_(lowest),
      highest_(highest),
      block_seconds_(block_seconds),
      first_block_(first_block),
      rule_(rule) {
  if (channels_ <= 0) return;
  // Every buffer at the largest block (the grid is at most kMaxRate): none grows later.
  fft_ = Fft(kMaxBlock);
  buffer_.resize(static_cast<std::size_t>(kMaxBlock));
  samples_.setZero(kMaxBlock + 1, channels_);
  block_samples_.setZero(kMaxBlock + 1, channels_);
  sum_.setZero(channels_);
  last_.setZero(channels_);
  fill_.setZero(channels_);
  gap_.setZero(channels_);
  spectrum_.setZero(kMaxBlock / 2 + 1);
  part_.setZero(kMaxBlock / 2 + 1);
  window_.setZero(kMaxBlock);
  whitening_.setZero(kMaxBlock / 2 + 1);
  tan_k_.setZero(kMaxBlock / 2 + 1);
}

bool SpectralCutoff::add(double t, const double* x, const double* rate, int stride) {
  if (channels_ <= 0) return false;
  if (!started_) {
    if (have_first_ && t > first_time_) intervals_[first_count_++] = t - first_time_;
    have_first_ = true;
    first_time_ = t;
    if (first_count_ < kFirstIntervals) return false;
    std::nth_element(intervals_, intervals_ + kFirstIntervals / 2, intervals_ + kFirstIntervals);
    start(intervals_[kFirstIntervals / 2]);
  }
  int steps = 1;
  if (have_last_) {
    steps = static_cast<int>(std::lround((t - grid_time_) / h_));
    if (steps > kMaxFill + 1) endBlock();
  }
  if (!have_last_) {
    grid_time_ = t;
    steps = 1;
  } else {
    steps = std::max(steps, 1);
    grid_time_ += steps * h_;
    grid_time_ += kTrack * (t - grid_time_);
  }
  // The sample moved to the grid's instant along its rate: what the smoother is given
  // (x at t) seen at regular instants, so that jitter in the stamps is noise here too.
  for (int c = 0; c < channels_; ++c) fill_[c] = x[c] + rate[c * stride] * (grid_time_ - t);
  bool chosen = false;
  for (int s = 1; s < steps; ++s) {  // missing samples: linear interpolation
    const double f = static_cast<double>(s) / steps;
    for (int c = 0; c < channels_; ++c) gap_[c] = last_[c] + f * (fill_[c] - last_[c]);
    chosen = accumulate(gap_.data()) || chosen;
  }
  chosen = accumulate(fill_.data()) || chosen;
  last_ = fill_;
  have_last_ = true;
  return chosen;
}

void SpectralCutoff::endBlock() {
  filled_ = 0;
  in_sum_ = 0;
  sum_.setZero();
  have_last_ = false;
}

int SpectralCutoff::pendingSteps() const {
  if (step_ < 0) return 0;
  const int scored = step_ <= channels_ ? 0 : scored_;
  const int scoring = rule_ == Rule::kNoiseFloor
                          ? 1
                          : std::max(1, (count_ - scored + kScoresPerStep - 1) / kScoresPerStep);
  return std::max(0, channels_ + 1 - step_) + scoring;
}

double SpectralCutoff::bandwidth() const {
  if (!(lowest_ <= highest_) || channels_ <= 0) return 0.0;
  return cutoff_ > 0.0 ? cutoff_ : lowest_;
}

void SpectralCutoff::start(double h) {
  started_ = true;
  const double max_rate = rule_ == Rule::kNoiseFloor ? kMaxRateNoiseFloor : kMaxRate;
  decimation_ = std::max(1, static_cast<int>(std::floor(1.0 / (h * max_rate) + 1e-9)));
  h_ = h;
  const double hd = h * decimation_;
  block_ = 16;
  while (block_ * hd < 0.9 * block_seconds_ && block_ < kMaxBlock) block_ *= 2;
  window_norm_ = 0.0;
  for (int j = 0; j < block_; ++j) {
    window_[j] = 0.5 - 0.5 * std::cos(2.0 * M_PI * (j + 0.5) / block_);
    window_norm_ += window_[j] * window_[j];
  }
  for (int k = 0; k <= block_ / 2; ++k) {
    const double s = std::sin(M_PI * k / block_);
    whitening_[k] = k == 0 ? 0.0 : 1.0 / (4.0 * s * s);
    tan_k_[k] = k == block_ / 2 ? 1e300 : std::tan(M_PI * k / block_);
  }
  const double top = std::min(highest_, 0.45 / hd);  // the candidates
  count_ = 0;
  for (double f = lowest_; f <= top * (1.0 + 1e-12) && count_ < kGridSize; f *= kGridRatio)
    grid_[count_++] = f;
}

bool SpectralCutoff::accumulate(const double* x) {
  bool chosen = step_ >= 0 && step();
  for (int c = 0; c < channels_; ++c) sum_[c] += x[c];
  if (++in_sum_ < decimation_) return chosen;
  samples_.row(filled_) = sum_.transpose() / decimation_;
  sum_.setZero();
  in_sum_ = 0;
  if (++filled_ <= block_) return chosen;
  // The first block holds the filters' start (rates).
  const bool first = ++seen_ == 1 && !first_block_;
  if (!first) {
    while (step_ >= 0) chosen = step() || chosen;
    block_samples_.swap(samples_);
    step_ = 0;
  }
  samples_.row(0) = (first ? samples_ : block_samples_).row(block_);  // next differences
  filled_ = 1;
  return chosen;
}

bool SpectralCutoff::step() {
  if (step_ < channels_) {
    transformChannel(step_++);
    return false;
  }
  if (step_ == channels_) {
    addSpectrum();
    scored_ = 0;
    ++step_;
    return false;
  }
  const bool done = scoreSome();
  if (done) step_ = -1;
  return done;
}

void SpectralCutoff::transformChannel(int c) {
  if (c == 0) part_.setZero();
  for (int j = 0; j < block_; ++j)
    buffer_[static_cast<std::size_t>(j)] =
        window_[j] * (block_samples_(j + 1, c) - block_samples_(j, c));
  fft_.transform(buffer_.data(), block_);
  for (int k = 1; k <= block_ / 2; ++k)
    part_[k] += std::norm(buffer_[static_cast<std::size_t>(k)]) * whitening_[k] / window_norm_;
}

void SpectralCutoff::addSpectrum() {
  ++blocks_;
  const double seconds = blocks_ * block_ * h_ * decimation_;
  const double weight =
      seconds <= kMemorySeconds ? 1.0 / blocks_ : block_ * h_ * decimation_ / kMemorySeconds;
  spectrum_ += weight * (part_ - spectrum_);
}

bool SpectralCutoff::scoreSome() {
  const double hd = h_ * decimation_;
  if (rule_ == Rule::kNoiseFloor) {
    scored_ = count_;
    chooseNoiseFloor(hd);
    return true;
  }
  const int end = std::min(count_, scored_ + kScoresPerStep);
  for (; scored_ < end; ++scored_) {
    scores_[scored_] = score(grid_[scored_] * hd);
    if (scored_ == 0 || scores_[scored_] < lowest_score_) lowest_score_ = scores_[scored_];
  }
  if (scored_ < count_) return false;
  if (count_ == 0) return true;
  for (int j = 0; j < count_; ++j)
    if (scores_[j] <= (1.0 + kTolerance) * lowest_score_) {
      cutoff_ = grid_[j];
      break;
    }
  return true;
}

void SpectralCutoff::chooseNoiseFloor(double hd) {
  const double bin = 1.0 / (block_ * hd);  // [Hz] between bins
  int bands = 0;
  for (double lo = lowest_; bands < kMaxBands; lo *= kBandRatio) {
    const int first = std::max(1, static_cast<int>(std::ceil(lo / bin)));
    const int last =
        std::min(block_ / 2 - 1, static_cast<int>(std::ceil(kBandRatio * lo / bin)) - 1);
    if (first > block_ / 2 - 1) break;
    if (last < first) continue;  // no bin in the band: the next one
    double sum = 0.0;
    for (int k = first; k <= last; ++k) sum += spectrum_[k];
    band_level_[bands] = band_raw_[bands] = std::max(1e-300, sum / (last - first + 1));
    band_centre_[bands++] = std::sqrt(first * last) * bin;
  }
  const double top = std::min(highest_, 0.45 / hd);
  on_bound_ = at_highest_ = true;
  cutoff_ = top;
  floor_level_ = 0.0;
  falls_ = false;
  if (bands < 2) return;
  for (int j = bands - 2; j >= 0; --j)
    band_level_[j] = std::max(band_level_[j], band_level_[j + 1]);  // the envelope
  bool flat = false;
  for (int knee = 0; knee < bands; ++knee) {
    int end = knee;  // the band an octave above
    while (end + 1 < bands && band_centre_[end] < 1.95 * band_centre_[knee]) ++end;
    if (band_centre_[end] < 1.9 * band_centre_[knee]) break;  // no octave left: no floor
    const double slope = std::log(band_level_[end] / band_level_[knee]) /
                         std::log(band_centre_[end] / band_centre_[knee]);
    flat = flat || slope > kFlatSlope;
    if (slope > kFlatSlope && band_level_[knee] < kFloorBelowPeak * band_level_[0]) {
      crossFloor(knee, end, top);
      return;
    }
  }
  falls_ = !flat;
}

void SpectralCutoff::crossFloor(int knee, int end, double top) {
  for (int j = knee; j <= end; ++j) floor_[j - knee] = band_raw_[j];
  const int m = end - knee + 1;
  std::nth_element(floor_, floor_ + m / 2, floor_ + m);
  floor_level_ = floor_[m / 2];
  const double twice = 2.0 * floor_level_;
  // The envelope again up to the floor's octave only: noise that rises above it (a
  // hump near the Nyquist rate) is not motion coming down to the floor.
  for (int j = end, k = end; j >= 0; --j)
    band_level_[j] = j == k ? band_raw_[j] : std::max(band_raw_[j], band_level_[j + 1]);
  int below = 0;
  while (below <= end && band_level_[below] > twice) ++below;
  if (below == 0 || below > end) {
    cutoff_ = below == 0 ? lowest_ : top;
    at_highest_ = below > end;
    return;
  }
  const int c = below - 1;
  const double u = std::log(band_level_[c] / twice) / std::log(band_level_[c] / band_level_[c + 1]);
  const double f =
      std::exp(std::log(band_centre_[c]) + u * std::log(band_centre_[c + 1] / band_centre_[c]));
  cutoff_ = std::max(lowest_, std::min(top, f));
  at_highest_ = cutoff_ >= 0.99 * top;
  on_bound_ = cutoff_ <= 1.01 * lowest_ || at_highest_;
}

double SpectralCutoff::score(double w) const {
  const double inv_tc = 1.0 / std::tan(M_PI * w);
  double residual = 0.0, trace = 1.0;
  for (int k = 1; k <= block_ / 2; ++k) {
    const double r = tan_k_[k] * inv_tc;
    const double r2 = r * r, r4 = r2 * r2;
    const double g = 1.0 / (1.0 + r4 * r4);
    const double both = k == block_ / 2 ? 1.0 : 2.0;
    residual += both * (1.0 - g) * (1.0 - g) * spectrum_[k];
    trace += both * g;
  }
  const double dof = 1.0 - trace / block_;
  return residual / block_ / (dof * dof);
}

}  // namespace jle
