#include <joint_load_estimator/filters/sample_clock.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jle {
namespace {

constexpr int kMinFit = 16;  // samples before the first fit
// The stamps' robust scale about the lattice, as a fraction of the period: a stream is
// periodic with jittered stamps between these (receive-time jitter of +-10% of the period
// is a scale of 0.07). Below the lower bound the stamps are exact already (kept, bit for
// bit); above the upper one there is no period. The wider bounds keep a stream in its
// state (hysteresis), so that a borderline stream does not switch at every sample.
constexpr double kEnterLow = 1e-3, kEnterHigh = 0.15;
constexpr double kLeaveLow = 5e-4, kLeaveHigh = 0.2;
constexpr double kMadToSigma = 1.4826;  // scale of a gaussian from its median absolute deviation
constexpr double kInlier = 3.0;         // [scales] residuals beyond are outliers of the fit

}  // namespace

SampleClock::SampleClock(bool regularize, int window)
    : enabled_(regularize),
      ring_(static_cast<std::size_t>(window)),
      scratch_(static_cast<std::size_t>(window)) {
  if (window < kMinFit)
    throw std::invalid_argument("SampleClock: window must be >= " + std::to_string(kMinFit));
}

void SampleClock::reset() {
  head_ = count_ = 0;
  fitted_ = regular_ = false;
  intercept_ = slope_ = scale_ = spacing_ = 0.0;
  last_instant_ = last_stamp_ = 0;
  last_spacing_ = 0.0;
}

const SampleClock::Point& SampleClock::point(int i) const {
  const int n = static_cast<int>(ring_.size());
  return ring_[static_cast<std::size_t>((head_ - count_ + i + n) % n)];
}

SampleClock::Point& SampleClock::at(int i) {
  const int n = static_cast<int>(ring_.size());
  return ring_[static_cast<std::size_t>((head_ - count_ + i + n) % n)];
}

double SampleClock::nextIndex(std::int64_t stamp) {
  // The index steps by the spacing over the period, rounded: gaps and dropped samples are
  // counted. The period is the fit's on a periodic stream, else the window's median
  // spacing (never the fit's, whose lattice would follow the indices it gave), or before
  // the first fit the smallest spacing seen (drops only lengthen it).
  double period = regular_ ? slope_ : spacing_;
  if (period <= 0.0) {
    period = static_cast<double>(stamp - point(count_ - 1).stamp);
    for (int i = 1; i < count_; ++i)
      period = std::min(period, static_cast<double>(point(i).stamp - point(i - 1).stamp));
  }
  const double steps = static_cast<double>(stamp - point(count_ - 1).stamp) / period;
  // Received less than half a period after the last: the last ones were late (a burst),
  // not a period apart after dropped samples: the newest step of more than one index was
  // one too many.
  for (int i = count_ - 1; steps < 0.5 && i > 0; --i) {
    if (!(at(i).index - at(i - 1).index > 1.0)) continue;
    for (int j = i; j < count_; ++j) at(j).index -= 1.0;
    break;
  }
  return point(count_ - 1).index + std::max(1.0, std::round(steps));
}

std::int64_t SampleClock::add(std::int64_t stamp) {
  if (count_ > 0 || last_stamp_ != 0) last_spacing_ = static_cast<double>(stamp - last_stamp_);
  last_stamp_ = stamp;
  if (!enabled_) return stamp;
  const double index = count_ == 0 ? 0.0 : nextIndex(stamp);
  Point& p = ring_[static_cast<std::size_t>(head_)];
  p.stamp = stamp;
  p.index = index;
  head_ = (head_ + 1) % static_cast<int>(ring_.size());
  if (count_ < static_cast<int>(ring_.size())) ++count_;
  fit();
  std::int64_t instant = stamp;
  if (regular_) instant = origin_ + std::llround(intercept_ + slope_ * (index - index_origin_));
  // A burst's samples follow a late one whose instant was taken for later: 1% of a period
  // apart (measured on the Panda at 1 kHz: 1/8 of a period was worse than the stamps).
  const std::int64_t step = std::max<std::int64_t>(1, std::llround(0.01 * period()));
  if (count_ > 1 && instant < last_instant_ + step && regular_) instant = last_instant_ + step;
  if (count_ > 1 && instant <= last_instant_) instant = last_instant_ + 1;
  last_instant_ = instant;
  return instant;
}

double SampleClock::median(int n) {
  const auto begin = scratch_.begin(), middle = begin + n / 2;
  std::nth_element(begin, middle, begin + n);
  return *middle;
}

void SampleClock::robustLine(double& intercept, double& slope) {
  // Slopes over half the window (long baselines), then the median intercept: a line
  // that half the points may miss.
  const int h = count_ / 2;
  for (int i = 0; i + h < count_; ++i) {
    const Point &a = point(i), &b = point(i + h);
    scratch_[static_cast<std::size_t>(i)] =
        static_cast<double>(b.stamp - a.stamp) / (b.index - a.index);
  }
  slope = median(count_ - h);
  for (int i = 0; i < count_; ++i) {
    const Point& a = point(i);
    scratch_[static_cast<std::size_t>(i)] =
        static_cast<double>(a.stamp - origin_) - slope * (a.index - index_origin_);
  }
  intercept = median(count_);
}

void SampleClock::fit() {
  if (count_ < kMinFit) return;
  for (int i = 1; i < count_; ++i)
    scratch_[static_cast<std::size_t>(i - 1)] =
        static_cast<double>(point(i).stamp - point(i - 1).stamp);
  spacing_ = median(count_ - 1);
  origin_ = point(0).stamp;
  index_origin_ = point(0).index;
  double a = 0.0, b = 0.0;
  robustLine(a, b);
  for (int i = 0; i < count_; ++i) {
    const Point& p = point(i);
    scratch_[static_cast<std::size_t>(i)] =
        std::abs(static_cast<double>(p.stamp - origin_) - a - b * (p.index - index_origin_));
  }
  scale_ = kMadToSigma * median(count_);
  // Least squares over the inliers: the most precise line through the jittered stamps.
  double n = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (int i = 0; i < count_; ++i) {
    const Point& p = point(i);
    const double x = p.index - index_origin_, y = static_cast<double>(p.stamp - origin_);
    if (std::abs(y - a - b * x) > kInlier * scale_ + 1.0) continue;
    n += 1.0;
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double det = n * sxx - sx * sx;
  if (n >= 2.0 && det > 0.0) {
    b = (n * sxy - sx * sy) / det;
    a = (sy - b * sx) / n;
  }
  intercept_ = a;
  slope_ = b;
  fitted_ = b > 0.0;
  const double ratio = fitted_ ? scale_ / b : 0.0;
  regular_ = fitted_ && (regular_ ? ratio > kLeaveLow && ratio < kLeaveHigh
                                  : ratio > kEnterLow && ratio < kEnterHigh);
}

}  // namespace jle
