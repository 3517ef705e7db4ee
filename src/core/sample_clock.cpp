#include <joint_load_estimator/sample_clock.hpp>

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
  intercept_ = slope_ = scale_ = 0.0;
  last_instant_ = 0;
}

const SampleClock::Point& SampleClock::point(int i) const {
  const int n = static_cast<int>(ring_.size());
  return ring_[static_cast<std::size_t>((head_ - count_ + i + n) % n)];
}

double SampleClock::nextIndex(std::int64_t stamp) const {
  const Point& last = point(count_ - 1);
  if (fitted_) {
    // The nearest lattice node of the fit; at least one after the last (a late sample
    // rounds to its successor's node, which the next on-time sample takes back).
    const double n = (static_cast<double>(stamp - origin_) - intercept_) / slope_;
    return std::max(index_origin_ + std::round(n), last.index + 1.0);
  }
  // Before the first fit: the spacing is the smallest seen so far (drops only lengthen it).
  double spacing = static_cast<double>(stamp - last.stamp);
  for (int i = 1; i < count_; ++i) {
    const Point &a = point(i - 1), &b = point(i);
    spacing = std::min(spacing, static_cast<double>(b.stamp - a.stamp) / (b.index - a.index));
  }
  return last.index + std::max(1.0, std::round(static_cast<double>(stamp - last.stamp) / spacing));
}

std::int64_t SampleClock::add(std::int64_t stamp) {
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
