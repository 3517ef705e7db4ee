// The bandwidth of the adaptive smoother (DifferentiatorType::kAdaptive with a lag): the
// cutoff that generalised cross-validation of the zero-phase 4th-order Butterworth
// (zero_phase.hpp, CutoffRule::kGcv) would choose on the record so far, computed from a
// running spectrum of the samples instead of filtering the record at every candidate.
// ROS-free, allocation-free after construction.
#pragma once

#include <joint_load_estimator/eigen_abi.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <vector>

namespace jle {

/// In place radix-2 discrete Fourier transform of n = 2^k <= capacity points (forward,
/// no scaling: X_k = sum_j x_j exp(-2 pi i j k / n)); the twiddles of the capacity are
/// computed once, and every smaller size uses every (capacity / n)-th of them.
class Fft {
 public:
  Fft() = default;
  explicit Fft(int capacity)
      : capacity_(capacity), twiddle_(static_cast<std::size_t>(capacity / 2)) {
    for (int k = 0; k < capacity / 2; ++k)
      twiddle_[static_cast<std::size_t>(k)] = std::polar(1.0, -2.0 * M_PI * k / capacity);
  }
  int capacity() const { return capacity_; }

  void transform(std::complex<double>* x, int n) const {
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

 private:
  int capacity_ = 0;
  std::vector<std::complex<double>> twiddle_;
};

/// The GCV cutoff of the record so far, from its spectrum. Each sample is moved along
/// its rate (an estimate the caller gives) to the instant of a regular grid whose interval
/// h is the median of the first kFirstIntervals intervals and which follows the stamps
/// slowly (kTrack): what the smoother is given, x at its stamp, seen at regular instants,
/// so that jitter in the stamps is noise here as it is to the smoother. Missing samples
/// (up to kMaxFill intervals) are interpolated linearly; a longer gap ends the current
/// block. The grid is averaged in groups down to at most kMaxRate and cut into blocks of
/// about block_seconds (kBlockSeconds by default; a power of two of samples); the first
/// block is left out (it holds the start of the filters that give the rates). Each block's first
/// differences (which flatten the spectrum, so that the window leaks little of the motion into the
/// noise band) are windowed (Hann) and transformed; the positions' spectrum is theirs divided by |1
/// - exp(-i w)|^2, summed over the channels that choose and averaged over the blocks (equally for
/// the first kMemorySeconds, then with that memory). The score
///   GCV(w) = mean_k (1 - G_k(w))^2 P_k / (1 - mean_k G_k(w))^2,
/// G_k the zero-phase filter's gain 1 / (1 + (tan(pi k / n) / tan(pi w))^8), is the one
/// zero_phase.cpp's gcvScore evaluates in the time domain (the circulant approximation
/// of the same smoother); it is searched on a grid of ratio kGridRatio, and the narrowest
/// cutoff within kTolerance of the minimum is chosen.
/// The work of a completed block (a transform per channel, the spectrum, the scores) is
/// spread over the grid samples that follow it, one step per sample (a channel's
/// transform, or kScoresPerStep scores), so that no sample's call carries the whole of it:
/// the choice takes effect pendingSteps() samples after the block, the same choice at the
/// same sample on every run (the node and process_bag agree).
class SpectralCutoff {
 public:
  static constexpr double kBlockSeconds = 2.0;
  static constexpr double kMemorySeconds = 30.0;
  static constexpr double kMaxRate = 1000.0;  ///< [Hz] above it, samples are averaged
  /// [Hz] Rule::kNoiseFloor's: the floor and the crossing lie far below it, and the
  /// transforms cost half of kMaxRate's (the smoothed stream's default runs it).
  static constexpr double kMaxRateNoiseFloor = 500.0;
  static constexpr int kMaxFill = 10;     ///< missing samples filled in a block at most
  static constexpr int kMaxBlock = 4096;  ///< samples of a block at most (2 s at 2 kHz)
  static constexpr double kGridRatio = 1.05;
  static constexpr int kGridSize = 128;  ///< candidates at most (1.05^128: 500x)
  static constexpr double kTolerance = 0.02;
  /// Fraction of the stamp's offset from the grid that the grid follows per sample.
  static constexpr double kTrack = 0.01;
  /// Candidates scored per step of the spread work.
  static constexpr int kScoresPerStep = 16;

