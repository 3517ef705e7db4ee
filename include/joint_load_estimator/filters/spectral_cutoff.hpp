// The bandwidth of the adaptive smoother (DifferentiatorType::kAdaptive with a lag): the
// cutoff that generalised cross-validation of the zero-phase 4th-order Butterworth
// (zero_phase.hpp, CutoffRule::kGcv) would choose on the record so far, computed from a
// running spectrum of the samples instead of filtering the record at every candidate.
// ROS-free, allocation-free after construction.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <vector>

namespace jle {

/// In place radix-2 discrete Fourier transform of n = 2^k <= capacity points (forward,
/// no scaling: X_k = sum_j x_j exp(-2 pi i j k / n)). Everything a transform reads is made
/// by the constructor, for every size up to the capacity: the bit-reversal swaps of each
/// size, and the twiddles of each stage, contiguous (stage len's exp(-2 pi i k / len),
/// k < len / 2, the same numbers as the capacity's every (capacity / len)-th).
class Fft {
 public:
  Fft() = default;
  explicit Fft(int capacity);
  int capacity() const { return capacity_; }

  void transform(std::complex<double>* x, int n) const;

 private:
  // x in bit-reversed order (the swaps of size n = 2^log2n).
  void permute(std::complex<double>* x, int log2n) const;
  // The stages len = 2 and 4 together (twiddles 1 and -i: no multiply), n >= 4.
  static void firstStages(double* x, int n);
  // The stages len and 2 len together (n >= 2 len), the butterflies of radix 2 in the
  // order of a radix-4 pass: each element loaded and stored once for both.
  void stagePair(double* x, int n, int len) const;
  // The stage len alone (the last of an odd count).
  void stage(double* x, int n, int len) const;

  int capacity_ = 0;
  std::vector<std::complex<double>> twiddle_;  // stage len's from index len / 2 - 1
  std::vector<int> swaps_;       // pairs i < j of each size, the sizes one after the other
  std::vector<int> swap_begin_;  // size 2^m's pairs: swaps_[swap_begin_[m] .. [m + 1])
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
/// The work of a completed block (the transforms, the spectrum, the scores) is spread over
/// the grid samples that follow it, one step per sample (a step per channel: two channels'
/// transform in one, z = a + i b, then its unpacking; the spectrum; kScoresPerStep
/// scores), so that no sample's call carries the whole of it:
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
                 double block_seconds = kBlockSeconds, bool first_block = false);

  /// Intervals whose median fixes the grid (receive-time stamps make single ones wrong).
  static constexpr int kFirstIntervals = 15;

  /// The next sample x[0..channels) at time t [s], and an estimate of its rates
  /// rate[c * stride] [unit/s]. Returns true when a block completed and the cutoff was chosen
  /// anew.
  bool add(double t, const double* x, const double* rate, int stride);

  /// A restart of the filters: the block in progress ends; the spectrum stays.
  void endBlock();

  /// Steps of a completed block's work still to do (0: none); one is done per grid sample.
  int pendingSteps() const;

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
  double bandwidth() const;
  int blockSamples() const { return block_; }
  /// Blocks in the spectrum so far.
  int blocks() const { return blocks_; }
  int decimation() const { return decimation_; }
  /// The running spectrum of the positions [unit^2]: bin k = 0 .. blockSamples() / 2 holds
  /// the variance of white noise that would give its level, summed over the channels that
  /// choose and averaged over the blocks (bin 0: 0); the bins above are 0.
  const Eigen::VectorXd& spectrum() const { return spectrum_; }

 private:
  // The grid's interval h [s] and the block layout, once.
  void start(double h);

  // One grid sample, channel c's value sample(c): a step of the last block's work, then
  // the sample into the row being averaged (completeRow once it holds decimation_).
  template <class Sample>
  bool accumulate(Sample sample);

  // The row's average; a completed block is handed to the work (what is left of the one
  // before done first: rare, the steps are far fewer than a block's samples). True when
  // that finished a choice.
  bool completeRow();

  // The next step of the work on block_samples_: the channels' transforms (steps 0 ..
  // channels - 1), the spectrum (channels), kScoresPerStep scores (then); true when the
  // choice is made.
  bool step();

  // Step s < channels of the transforms: even s, channels s and s + 1 in one complex
  // transform (z = a + i b; channel s alone, the last of an odd count, its power into
  // part_ at once); odd s, that pair's powers into part_ (unpackPair).
  void transformStep(int s);

  // The pair's power |A_k|^2 + |B_k|^2 (|A_k|^2 = |Z_k + conj(Z_{n-k})|^2 / 4, |B_k|^2 =
  // |Z_k - conj(Z_{n-k})|^2 / 4) from its transform Z in buffer_, whitened, into part_.
  void unpackPair();

  void addSpectrum();

  // GCV over the grid, kScoresPerStep candidates a step; with the last, the choice (true
  // once made): the narrowest cutoff within kTolerance of the minimum. Where the score is
  // flat (broadband motion, a short record) its minimum wanders, and the narrower cutoff
  // has the less noisy derivatives.
  bool scoreSome();

  // Rule::kNoiseFloor on the spectrum so far (grid interval hd [s]): the bands' levels
  // into band_level_ (their centres [Hz] in band_centre_), then the knee, the floor and
  // the crossing.
  void chooseNoiseFloor(double hd);

  // The crossing of the envelope (non-increasing) with twice the median level of the
  // bands knee .. end (the floor), interpolated on log-log between the last band above it
  // and the next; within lowest .. top [Hz].
  void crossFloor(int knee, int end, double top);

  // GCV(w), w [cycles per grid sample]; the two-sided means from the one-sided spectrum
  // (k and n - k alike, k = n / 2 once; k = 0 has gain 1).
  double score(double w) const;

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
  // (block + 1) x channels, decimated, row-major (sample j's channels from j * channels; a
  // row in the making holds the sum of its in_sum_ samples).
  std::vector<double> samples_;
  std::vector<double> block_samples_;  // the completed block the work is on, alike
  Eigen::VectorXd last_, fill_;        // the last sample moved to the grid; this one, where a gap
  Eigen::VectorXd spectrum_, part_, window_, whitening_, tan_k_;
};

}  // namespace jle
