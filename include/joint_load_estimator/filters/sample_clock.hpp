// The sample clock of one stream: from the stamps of a periodic source whose stamps
// were taken at reception (they jitter about the instants the samples were taken), the
// instants themselves, by a robust linear fit of stamp against sample index over a
// sliding window, the index counted through gaps and dropped samples by rounding.
// A source without a period (irregular sampling) and a periodic source whose stamps are
// already exact keep their stamps, bit for bit. ROS-free; no allocation per sample.
#pragma once

#include <cstdint>
#include <vector>

namespace jle {

class SampleClock {
 public:
  /// `regularize` false: add() always returns the stamp. `window` (>= 16): samples of
  /// the fit.
  explicit SampleClock(bool regularize, int window = 128);

  /// The stream's next sample, stamped `stamp` [ns] (newer than the previous one):
  /// the instant [ns] it was taken, estimated from the stamps so far (regular()), or
  /// `stamp` itself. The instants increase strictly.
  std::int64_t add(std::int64_t stamp);
  /// Forgets the stream (a jump of time).
  void reset();

  /// Whether the stream is periodic with jittered stamps: its instants are estimated.
  bool regular() const { return regular_; }
  /// The stream's mean spacing [ns] over the window (the fit's slope); before the first
  /// fit, and always with `regularize` false, the last spacing of the stamps (0 before
  /// the second sample).
  double period() const { return fitted_ ? slope_ : last_spacing_; }
  /// The robust scale (1.4826 MAD) [ns] of the stamps about the fitted lattice.
  double jitter() const { return scale_; }

 private:
  struct Point {
    std::int64_t stamp = 0;
    double index = 0.0;  // sample index, counted through gaps
  };
  const Point& point(int i) const;  // i-th oldest in the window
  Point& at(int i);
  double nextIndex(std::int64_t stamp);
  void fit();
  void robustLine(double& intercept, double& slope);
  double median(int n);

  bool enabled_;
  std::vector<Point> ring_;
  std::vector<double> scratch_;
  int head_ = 0, count_ = 0;
  // The fit: stamp = origin_ + intercept_ + slope_ (index - index_origin_) [ns].
  std::int64_t origin_ = 0;
  double index_origin_ = 0.0, intercept_ = 0.0, slope_ = 0.0, scale_ = 0.0;
  double spacing_ = 0.0;  // [ns] median spacing of consecutive samples in the window
  bool fitted_ = false, regular_ = false;
  std::int64_t last_instant_ = 0;
  std::int64_t last_stamp_ = 0;
  double last_spacing_ = 0.0;  // [ns] between the last two stamps
};

}  // namespace jle