  /// How the cutoff is chosen from the spectrum.
  enum class Rule : std::uint8_t {
    kGcv,  ///< the GCV score above
    /// Where the spectrum meets its noise floor, as zero_phase.hpp's CutoffRule::kSpectrum
    /// on the record's bands: the bins' levels (the variance of white noise that would
    /// give them) averaged in bands of ratio kBandRatio; their upper envelope from above
    /// followed up in frequency; the first band from which it falls by less than
    /// kFlatSlope (log-log) over the next octave, kFloorBelowPeak under its highest level,
    /// starts the floor (the median level of that octave), and the cutoff is where the
    /// envelope, coming down, crosses twice the floor. Coloured noise, flat to a corner,
    /// is not taken for motion (GCV takes it for motion). No floor: the highest cutoff.
    kNoiseFloor,
  };
  static constexpr double kBandRatio = 1.1;
  static constexpr double kFlatSlope = -1.5;
  static constexpr double kFloorBelowPeak = 1e-3;

  SpectralCutoff() = default;
  /// channels: how many of the first channels of each sample choose (e.g. the joint
  /// positions, not the wrenches); lowest, highest: the cutoffs searched [Hz]; blocks of
  /// about block_seconds, the first one left out unless first_block (a caller that
  /// reads only fallsThroughout(), which the filters' start does not make).
  SpectralCutoff(int channels, double lowest, double highest, Rule rule = Rule::kGcv,
                 double block_seconds = kBlockSeconds, bool first_block = false)
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

  /// Intervals whose median fixes the grid (receive-time stamps make single ones wrong).
  static constexpr int kFirstIntervals = 15;

