// The running spectrum and its cutoff rules of spectral_cutoff.hpp.
#include <joint_load_estimator/filters/spectral_cutoff.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <complex>

namespace jle {
namespace {

// static_cast<int>(std::lround(v)) (halves away from zero), without the library call
// where |v| < 2^30: v - trunc(v) is exact there.
int roundToInt(double v) {
  if (!(std::fabs(v) < 1073741824.0)) return static_cast<int>(std::lround(v));
  const int i = static_cast<int>(v);
  const double rest = v - i;
  return rest >= 0.5 ? i + 1 : rest <= -0.5 ? i - 1 : i;
}

}  // namespace

Fft::Fft(int capacity) : capacity_(capacity) {
  if (capacity <= 0) return;
  int log2cap = 0;
  while ((1 << log2cap) < capacity) ++log2cap;
  assert((1 << log2cap) == capacity);
  // The capacity's twiddles, then each smaller stage's as every (capacity / len)-th of
  // them: -2 pi k / len and -2 pi (k capacity / len) / capacity are the same number.
  twiddle_.resize(static_cast<std::size_t>(std::max(capacity - 1, 0)));
  const int top = capacity / 2 - 1;
  for (int k = 0; k < capacity / 2; ++k)
    twiddle_[static_cast<std::size_t>(top + k)] = std::polar(1.0, -2.0 * M_PI * k / capacity);
  for (int len = 2; len < capacity; len <<= 1)
    for (int k = 0; k < len / 2; ++k)
      twiddle_[static_cast<std::size_t>(len / 2 - 1 + k)] =
          twiddle_[static_cast<std::size_t>(top + k * (capacity / len))];
  // The bit reversal of the capacity's indices; size 2^m's is it shifted right.
  std::vector<int> reversed(static_cast<std::size_t>(capacity), 0);
  for (int i = 1; i < capacity; ++i)
    reversed[static_cast<std::size_t>(i)] =
        (reversed[static_cast<std::size_t>(i >> 1)] >> 1) | ((i & 1) << (log2cap - 1));
  // Fewer than capacity pairs in all: the sizes' halves add up to capacity - 1/2.
  swaps_.resize(static_cast<std::size_t>(2 * capacity));
  swap_begin_.assign(static_cast<std::size_t>(log2cap + 2), 0);
  int* out = swaps_.data();
  for (int m = 0; m <= log2cap; ++m) {
    for (int i = 0; i < (1 << m); ++i) {
      const int j = reversed[static_cast<std::size_t>(i)] >> (log2cap - m);
      if (i >= j) continue;
      *out++ = i;
      *out++ = j;
    }
    swap_begin_[static_cast<std::size_t>(m + 1)] = static_cast<int>(out - swaps_.data());
  }
}

void Fft::transform(std::complex<double>* x, int n) const {
  assert(n >= 1 && n <= capacity_ && (n & (n - 1)) == 0);
  int log2n = 0;
  while ((1 << log2n) < n) ++log2n;
  permute(x, log2n);
  // Arrays of std::complex<double> are arrays of (real, imaginary) pairs ([complex.numbers]).
  double* d = reinterpret_cast<double*>(x);
  int len = 2;
  if (n >= 4) {
    firstStages(d, n);
    len = 8;
  }
  for (; 2 * len <= n; len <<= 2) stagePair(d, n, len);
  if (len <= n) stage(d, n, len);
}

void Fft::permute(std::complex<double>* x, int log2n) const {
  const int* pair = swaps_.data() + swap_begin_[static_cast<std::size_t>(log2n)];
  const int* end = swaps_.data() + swap_begin_[static_cast<std::size_t>(log2n + 1)];
  for (; pair != end; pair += 2) std::swap(x[pair[0]], x[pair[1]]);
}

void Fft::firstStages(double* x, int n) {
  for (double* q = x; q != x + 2 * n; q += 8) {
    // len 2: (0, 1) and (2, 3) with twiddle 1.
    const double a0r = q[0] + q[2], a0i = q[1] + q[3], a1r = q[0] - q[2], a1i = q[1] - q[3];
    const double a2r = q[4] + q[6], a2i = q[5] + q[7], a3r = q[4] - q[6], a3i = q[5] - q[7];
    // len 4: (0, 2) with twiddle 1, (1, 3) with -i: -i (a + i b) = b - i a.
    q[0] = a0r + a2r;
    q[1] = a0i + a2i;
    q[4] = a0r - a2r;
    q[5] = a0i - a2i;
    q[2] = a1r + a3i;
    q[3] = a1i - a3r;
    q[6] = a1r - a3i;
    q[7] = a1i + a3r;
  }
}

void Fft::stagePair(double* x, int n, int len) const {
  const int h = len / 2;
  const double* w1 = reinterpret_cast<const double*>(twiddle_.data() + (h - 1));    // len's
  const double* w2 = reinterpret_cast<const double*>(twiddle_.data() + (len - 1));  // 2 len's
  for (double* q0 = x; q0 != x + 2 * n; q0 += 4 * len) {
    double *q1 = q0 + len, *q2 = q1 + len, *q3 = q2 + len;  // the quarters, h points each
    for (int k = 0; k < 2 * h; k += 2) {
      // Stage len: (q0, q1) and (q2, q3), twiddle w1[k].
      const double wr = w1[k], wi = w1[k + 1];
      const double t1r = q1[k] * wr - q1[k + 1] * wi, t1i = q1[k] * wi + q1[k + 1] * wr;
      const double t3r = q3[k] * wr - q3[k + 1] * wi, t3i = q3[k] * wi + q3[k + 1] * wr;
      const double p0r = q0[k] + t1r, p0i = q0[k + 1] + t1i;
      const double p1r = q0[k] - t1r, p1i = q0[k + 1] - t1i;
      const double p2r = q2[k] + t3r, p2i = q2[k + 1] + t3i;
      const double p3r = q2[k] - t3r, p3i = q2[k + 1] - t3i;
      // Stage 2 len: (q0, q2) with twiddle w2[k], (q1, q3) with w2[k + h].
      const double vr = w2[k], vi = w2[k + 1], ur = w2[k + len], ui = w2[k + len + 1];
      const double s2r = p2r * vr - p2i * vi, s2i = p2r * vi + p2i * vr;
      const double s3r = p3r * ur - p3i * ui, s3i = p3r * ui + p3i * ur;
      q0[k] = p0r + s2r;
      q0[k + 1] = p0i + s2i;
      q2[k] = p0r - s2r;
      q2[k + 1] = p0i - s2i;
      q1[k] = p1r + s3r;
      q1[k + 1] = p1i + s3i;
      q3[k] = p1r - s3r;
      q3[k + 1] = p1i - s3i;
    }
  }
}

void Fft::stage(double* x, int n, int len) const {
  const int h = len / 2;
  const double* w = reinterpret_cast<const double*>(twiddle_.data() + (h - 1));
  for (double* a = x; a != x + 2 * n; a += 2 * len) {
    double* b = a + len;
    for (int k = 0; k < 2 * h; k += 2) {
      const double tr = b[k] * w[k] - b[k + 1] * w[k + 1];
      const double ti = b[k] * w[k + 1] + b[k + 1] * w[k];
      const double ar = a[k], ai = a[k + 1];
      a[k] = ar + tr;
      a[k + 1] = ai + ti;
      b[k] = ar - tr;
      b[k + 1] = ai - ti;
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
  samples_.assign(static_cast<std::size_t>(kMaxBlock + 1) * channels_, 0.0);
  block_samples_.assign(samples_.size(), 0.0);
  last_.setZero(channels_);
  fill_.setZero(channels_);
  spectrum_.setZero(kMaxBlock / 2 + 1);
  part_.setZero(kMaxBlock / 2 + 1);
  window_.setZero(kMaxBlock);
  whitening_.setZero(kMaxBlock / 2 + 1);
  tan_k_.setZero(kMaxBlock / 2 + 1);
}

// __restrict (x and rate are only read; last_ and samples_, written, are reached through
// one pointer each): the loop over the channels is vectorised without run-time overlap
// checks (some 35 instructions of 200 a sample with 7 channels).
bool SpectralCutoff::add(double t, const double* __restrict x, const double* __restrict rate,
                         int stride) {
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
    steps = roundToInt((t - grid_time_) / h_);
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
  const double offset = grid_time_ - t;
  double* __restrict last = last_.data();
  bool chosen = false;
  if (steps > 1) {  // missing samples: linear interpolation from the last to this one
    double* fill = fill_.data();
    for (int c = 0; c < channels_; ++c) fill[c] = x[c] + rate[c * stride] * offset;
    for (int s = 1; s < steps; ++s) {
      const double f = static_cast<double>(s) / steps;
      chosen = accumulate([&](int c) { return last[c] + f * (fill[c] - last[c]); }) || chosen;
    }
  }
  chosen = accumulate([&](int c) { return last[c] = x[c] + rate[c * stride] * offset; }) || chosen;
  have_last_ = true;
  return chosen;
}

void SpectralCutoff::endBlock() {
  filled_ = 0;
  in_sum_ = 0;  // the partial sum in row filled_ is written over
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

template <class Sample>
bool SpectralCutoff::accumulate(Sample sample) {
  const bool chosen = step_ >= 0 && step();
  {  // The mean of decimation_ samples, summed in row filled_ itself (from 0 at its first);
     // row the only access to it in this block (__restrict).
    double* __restrict row = samples_.data() + static_cast<std::size_t>(filled_) * channels_;
    const bool first_in_row = in_sum_ == 0;
    for (int c = 0; c < channels_; ++c) row[c] = (first_in_row ? 0.0 : row[c]) + sample(c);
  }
  if (++in_sum_ < decimation_) return chosen;
  return completeRow() || chosen;
}

bool SpectralCutoff::completeRow() {
  double* row = samples_.data() + static_cast<std::size_t>(filled_) * channels_;
  if (decimation_ > 1)
    for (int c = 0; c < channels_; ++c) row[c] /= decimation_;
  in_sum_ = 0;
  if (++filled_ <= block_) return false;
  // The first block holds the filters' start (rates).
  bool chosen = false;
  const bool first = ++seen_ == 1 && !first_block_;
  if (!first) {
    while (step_ >= 0) chosen = step() || chosen;
    block_samples_.swap(samples_);
    step_ = 0;
  }
  const double* last = (first ? samples_ : block_samples_).data();  // next differences
  std::copy(last + static_cast<std::size_t>(block_) * channels_,
            last + static_cast<std::size_t>(block_ + 1) * channels_, samples_.data());
  filled_ = 1;
  return chosen;
}

bool SpectralCutoff::step() {
  if (step_ < channels_) {
    transformStep(step_++);
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

void SpectralCutoff::transformStep(int s) {
  if (s % 2 == 1) {
    unpackPair();
    return;
  }
  if (s == 0) part_.setZero();
  // Channel s's windowed differences, channel s + 1's as the imaginary part (none: 0).
  const bool pair = s + 1 < channels_;
  const int m = channels_;  // row j of block_samples_ from j * m
  const double* a = block_samples_.data() + s;
  const double* b = pair ? a + 1 : a;
  double* z = reinterpret_cast<double*>(buffer_.data());
  for (int j = 0; j < block_; ++j) {
    z[2 * j] = window_[j] * (a[(j + 1) * m] - a[j * m]);
    z[2 * j + 1] = pair ? window_[j] * (b[(j + 1) * m] - b[j * m]) : 0.0;
  }
  fft_.transform(buffer_.data(), block_);
  if (pair) return;  // the next step unpacks
  for (int k = 1; k <= block_ / 2; ++k)
    part_[k] += std::norm(buffer_[static_cast<std::size_t>(k)]) * whitening_[k] / window_norm_;
}

void SpectralCutoff::unpackPair() {
  // Z = A + i B of two real sequences: A_k = (Z_k + conj(Z_{n-k})) / 2 and
  // B_k = (Z_k - conj(Z_{n-k})) / (2 i), k = 1 .. n / 2 (so n - k < n). The spectrum sums
  // the channels, and |A_k|^2 + |B_k|^2 = (|Z_k|^2 + |Z_{n-k}|^2) / 2 (the cross terms
  // cancel): the pair's power without the A and B of each.
  for (int k = 1; k <= block_ / 2; ++k) {
    const double both = 0.5 * (std::norm(buffer_[static_cast<std::size_t>(k)]) +
                               std::norm(buffer_[static_cast<std::size_t>(block_ - k)]));
    part_[k] += both * whitening_[k] / window_norm_;
  }
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