  /// The next sample x[0..channels) at time t [s], and an estimate of its rates
  /// rate[c * stride] [unit/s]. Returns true when a block completed and the cutoff was chosen
  /// anew.
  bool add(double t, const double* x, const double* rate, int stride) {
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

  /// A restart of the filters: the block in progress ends; the spectrum stays.
  void endBlock() {
    filled_ = 0;
    in_sum_ = 0;
    sum_.setZero();
    have_last_ = false;
  }

  /// Steps of a completed block's work still to do (0: none); one is done per grid sample.
  int pendingSteps() const {
    if (step_ < 0) return 0;
    const int scored = step_ <= channels_ ? 0 : scored_;
    const int scoring = rule_ == Rule::kNoiseFloor
                            ? 1
                            : std::max(1, (count_ - scored + kScoresPerStep - 1) / kScoresPerStep);
    return std::max(0, channels_ + 1 - step_) + scoring;
  }

  /// The chosen cutoff [Hz] (0 before the first choice).
  double cutoff() const { return cutoff_; }
  /// Rule::kNoiseFloor: the noise floor of the last choice (the variance of white noise
  /// that gives that level, summed over the channels that choose) [unit^2]; 0 where no
  /// floor was found (the spectrum falls to the highest cutoff: data without noise).
  double floorLevel() const { return floor_level_; }
  /// Whether the last choice is the highest cutoff searched.
  bool atHighest() const { return at_highest_; }
  /// Rule::kNoiseFloor: whether the last spectrum fell more steeply than kFlatSlope over
  /// every octave up to the highest band: no flat part at any level, nothing like noise
  /// (data exact to the rounding).
  bool fallsThroughout() const { return falls_; }
  /// Whether the last choice sits on a bound of the search (the lowest or the highest
  /// cutoff, or no noise floor found): the data do not settle it.
  bool onBound() const { return on_bound_; }
  /// The bandwidth to use [Hz]: the chosen cutoff, before it the lowest searched; 0 when
  /// there is nothing to search (lowest above highest).
  double bandwidth() const {
    if (!(lowest_ <= highest_) || channels_ <= 0) return 0.0;
    return cutoff_ > 0.0 ? cutoff_ : lowest_;
  }
  int blockSamples() const { return block_; }
  /// Blocks in the spectrum so far.
  int blocks() const { return blocks_; }
  int decimation() const { return decimation_; }

 private:
  // The grid's interval h [s] and the block layout, once.
  void start(double h) {
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

  // One grid sample: a step of the last block's work, then the sample; a completed
  // block is handed to the work (what is left of the one before done first: rare, the
  // steps are far fewer than a block's samples).
  bool accumulate(const double* x) {
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

  // The next step of the work on block_samples_: channel step_'s transform (steps 0 ..
  // channels - 1), the spectrum (channels), kScoresPerStep scores (then); true when the
  // choice is made.
  bool step() {
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

  void transformChannel(int c) {
    if (c == 0) part_.setZero();
    for (int j = 0; j < block_; ++j)
      buffer_[static_cast<std::size_t>(j)] =
          window_[j] * (block_samples_(j + 1, c) - block_samples_(j, c));
    fft_.transform(buffer_.data(), block_);
    for (int k = 1; k <= block_ / 2; ++k)
      part_[k] += std::norm(buffer_[static_cast<std::size_t>(k)]) * whitening_[k] / window_norm_;
  }

  void addSpectrum() {
    ++blocks_;
    const double seconds = blocks_ * block_ * h_ * decimation_;
    const double weight =
        seconds <= kMemorySeconds ? 1.0 / blocks_ : block_ * h_ * decimation_ / kMemorySeconds;
    spectrum_ += weight * (part_ - spectrum_);
  }

  // GCV over the grid, kScoresPerStep candidates a step; with the last, the choice (true
  // once made): the narrowest cutoff within kTolerance of the minimum. Where the score is
  // flat (broadband motion, a short record) its minimum wanders, and the narrower cutoff
  // has the less noisy derivatives.
  bool scoreSome() {
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

  // Rule::kNoiseFloor on the spectrum so far (grid interval hd [s]): the bands' levels
  // into band_level_ (their centres [Hz] in band_centre_), then the knee, the floor and
  // the crossing.
  void chooseNoiseFloor(double hd) {
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

  // The crossing of the envelope (non-increasing) with twice the median level of the
  // bands knee .. end (the floor), interpolated on log-log between the last band above it
  // and the next; within lowest .. top [Hz].
  void crossFloor(int knee, int end, double top) {
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
    const double u =
        std::log(band_level_[c] / twice) / std::log(band_level_[c] / band_level_[c + 1]);
    const double f =
        std::exp(std::log(band_centre_[c]) + u * std::log(band_centre_[c + 1] / band_centre_[c]));
    cutoff_ = std::max(lowest_, std::min(top, f));
    at_highest_ = cutoff_ >= 0.99 * top;
    on_bound_ = cutoff_ <= 1.01 * lowest_ || at_highest_;
  }

  // GCV(w), w [cycles per grid sample]; the two-sided means from the one-sided spectrum
  // (k and n - k alike, k = n / 2 once; k = 0 has gain 1).
  double score(double w) const {
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

  static constexpr int kMaxBands = 160;  ///< bands of ratio 1.1 at most (1.1^160: 4e6)
  int channels_ = 0;
  double lowest_ = 0.5, highest_ = 50.0;
  double block_seconds_ = kBlockSeconds;
  bool first_block_ = false;
  Rule rule_ = Rule::kGcv;
  bool on_bound_ = false, at_highest_ = false, falls_ = false;
  double floor_level_ = 0.0;
  double band_level_[kMaxBands] = {}, band_raw_[kMaxBands] = {}, band_centre_[kMaxBands] = {};
  double floor_[kMaxBands] = {};
  bool started_ = false, have_first_ = false;
  int first_count_ = 0;
  double first_time_ = 0.0;
  double intervals_[kFirstIntervals] = {};
  double grid_[kGridSize] = {}, scores_[kGridSize] = {};
  double h_ = 0.0;
  int decimation_ = 1, block_ = 0, filled_ = 0, in_sum_ = 0, blocks_ = 0, seen_ = 0;
  bool have_last_ = false;
  double grid_time_ = 0.0;
  double cutoff_ = 0.0;
  double window_norm_ = 1.0;
  int step_ = -1;               // the next step of a completed block's work (-1: none)
  int count_ = 0, scored_ = 0;  // candidates on the grid, and scored so far
  double lowest_score_ = 0.0;
  Fft fft_;
  std::vector<std::complex<double>> buffer_;
  Eigen::MatrixXd samples_;        // (block + 1) x channels, decimated
  Eigen::MatrixXd block_samples_;  // the completed block the work is on, alike
  Eigen::VectorXd sum_, last_, fill_, gap_;
  Eigen::VectorXd spectrum_, part_, window_, whitening_, tan_k_;
};

}  // namespace jle
