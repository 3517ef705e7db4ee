// Zero-phase Butterworth smoothing of a whole record (docs/studies/zero_phase.md).
#include <joint_load_estimator/filters/zero_phase.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/QR>

namespace jle {
namespace {

// One second-order section in direct form II transposed (as scipy.signal.sosfilt):
// y = b0 x + z1, z1' = b1 x - a1 y + z2, z2' = b2 x - a2 y.
struct Section {
  double b0, b1, b2, a1, a2;
};

// Butterworth low-pass of `order`, cutoff w as a fraction of the sampling rate
// (0 < w < 0.5), by the bilinear transform with prewarping (as scipy.signal.butter);
// every section has a DC gain of 1.
std::vector<Section> butterworth(double w, int order) {
  const double warped = 2.0 * std::tan(M_PI * w);  // the analog cutoff [rad/sample]
  std::vector<Section> sections;
  for (int k = 0; k < order / 2; ++k) {
    // The pole in the upper left quadrant; its conjugate is the section's other pole.
    const std::complex<double> p =
        warped * std::polar(1.0, M_PI * (2.0 * k + order + 1) / (2.0 * order));
    const std::complex<double> z = (2.0 + p) / (2.0 - p);
    const double a1 = -2.0 * z.real(), a2 = std::norm(z);
    const double g = (1.0 + a1 + a2) / 4.0;  // numerator g (1 + z^-1)^2
    sections.push_back({g, 2.0 * g, g, a1, a2});
  }
  if (order % 2 == 1) {
    const double a1 = -(2.0 - warped) / (2.0 + warped);  // the real pole p = -warped
    const double g = (1.0 + a1) / 2.0;
    sections.push_back({g, g, 0.0, a1, 0.0});
  }
  return sections;
}

// Filters y[0 .. n-1] in place through the sections, each started in the steady state of
// a constant input y[0] (scipy.signal.sosfilt_zi times y[0]; every DC gain is 1).
void runSections(const std::vector<Section>& sections, double* y, int n) {
  const double x0 = y[0];
  for (const Section& c : sections) {
    double z2 = (c.b2 - c.a2) * x0;
    double z1 = (c.b1 - c.a1) * x0 + z2;
    for (int i = 0; i < n; ++i) {
      const double x = y[i];
      const double out = c.b0 * x + z1;
      z1 = c.b1 * x - c.a1 * out + z2;
      z2 = c.b2 * x - c.a2 * out;
      y[i] = out;
    }
  }
}

// The forward-backward filter of one channel x (n samples), padded by `pad` samples at
// each end: the line through the two end samples is taken out, the rest extended by odd
// reflection about its ends, filtered forward and backward, and the line put back (so
// that a constant and a ramp pass exactly). Returns the n + 2 pad samples, the input's
// at pad .. pad + n - 1.
Eigen::VectorXd filtfiltPadded(const std::vector<Section>& sections, const double* x, int n,
                               int pad) {
  const double slope = (x[n - 1] - x[0]) / (n - 1);
  const auto line = [&](int i) { return x[0] + slope * i; };
  Eigen::VectorXd y(n + 2 * pad);
  for (int i = 0; i < n; ++i) y[pad + i] = x[i] - line(i);
  for (int k = 1; k <= pad; ++k) {
    y[pad - k] = -y[pad + k];
    y[pad + n - 1 + k] = -y[pad + n - 1 - k];
  }
  runSections(sections, y.data(), static_cast<int>(y.size()));
  y.reverseInPlace();
  runSections(sections, y.data(), static_cast<int>(y.size()));
  y.reverseInPlace();
  for (int i = 0; i < y.size(); ++i) y[i] += line(i - pad);
  return y;
}

// The uniform time axis that the filter runs on: t0 + k h, k = 0 .. m. `uniform`: the
// input stamps are on it (within 1e-4 h) and are used as they are.
struct Grid {
  double t0 = 0.0, h = 0.0;
  int m = 0;
  bool uniform = true;
  double at(int k) const { return t0 + k * h; }
};

// The median period of t, and the grid spanning t at (about) that period.
Grid gridOf(const std::vector<double>& t) {
  std::vector<double> dt(t.size() - 1);
  for (std::size_t i = 0; i + 1 < t.size(); ++i) dt[i] = t[i + 1] - t[i];
  const std::size_t mid = dt.size() / 2;
  std::nth_element(dt.begin(), dt.begin() + mid, dt.end());
  double median = dt[mid];
  if (dt.size() % 2 == 0) median = 0.5 * (median + *std::max_element(dt.begin(), dt.begin() + mid));
  Grid grid;
  grid.t0 = t.front();
  grid.m = std::max(2, static_cast<int>(std::lround((t.back() - t.front()) / median)));
  grid.h = (t.back() - t.front()) / grid.m;
  grid.uniform = grid.m + 1 == static_cast<int>(t.size());
  for (std::size_t i = 0; grid.uniform && i < t.size(); ++i)
    grid.uniform = std::abs(t[i] - grid.at(static_cast<int>(i))) <= 1e-4 * grid.h;
  return grid;
}

// The interval [k, k + 1] of the grid that holds time s, and the fraction of it.
int intervalOf(const Grid& grid, double s, double& fraction) {
  const int k = std::min(grid.m - 1, std::max(0, static_cast<int>((s - grid.t0) / grid.h)));
  fraction = (s - grid.at(k)) / grid.h;
  return k;
}

// x (at the stamps t) linearly interpolated onto the grid.
Eigen::MatrixXd resample(const Grid& grid, const std::vector<double>& t, const Eigen::MatrixXd& x) {
  Eigen::MatrixXd out(grid.m + 1, x.cols());
  std::size_t i = 0;
  for (int k = 0; k <= grid.m; ++k) {
    const double s = k == grid.m ? t.back() : grid.at(k);
    while (i + 2 < t.size() && t[i + 1] <= s) ++i;
    const double f = (s - t[i]) / (t[i + 1] - t[i]);
    out.row(k) = (1.0 - f) * x.row(i) + f * x.row(i + 1);
  }
  return out;
}

void checkInput(const std::vector<double>& t, const Eigen::MatrixXd& x) {
  if (static_cast<Eigen::Index>(t.size()) != x.rows())
    throw std::invalid_argument("zero_phase: " + std::to_string(t.size()) + " stamps for " +
                                std::to_string(x.rows()) + " samples");
  if (t.size() < 3)
    throw std::invalid_argument("zero_phase: " + std::to_string(t.size()) +
                                " samples; at least 3 are needed");
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i]) || (i > 0 && !(t[i] > t[i - 1])))
      throw std::invalid_argument("zero_phase: stamp " + std::to_string(i) +
                                  " is not finite or does not increase");
  }
  if (!x.allFinite()) throw std::invalid_argument("zero_phase: a sample is not finite");
}

// The samples added at each end: `padding` (0: 3 (order + 1)), at least the 2 that the
// derivatives' stencil needs, at most samples - 1 (the odd reflection's reach).
int paddingOf(int padding, int order, int samples) {
  return std::min(std::max(2, padding > 0 ? padding : 3 * (order + 1)), samples - 1);
}

// Every channel of xg (on the grid, L samples) smoothed: the padded outputs, (L + 2 pad)
// x channels.
Eigen::MatrixXd smoothPadded(const Eigen::MatrixXd& xg, double w, int order, int pad) {
  const std::vector<Section> sections = butterworth(w, order);
  const int n = static_cast<int>(xg.rows());
  Eigen::MatrixXd out(n + 2 * pad, xg.cols());
  for (Eigen::Index c = 0; c < xg.cols(); ++c)
    out.col(c) = filtfiltPadded(sections, xg.col(c).data(), n, pad);
  return out;
}

// The padded smoothed grid channels back at the stamps t: the grid's own samples when t is
// uniform, else linearly interpolated (the filter's value without derivatives).
Eigen::MatrixXd atStamps(const Grid& grid, const std::vector<double>& t,
                         const Eigen::MatrixXd& padded, int pad) {
  if (grid.uniform) return padded.middleRows(pad, grid.m + 1);
  Eigen::MatrixXd out(static_cast<Eigen::Index>(t.size()), padded.cols());
  for (std::size_t i = 0; i < t.size(); ++i) {
    double f = 0.0;
    const int k = intervalOf(grid, t[i], f);
    out.row(static_cast<Eigen::Index>(i)) =
        (1.0 - f) * padded.row(pad + k) + f * padded.row(pad + k + 1);
  }
  return out;
}

// The cutoff as a fraction of the grid's sampling rate, checked against the Nyquist rate.
double relativeCutoff(const Grid& grid, double cutoff) {
  const double w = cutoff * grid.h;
  if (!(w < 0.5))
    throw std::invalid_argument("zero_phase cutoff " + std::to_string(cutoff) +
                                " Hz must be below half the sampling rate (" +
                                std::to_string(0.5 / grid.h) + " Hz)");
  return w;
}

// Rate and acceleration of the padded smoothed channels at the grid's samples, by 5-point
// central differences (error O(h^4)); the padding supplies the neighbours at the ends.
void differentiate(const Eigen::MatrixXd& padded, int pad, double h, Eigen::MatrixXd& rate,
                   Eigen::MatrixXd& accel) {
  const Eigen::Index n = padded.rows() - 2 * pad;
  const auto y = [&](Eigen::Index k, int d) { return padded.row(pad + k + d); };
  rate.resize(n, padded.cols());
  accel.resize(n, padded.cols());
  for (Eigen::Index k = 0; k < n; ++k) {
    rate.row(k) = (y(k, -2) - 8.0 * y(k, -1) + 8.0 * y(k, 1) - y(k, 2)) / (12.0 * h);
    accel.row(k) =
        (-y(k, -2) + 16.0 * y(k, -1) - 30.0 * y(k, 0) + 16.0 * y(k, 1) - y(k, 2)) / (12.0 * h * h);
  }
}

// The channels that a cutoff is chosen for: x at the stamps t, xg on the grid, the
// measured velocities v at t (null: none); and the search's constants.
struct CutoffSearch {
  const Grid& grid;
  const std::vector<double>& t;
  const Eigen::MatrixXd& x;
  const Eigen::MatrixXd& xg;
  const Eigen::MatrixXd* v;
  int order, pad;
  double w_lo;        // the lowest cutoff searched [1/sample]
  double w_hi;        // the highest [1/sample]
  double margin = 0;  // [s] left out of the scores at each end
  // The noise spectrum's cutoff once found (it is asked for by several checks), and
  // whether it found a floor; spectrum_w < 0: not yet.
  mutable double spectrum_w = -1.0;
  mutable bool spectrum_found = false;
  mutable double spectrum_floor = 0.0;  // the noise floor's level (white noise's variance)

  // Whether time s is far enough from the ends to be scored: there the padding's
  // transient (odd reflection bends the curvature) would dominate at low cutoffs.
  bool inside(double s) const { return s - t.front() >= margin && t.back() - s >= margin; }

  // Mean square of x - smooth(x) over every channel at cutoff w [1/sample], at the input
  // stamps (the measurements themselves, not their resampling, whose interpolation
  // colours the noise), away from the ends.
  double meanSquareResidual(double w) const {
    const Eigen::MatrixXd s = atStamps(grid, t, smoothPadded(xg, w, order, pad), pad);
    double sum = 0.0;
    long count = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!inside(t[i])) continue;
      const auto row = static_cast<Eigen::Index>(i);
      sum += (x.row(row) - s.row(row)).squaredNorm();
      ++count;
    }
    return sum / static_cast<double>(count * x.cols());
  }

  // The generalised cross-validation score at cutoff w: mean square residual /
  // (1 - tr(S) / L)^2, tr(S) from the filter's gain |H|^2 at the L DFT frequencies of the
  // record (the circulant approximation of the smoother S).
  double gcvScore(double w) const {
    const Eigen::Index n = xg.rows();
    const double tc = std::tan(M_PI * w);
    double trace = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) {
      const double ratio = std::tan(M_PI * static_cast<double>(k) / n) / tc;
      trace += 1.0 / (1.0 + std::pow(ratio * ratio, order));
    }
    const double dof = 1.0 - trace / static_cast<double>(n);
    return meanSquareResidual(w) / (dof * dof);
  }

  // The grid's rate (or acceleration) of x at cutoff w, channel c, at stamp i
  // (interpolated linearly between grid samples).
  static double atStamp(const Grid& grid, const std::vector<double>& t, const Eigen::MatrixXd& y,
                        std::size_t i, Eigen::Index c) {
    double f = 0.0;
    const int k = grid.uniform ? static_cast<int>(i) : intervalOf(grid, t[i], f);
    return (1.0 - f) * y(k, c) + f * y(std::min(k + 1, grid.m), c);
  }

  // Whether stamp i is scored by the velocity evidence: all but the first and the last
  // 0.5 s of the record (a tenth of a shorter one), the project's convention for loads
  // near a record's end. Beyond them the padding's error is the error the loads will
  // have, and the measured velocities see it; nearer the ends it is large at any cutoff
  // searched, and would drive the choice.
  bool evidenceAt(std::size_t i) const {
    const double end = std::min(0.5, (t.back() - t.front()) / 10.0);
    return i > 0 && i + 1 < t.size() && t[i] - t.front() >= end && t.back() - t[i] >= end;
  }

  // The velocity evidence's score at cutoff w: the mean square of (zero-phase acceleration
  // of x) - (central difference of the measured velocities, (v[i+1] - v[i-1]) /
  // (t[i+1] - t[i-1])) over the scored stamps where both velocities are finite. With the
  // velocities' noise independent of the positions', its expectation is the
  // acceleration's mean square error (what the loads' error follows) plus a constant, the
  // difference's own error; the difference's noise is mostly near the Nyquist rate, where
  // the smoothed acceleration has little, so the score's scatter is small.
  double velocityScore(double w) const {
    Eigen::MatrixXd rate, accel;
    differentiate(smoothPadded(xg, w, order, pad), pad, grid.h, rate, accel);
    double sum = 0.0;
    long count = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!evidenceAt(i)) continue;
      const auto row = static_cast<Eigen::Index>(i);
      for (Eigen::Index c = 0; c < x.cols(); ++c) {
        const double a_v = ((*v)(row + 1, c) - (*v)(row - 1, c)) / (t[i + 1] - t[i - 1]);
        if (!std::isfinite(a_v)) continue;
        const double d = atStamp(grid, t, accel, i, c) - a_v;
        sum += d * d;
        ++count;
      }
    }
    return sum / static_cast<double>(std::max(1L, count));
  }

  // The mean square of (zero-phase rate of x at cutoff w) - (measured velocity), and of
  // the rate itself (`rate_square`), over the scored stamps with a finite velocity.
  double rateDifference(double w, double& rate_square) const {
    Eigen::MatrixXd rate, accel;
    differentiate(smoothPadded(xg, w, order, pad), pad, grid.h, rate, accel);
    double sum = 0.0, sum_rate = 0.0;
    long count = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (!evidenceAt(i)) continue;
      for (Eigen::Index c = 0; c < x.cols(); ++c) {
        const double measured = (*v)(static_cast<Eigen::Index>(i), c);
        if (!std::isfinite(measured)) continue;
        const double r = atStamp(grid, t, rate, i, c);
        sum += (r - measured) * (r - measured);
        sum_rate += r * r;
        ++count;
      }
    }
    const double n = static_cast<double>(std::max(1L, count));
    rate_square = sum_rate / n;
    return sum / n;
  }
};

// Winter's residual analysis: the residual's RMS R(w) is a straight line where it holds
// only noise (fitted over 0.2 .. 0.4 of the sampling rate); its intercept a at w = 0
// estimates the noise, and the cutoff is where R(w) = a (bisection on log w), at most
// w_hi.
double residualCutoff(const CutoffSearch& search) {
  const int fits = 9;
  double sw = 0, sr = 0, sww = 0, swr = 0;
  for (int j = 0; j < fits; ++j) {
    const double w = 0.2 + 0.025 * j;
    const double r = std::sqrt(search.meanSquareResidual(w));
    sw += w, sr += r, sww += w * w, swr += w * r;
  }
  const double slope = (fits * swr - sw * sr) / (fits * sww - sw * sw);
  const double a = (sr - slope * sw) / fits;
  const auto above = [&](double w) { return search.meanSquareResidual(w) > a * a; };
  double lo = std::log(search.w_lo), hi = std::log(0.2);
  if (!above(search.w_lo)) return search.w_lo;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (above(std::exp(mid)) ? lo : hi) = mid;
  }
  return std::min(search.w_hi, std::exp(hi));
}

// The minimum of score(w) over w_lo .. w_hi: a scan at ratio 1.1, then a golden section
// between the best scanned point's neighbours (on log w).
template <typename Score>
double minimiseOnLog(const Score& score_of_w, double w_lo, double w_hi) {
  const auto score = [&](double log_w) { return score_of_w(std::exp(log_w)); };
  const double lo = std::log(w_lo), hi = std::log(w_hi);
  const int steps = std::max(1, static_cast<int>(std::ceil((hi - lo) / std::log(1.1))));
  const double step = (hi - lo) / steps;
  int best = 0;
  double best_score = score(lo);
  for (int j = 1; j <= steps; ++j) {
    const double s = score(lo + j * step);
    if (s < best_score) best_score = s, best = j;
  }
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = lo + std::max(0, best - 1) * step, b = lo + std::min(steps, best + 1) * step;
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = score(c), fd = score(d);
  for (int i = 0; i < 40; ++i) {
    if (fc < fd) {
      b = d, d = c, fd = fc, c = b - g * (b - a), fc = score(c);
    } else {
      a = c, c = d, fc = fd, d = a + g * (b - a), fd = score(d);
    }
  }
  return std::exp(0.5 * (a + b));
}

// The spectrum of the grid channels in bands between the cutoffs w[j] and w[j + 1] (ratio
// 1.1 from w_lo to 0.4): each band's power (the difference of two zero-phase low-passes
// of order kAnalysisOrder per pass, steep enough that the motion's lines do not leak
// into the noise floor), over the power that white noise of unit variance puts in it
// (the same difference of gains, averaged over the L DFT frequencies): the level of
// white noise that would give the band's power.
constexpr int kAnalysisOrder = 8;
// [Hz] the lowest band analysed, or the lowest cutoff searched if lower (a thousandth of
// the rate: above 1 kHz it lies above where arms and bodies move most, and the floor's
// threshold, kFloorBelowPeak under the highest level, would be measured against a band
// that holds little of the motion).
constexpr double kLowestBand = 1.0;

// The value, rate and acceleration at the end sample `at` of the n rows of x (grid
// period h), fitted by a quadratic over the `span` samples ending (or starting) there:
// 3 x channels.
Eigen::MatrixXd endState(const Eigen::MatrixXd& x, Eigen::Index at, Eigen::Index span, double h) {
  const Eigen::Index first = at == 0 ? 0 : at - span + 1;
  Eigen::MatrixXd basis(span, 3);
  for (Eigen::Index k = 0; k < span; ++k) {
    const double u = static_cast<double>(first + k - at) * h;
    basis.row(k) << 1.0, u, u * u;
  }
  Eigen::MatrixXd state = basis.colPivHouseholderQr().solve(x.middleRows(first, span));
  state.row(2) *= 2.0;
  return state;
}

// x less the quintic that matches its value, rate and acceleration at both ends (each
// fitted by endState over kEndFitSeconds): what is left starts and ends at rest with no
// curvature, so that the analysis filters' odd reflection does not bend it and their end
// transients, which look like motion above the motion's band, stay below the noise.
constexpr double kEndFitSeconds = 0.1;

Eigen::MatrixXd restingEnds(const Eigen::MatrixXd& x, double h) {
  const Eigen::Index n = x.rows();
  const Eigen::Index span = std::min<Eigen::Index>(
      n / 4, std::max<Eigen::Index>(5, static_cast<Eigen::Index>(std::lround(kEndFitSeconds / h))));
  if (span < 5) return x;
  const Eigen::MatrixXd a = endState(x, 0, span, h), b = endState(x, n - 1, span, h);
  const double T = static_cast<double>(n - 1) * h;
  Eigen::MatrixXd out(x.rows(), x.cols());
  for (Eigen::Index k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / static_cast<double>(n - 1);
    const double s2 = s * s, s3 = s2 * s, s4 = s3 * s, s5 = s4 * s;
    const double h0 = 1 - 10 * s3 + 15 * s4 - 6 * s5, h5 = 10 * s3 - 15 * s4 + 6 * s5;
    const double h1 = s - 6 * s3 + 8 * s4 - 3 * s5, h4 = -4 * s3 + 7 * s4 - 3 * s5;
    const double h2 = 0.5 * (s2 - 3 * s3 + 3 * s4 - s5), h3 = 0.5 * (s3 - 2 * s4 + s5);
    out.row(k) = x.row(k) - (h0 * a.row(0) + h1 * T * a.row(1) + h2 * T * T * a.row(2) +
                             h3 * T * T * b.row(2) + h4 * T * b.row(1) + h5 * b.row(0));
  }
  return out;
}

std::vector<double> bandLevels(const CutoffSearch& search, std::vector<double>& w) {
  w.clear();
  const double first =
      std::min(search.w_lo, std::max(1.0 / search.grid.m, kLowestBand * search.grid.h));
  for (double c = first; c < 0.4; c *= 1.1) w.push_back(c);
  if (w.size() < 2) return {};  // a record too short for a band below 0.4 of the rate
  const Eigen::Index n = search.xg.rows();
  const int pad = paddingOf(0, kAnalysisOrder, static_cast<int>(n));
  Eigen::VectorXd tan2(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double tk = std::tan(M_PI * static_cast<double>(k) / static_cast<double>(n));
    tan2[k] = tk * tk;
  }
  const auto gains = [&](double wc) {
    const double tc = std::tan(M_PI * wc);
    return Eigen::VectorXd((1.0 + (tan2 / (tc * tc)).array().pow(kAnalysisOrder)).inverse());
  };
  std::vector<double> level;
  const Eigen::MatrixXd xa = restingEnds(search.xg, search.grid.h);
  Eigen::MatrixXd before = smoothPadded(xa, w[0], kAnalysisOrder, pad);
  Eigen::VectorXd gain_before = gains(w[0]);
  for (std::size_t j = 0; j + 1 < w.size(); ++j) {
    const Eigen::MatrixXd after = smoothPadded(xa, w[j + 1], kAnalysisOrder, pad);
    const Eigen::VectorXd gain_after = gains(w[j + 1]);
    double power = 0.0;
    long count = 0;
    for (Eigen::Index k = 0; k < n; ++k) {
      if (!search.inside(search.grid.at(static_cast<int>(k)))) continue;
      power += (after.row(pad + k) - before.row(pad + k)).squaredNorm();
      count += search.xg.cols();
    }
    const double white = (gain_after - gain_before).squaredNorm() / static_cast<double>(n);
    level.push_back(std::max(1e-300, power / static_cast<double>(std::max(1L, count))) /
                    std::max(1e-300, white));
    before = after;
    gain_before = gain_after;
  }
  return level;
}

// Where the positions' spectrum meets its noise floor. The levels' upper envelope from
// above (the highest level at or above each band: a motion's spectrum is lumpy, a
// periodic one made of lines) is followed up in frequency; the first band from which it
// falls by less than kFlatSlope (log-log) over the next octave, kFloorBelowPeak under the
// highest level, starts the floor; the floor is the median level of that octave, and the
// cutoff is where the envelope, coming down, crosses twice the floor (motion's power
// equal to the noise's: a Wiener filter's gain of 1/2). Coloured noise that is flat to a
// corner and falls above it has its floor below the corner, as white noise has.
// `found`: false when there is no floor up to 0.4 of the rate; then w_hi.
constexpr double kFlatSlope = -1.5;
constexpr double kRounding = 1e-10;  // of the positions' largest magnitude
constexpr double kFloorBelowPeak = 1e-3;

double findSpectrumCutoff(const CutoffSearch& search, bool& found) {
  std::vector<double> w;
  const std::vector<double> level = bandLevels(search, w);
  const int bands = static_cast<int>(level.size()), octave = 7;  // 1.1^7 = 1.95
  const auto centre = [&](int j) { return std::sqrt(w[j] * w[j + 1]); };
  std::vector<double> envelope(level);
  for (int j = bands - 2; j >= 0; --j) envelope[j] = std::max(envelope[j], envelope[j + 1]);
  found = false;
  int knee = 0;
  for (; knee + octave < bands; ++knee) {  // none when there are octave + 1 bands or fewer
    const double slope = std::log(envelope[knee + octave] / envelope[knee]) /
                         std::log(centre(knee + octave) / centre(knee));
    if (slope > kFlatSlope && envelope[knee] < kFloorBelowPeak * envelope[0]) {
      found = true;
      break;
    }
  }
  if (!found) return search.w_hi;
  std::vector<double> floor(level.begin() + knee, level.begin() + knee + octave + 1);
  std::nth_element(floor.begin(), floor.begin() + octave / 2, floor.end());
  const double twice_floor = 2.0 * floor[octave / 2];
  search.spectrum_floor = floor[octave / 2];
  // A floor at the numbers' rounding is no noise: exact positions.
  const double scale = kRounding * search.xg.cwiseAbs().maxCoeff();
  if (!(search.spectrum_floor > scale * scale)) {
    found = false;
    return search.w_hi;
  }
  // The envelope again up to the floor's octave only (noise rising above it is not motion
  // coming down to the floor); the last band above twice the floor, and the next.
  const int end = knee + octave;
  envelope[end] = level[end];
  for (int j = end - 1; j >= 0; --j) envelope[j] = std::max(level[j], envelope[j + 1]);
  int below = 0;
  while (below <= end && envelope[below] > twice_floor) ++below;
  if (below == 0) return search.w_lo;
  if (below > end) return search.w_hi;
  const int c = below - 1;
  // The crossing between the centres of bands c and c + 1, interpolated on log-log.
  const double u = std::log(envelope[c] / twice_floor) / std::log(envelope[c] / envelope[c + 1]);
  const double crossing = std::exp(std::log(centre(c)) + u * std::log(centre(c + 1) / centre(c)));
  return std::max(search.w_lo, std::min(search.w_hi, crossing));
}

// The record's ends at cutoff w [1/sample]: the mean square of the acceleration's end
// transient (odd reflection bends the curvature) over the 2 S samples that follow the first
// S after an end (S: the settle length, 0.5 s or a tenth of a shorter record, the
// project's convention for loads near a record's end; scored beyond it), per channel.
// Measured on the data: the record cut kEndCuts times near each end, the cut record's
// acceleration against the whole one's there.
constexpr int kEndCuts = 3;

double endError(const CutoffSearch& search, double w) {
  const Eigen::Index n = search.xg.rows();
  const double h = search.grid.h;
  const auto settle = static_cast<Eigen::Index>(std::ceil(std::min(0.5, n * h / 10.0) / h));
  Eigen::MatrixXd rate, full, part_rate, part;
  differentiate(smoothPadded(search.xg, w, search.order, search.pad), search.pad, h, rate, full);
  double sum = 0.0;
  long count = 0;
  for (int j = 1; j <= kEndCuts; ++j) {
    const Eigen::Index cut = j * settle, span = 2 * settle;
    if (2 * cut + settle + span > n) break;
    const Eigen::Index rows = n - cut;
    const int pad = paddingOf(0, search.order, static_cast<int>(rows));
    differentiate(smoothPadded(search.xg.bottomRows(rows), w, search.order, pad), pad, h, part_rate,
                  part);
    sum += (part.middleRows(settle, span) - full.middleRows(cut + settle, span)).squaredNorm();
    differentiate(smoothPadded(search.xg.topRows(rows), w, search.order, pad), pad, h, part_rate,
                  part);
    sum +=
        (part.middleRows(rows - settle - span, span) - full.middleRows(rows - settle - span, span))
            .squaredNorm();
    count += 2 * span * search.xg.cols();
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

// The noise spectrum's cutoff moved up where the record's end transients cost the loads
// more than the noise a wider filter lets through: from the spectrum's w_s, the w (ratio
// 1.1, at most w_hi) minimising the scored mean square error it adds, the noise floor's
// (level L, white noise's variance per sample) acceleration error above w_s,
//   2 L (2 pi)^4 c (w^5 - w_s^5) / h^4, c = int x^4 / (1 + x^(2 order))^2 dx over 0 .. inf
// (the forward-backward filter's power gain), plus the end transients' (endError) over
// the share 2 (2 S) / scored samples that they reach. Short records (no cut fits) keep w_s.
double endAwareCutoff(const CutoffSearch& search, double w_s) {
  const double n = static_cast<double>(search.xg.rows()), h = search.grid.h;
  const double settle = std::ceil(std::min(0.5, n * h / 10.0) / h);
  if (!(search.spectrum_floor > 0.0) || 2.0 * settle + 3.0 * settle > n) return w_s;
  const double p = 2.0 * search.order;
  const double c = (1.0 - 5.0 / p) * (M_PI / p) / std::sin(5.0 * M_PI / p);
  const double noise = 2.0 * search.spectrum_floor * std::pow(2.0 * M_PI, 4) * c / std::pow(h, 4);
  const double share = 2.0 * 2.0 * settle / (n - 2.0 * settle);
  double best_w = w_s, best = share * endError(search, w_s);
  for (double w = 1.1 * w_s; w <= search.w_hi; w *= 1.1) {
    const double added = noise * (std::pow(w, 5) - std::pow(w_s, 5));
    if (added >= best) break;  // the noise's share only grows
    const double cost = added + share * endError(search, w);
    if (cost < best) best = cost, best_w = w;
  }
  return best_w;
}

// findSpectrumCutoff, then moved for the record's ends, once per search.
double spectrumCutoff(const CutoffSearch& search, bool& found) {
  if (search.spectrum_w < 0.0) {
    search.spectrum_w = findSpectrumCutoff(search, search.spectrum_found);
    if (search.spectrum_found) search.spectrum_w = endAwareCutoff(search, search.spectrum_w);
  }
  found = search.spectrum_found;
  return search.spectrum_w;
}

// One automatic rule's cutoff [1/sample]; `found`: false when kSpectrum found no floor.
double ruleCutoff(const CutoffSearch& search, CutoffRule rule, bool& found) {
  found = true;
  switch (rule) {
    case CutoffRule::kResidual: return residualCutoff(search);
    case CutoffRule::kGcv:
      return minimiseOnLog([&](double w) { return search.gcvScore(w); }, search.w_lo, search.w_hi);
    case CutoffRule::kVelocity:
      return minimiseOnLog([&](double w) { return search.velocityScore(w); }, search.w_lo,
                           search.w_hi);
    default: return spectrumCutoff(search, found);
  }
}

std::string hz(double f) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g Hz", f);
  return text;
}

// A warning when the `other` rule's cutoff and the choice's differ by more than
// kCutoffDisagreement.
void warnAbout(const CutoffSearch& search, CutoffRule other, CutoffChoice& choice) {
  bool found = true;
  const double f = ruleCutoff(search, other, found) / search.grid.h;
  const double own = choice.positions_cutoff;
  const double ratio = std::max(f / own, own / f);
  if (!(ratio > kCutoffDisagreement)) return;
  char text[64];
  std::snprintf(text, sizeof text, "%.3g Hz, %.1fx ", f, ratio);
  choice.warnings.push_back(
      std::string("zero-phase cutoff: ") + toString(other) + " chooses " + text +
      (f > own ? "above " : "below ") + "the " + hz(own) + " of " + toString(choice.rule) +
      (other == CutoffRule::kVelocity
           ? ": the measured velocities contradict it"
           : ": the position noise may be coloured; check the loads or give --cutoff"));
}

// Whether the measured velocities are evidence: at the noise spectrum's cutoff, their
// mean square difference from the positions' rate is below kFollow times the rate's
// own mean square (velocities that are all zero, in another unit or of other joints are
// not).
constexpr double kFollow = 0.5;

bool velocitiesFollow(const CutoffSearch& search) {
  bool found = true;
  double rate_square = 0.0;
  const double difference = search.rateDifference(spectrumCutoff(search, found), rate_square);
  return difference < kFollow * rate_square;
}

// The search over the channels x at the stamps t (xg on the grid; v the measured
// velocities at t or null). The lowest cutoff searched is a thousandth of the rate or one
// period over the record, the highest config.max_cutoff or 0.4 of the rate; the scores
// leave out two periods of the lowest at each end, at most a quarter of the record.
CutoffSearch searchOf(const Grid& grid, const std::vector<double>& t, const Eigen::MatrixXd& x,
                      const Eigen::MatrixXd& xg, const Eigen::MatrixXd* v,
                      const ZeroPhaseConfig& config) {
  const double w_lo = std::max(1e-3, 1.0 / grid.m);
  const double w_hi = std::max(w_lo, std::min(0.4, config.max_cutoff * grid.h));
  const int pad = paddingOf(config.padding, config.order, static_cast<int>(xg.rows()));
  CutoffSearch search{grid, t, x, xg, v, config.order, pad, w_lo, w_hi};
  search.margin = grid.h * static_cast<double>(std::min<Eigen::Index>(
                               static_cast<Eigen::Index>(std::ceil(2.0 / w_lo)), xg.rows() / 4));
  return search;
}

// Channels filtered alike (FilteredAlike) as the cutoff's search sees them: their grid,
// where their own spectrum meets its noise floor (`top` [1/sample of their grid]: where
// their content ends) and whether it found a floor.
struct AlikeGroup {
  std::string what;
  Grid grid;
  double top = 0.0;
  bool found = false;
  double topHz() const { return top / grid.h; }
  // Whether their content reaches more than kCutoffDisagreement above f [Hz].
  bool reachesAbove(double f) const { return found && topHz() > kCutoffDisagreement * f; }
};

AlikeGroup alikeGroup(const FilteredAlike& alike, const ZeroPhaseConfig& config) {
  checkInput(alike.t, alike.x);
  AlikeGroup g;
  g.what = alike.what;
  g.grid = gridOf(alike.t);
  const Eigen::MatrixXd xg = g.grid.uniform ? alike.x : resample(g.grid, alike.t, alike.x);
  g.top = spectrumCutoff(searchOf(g.grid, alike.t, alike.x, xg, nullptr, config), g.found);
  return g;
}

// The positions' acceleration on the grid at cutoff w [1/sample].
Eigen::MatrixXd gridAcceleration(const CutoffSearch& search, double w) {
  Eigen::MatrixXd rate, accel;
  differentiate(smoothPadded(search.xg, w, search.order, search.pad), search.pad, search.grid.h,
                rate, accel);
  return accel;
}

// The mean square, per channel, of the grid rows a 0.5 s or more from the ends (a tenth of
// a shorter record: the project's convention for loads near a record's end).
double scoredMeanSquare(const CutoffSearch& search, const Eigen::MatrixXd& a) {
  const Eigen::Index n = a.rows();
  const double h = search.grid.h;
  const auto settle =
      static_cast<Eigen::Index>(std::ceil(std::min(0.5, static_cast<double>(n) * h / 10.0) / h));
  const Eigen::Index first = n > 2 * settle ? settle : 0, rows = n - 2 * first;
  return a.middleRows(first, rows).squaredNorm() / static_cast<double>(rows * a.cols());
}

// The positions' own cutoff w_p [1/sample] raised for channels filtered alike whose own
// spectrum meets its floor more than kCutoffDisagreement above it (a contact force's heel
// strikes: content that w_p would smooth away from the loads): up to the highest such
// group's top (at most w_hi), as long as the noise that the rise lets into the positions'
// acceleration (its mean square change from w_p's: above w_p their spectrum is noise)
// stays below kAlikeNoise times the acceleration's own mean square at w_p. At 1, the
// acceleration keeps as much motion as noise: the balance that kSpectrum strikes per band
// (motion's power equal to the noise's), struck over the whole acceleration. A scan at
// ratio kAlikeStep, then bisection on log w between the last cutoff within and the first
// beyond.
constexpr double kAlikeNoise = 1.0;
constexpr double kAlikeStep = 1.05;

double alikeCutoff(const CutoffSearch& search, const std::vector<AlikeGroup>& groups, double w_p) {
  const double h = search.grid.h;
  double w_end = w_p;
  for (const AlikeGroup& g : groups)
    if (g.reachesAbove(w_p / h)) w_end = std::max(w_end, std::min(search.w_hi, g.topHz() * h));
  if (!(w_end > kAlikeStep * w_p)) return w_p;
  const Eigen::MatrixXd own = gridAcceleration(search, w_p);
  const double bound = kAlikeNoise * scoredMeanSquare(search, own);
  const auto within = [&](double w) {
    return scoredMeanSquare(search, gridAcceleration(search, w) - own) <= bound;
  };
  double lo = w_p, hi = w_p;
  while (hi < w_end && within(hi)) lo = hi, hi = std::min(w_end, kAlikeStep * hi);
  if (within(hi)) return hi;  // w_end
  for (int i = 0; i < 20; ++i) {
    const double mid = std::sqrt(lo * hi);
    (within(mid) ? lo : hi) = mid;
  }
  return lo;
}

// A warning into choice where the group's own spectrum meets its noise floor more than
// kCutoffDisagreement above the cutoff that filters it alike.
void warnFilteredAlike(const AlikeGroup& g, const ZeroPhaseConfig& config, CutoffChoice& choice) {
  if (!g.reachesAbove(choice.cutoff)) return;
  const double f = g.topHz();
  const bool bound = f >= 0.99 * std::min(config.max_cutoff, 0.4 / g.grid.h);
  choice.warnings.push_back("zero-phase cutoff: " + g.what + ": its own spectrum meets its noise " +
                            "floor at " + (bound ? "or above " : "") + hz(f) + ", " +
                            std::to_string(static_cast<int>(f / choice.cutoff)) + "x the " +
                            hz(choice.cutoff) + " that filters it alike: its fast " +
                            "content (an impact, a heel strike) is smoothed away from the " +
                            "loads; check them, or give --cutoff");
}

// The positions' own choice raised for the groups filtered alike (alikeCutoff), and what
// a user must hear about them.
void raiseForAlike(const CutoffSearch& search, const std::vector<AlikeGroup>& groups,
                   CutoffChoice& choice) {
  const double h = search.grid.h;
  choice.positions_cutoff = choice.cutoff;
  if (groups.empty()) return;
  const double w_p = choice.cutoff * h, w = alikeCutoff(search, groups, w_p);
  if (w > w_p) {
    choice.cutoff = w / h;
    std::string names;
    for (const AlikeGroup& g : groups)
      if (g.reachesAbove(choice.positions_cutoff)) names += (names.empty() ? "" : ", ") + g.what;
    choice.warnings.push_back("zero-phase cutoff: " + hz(choice.cutoff) + ", raised from the " +
                              hz(choice.positions_cutoff) + " of " + toString(choice.rule) +
                              " for the content of " + names + " filtered alike: the " +
                              "positions' rates carry more noise than at " +
                              hz(choice.positions_cutoff));
  }
}

// The automatic choice: the rule's cutoff, then the checks a user must hear about.
CutoffChoice chooseAutomatic(const CutoffSearch& search, const ZeroPhaseConfig& config,
                             const std::vector<AlikeGroup>& groups) {
  CutoffChoice choice;
  const double h = search.grid.h;
  choice.lowest = search.w_lo / h;
  choice.highest = search.w_hi / h;
  choice.rule = config.rule;
  if (choice.rule == CutoffRule::kVelocity && !search.v)
    throw std::invalid_argument(
        "zero_phase: the velocity rule needs measured velocities (none given, or none finite)");
  const bool follow = search.v && velocitiesFollow(search);
  if (search.v && !follow)
    choice.warnings.push_back(
        "zero-phase cutoff: the measured velocities do not follow the positions' rate (all "
        "zero, another unit or other joints?): " +
        std::string(choice.rule == CutoffRule::kVelocity ? "used all the same" : "not used"));
  if (choice.rule == CutoffRule::kAuto)
    choice.rule = follow ? CutoffRule::kVelocity : CutoffRule::kSpectrum;
  bool found = true;
  choice.cutoff = ruleCutoff(search, choice.rule, found) / h;
  if (!found)
    choice.warnings.push_back("zero-phase cutoff: the positions' spectrum falls steeply up to " +
                              hz(0.4 / h) + " (no noise floor found)");
  raiseForAlike(search, groups, choice);
  if (choice.cutoff >= 0.99 * choice.highest || choice.cutoff <= 1.01 * choice.lowest)
    choice.warnings.push_back(std::string("zero-phase cutoff: ") + hz(choice.cutoff) + " (" +
                              toString(choice.rule) + ") is on the search's " +
                              (choice.cutoff <= 1.01 * choice.lowest ? "lowest" : "highest") +
                              " bound (" + hz(choice.lowest) + " .. " + hz(choice.highest) +
                              "): the data do not settle it; check the loads or give --cutoff");
  if (choice.rule != CutoffRule::kSpectrum) warnAbout(search, CutoffRule::kSpectrum, choice);
  if (choice.rule == CutoffRule::kSpectrum) warnAbout(search, CutoffRule::kGcv, choice);
  if (follow && choice.rule != CutoffRule::kVelocity)
    warnAbout(search, CutoffRule::kVelocity, choice);
  for (const AlikeGroup& g : groups) warnFilteredAlike(g, config, choice);
  return choice;
}

// The cutoff of config.rule for the channels x at the stamps t (searchOf's arguments).
CutoffChoice cutoffOf(const Grid& grid, const std::vector<double>& t, const Eigen::MatrixXd& x,
                      const Eigen::MatrixXd& xg, const Eigen::MatrixXd* v,
                      const ZeroPhaseConfig& config, const std::vector<FilteredAlike>& alike) {
  if (config.rule == CutoffRule::kFixed) {
    CutoffChoice choice;
    choice.cutoff = choice.lowest = choice.highest = choice.positions_cutoff = config.cutoff;
    return choice;
  }
  std::vector<AlikeGroup> groups;
  for (const FilteredAlike& a : alike)
    if (a.x.cols() > 0) groups.push_back(alikeGroup(a, config));
  return chooseAutomatic(searchOf(grid, t, x, xg, v, config), config, groups);
}

// The measured velocities if they are usable evidence (the shape of x, at least half of
// them finite), else null.
const Eigen::MatrixXd* evidenceOf(const Eigen::MatrixXd& x, const Eigen::MatrixXd& velocities) {
  if (velocities.size() == 0) return nullptr;
  if (velocities.rows() != x.rows() || velocities.cols() != x.cols())
    throw std::invalid_argument("zero_phase: velocities are " + std::to_string(velocities.rows()) +
                                " x " + std::to_string(velocities.cols()) + ", positions " +
                                std::to_string(x.rows()) + " x " + std::to_string(x.cols()));
  const long finite = static_cast<long>(velocities.array().isFinite().count());
  return 2 * finite >= static_cast<long>(velocities.size()) ? &velocities : nullptr;
}

// The grid's smoothed value, rate and acceleration evaluated at the stamps t: value by the
// cubic Hermite interpolant of (value, rate), rate by that of (rate, accel), acceleration
// linearly.
void evaluateAt(const Grid& grid, const std::vector<double>& t, ZeroPhaseResult& r) {
  const Eigen::MatrixXd v = r.value, d = r.rate, a = r.accel;
  const double h = grid.h;
  const auto rows = static_cast<Eigen::Index>(t.size());
  r.value.resize(rows, v.cols());
  r.rate.resize(rows, v.cols());
  r.accel.resize(rows, v.cols());
  for (std::size_t i = 0; i < t.size(); ++i) {
    double s = 0.0;
    const int k = intervalOf(grid, t[i], s);
    const double h00 = (2 * s - 3) * s * s + 1, h10 = ((s - 2) * s + 1) * s;
    const double h01 = (3 - 2 * s) * s * s, h11 = (s - 1) * s * s;
    const auto row = static_cast<Eigen::Index>(i);
    r.value.row(row) =
        h00 * v.row(k) + h10 * h * d.row(k) + h01 * v.row(k + 1) + h11 * h * d.row(k + 1);
    r.rate.row(row) =
        h00 * d.row(k) + h10 * h * a.row(k) + h01 * d.row(k + 1) + h11 * h * a.row(k + 1);
    r.accel.row(row) = (1.0 - s) * a.row(k) + s * a.row(k + 1);
  }
}

}  // namespace

const char* toString(CutoffRule rule) {
  switch (rule) {
    case CutoffRule::kFixed: return "given";
    case CutoffRule::kResidual: return "residual analysis";
    case CutoffRule::kGcv: return "generalised cross-validation";
    case CutoffRule::kSpectrum: return "noise spectrum";
    case CutoffRule::kVelocity: return "velocity evidence";
    case CutoffRule::kAuto: return "auto";
  }
  return "";
}

bool parseCutoffRule(const std::string& text, CutoffRule& rule) {
  const std::pair<const char*, CutoffRule> names[] = {{"auto", CutoffRule::kAuto},
                                                      {"spectrum", CutoffRule::kSpectrum},
                                                      {"velocity", CutoffRule::kVelocity},
                                                      {"gcv", CutoffRule::kGcv},
                                                      {"residual", CutoffRule::kResidual}};
  for (const auto& [name, value] : names)
    if (text == name) {
      rule = value;
      return true;
    }
  return false;
}

void validate(const ZeroPhaseConfig& config) {
  if (config.rule == CutoffRule::kFixed && !(config.cutoff > 0.0 && std::isfinite(config.cutoff)))
    throw std::invalid_argument("zero_phase cutoff must be finite and > 0 [Hz] (got " +
                                std::to_string(config.cutoff) + ")");
  if (!(config.max_cutoff > 0.0 && std::isfinite(config.max_cutoff)))
    throw std::invalid_argument("zero_phase max_cutoff must be finite and > 0 [Hz] (got " +
                                std::to_string(config.max_cutoff) + ")");
  if (config.order < 1 || config.order > 8)
    throw std::invalid_argument("zero_phase order must be 1..8 (got " +
                                std::to_string(config.order) + ")");
  if (config.padding < 0)
    throw std::invalid_argument("zero_phase padding must be >= 0 (got " +
                                std::to_string(config.padding) + ")");
}

CutoffChoice selectCutoff(const std::vector<double>& t, const Eigen::MatrixXd& x,
                          const ZeroPhaseConfig& config, const Eigen::MatrixXd& velocities,
                          const std::vector<FilteredAlike>& alike) {
  validate(config);
  checkInput(t, x);
  const Grid grid = gridOf(t);
  return cutoffOf(grid, t, x, grid.uniform ? x : resample(grid, t, x), evidenceOf(x, velocities),
                  config, alike);
}

double chooseCutoff(const std::vector<double>& t, const Eigen::MatrixXd& x,
                    const ZeroPhaseConfig& config, const Eigen::MatrixXd& velocities) {
  return selectCutoff(t, x, config, velocities).cutoff;
}

ZeroPhaseResult smoothZeroPhase(const std::vector<double>& t, const Eigen::MatrixXd& x,
                                const ZeroPhaseConfig& config, const Eigen::MatrixXd& velocities,
                                const std::vector<FilteredAlike>& alike) {
  validate(config);
  checkInput(t, x);
  const Grid grid = gridOf(t);
  const Eigen::MatrixXd xg = grid.uniform ? x : resample(grid, t, x);
  ZeroPhaseResult r;
  r.choice = cutoffOf(grid, t, x, xg, evidenceOf(x, velocities), config, alike);
  r.cutoff = r.choice.cutoff;
  const int pad = paddingOf(config.padding, config.order, static_cast<int>(xg.rows()));
  const Eigen::MatrixXd padded =
      smoothPadded(xg, relativeCutoff(grid, r.cutoff), config.order, pad);
  r.value = padded.middleRows(pad, xg.rows());
  differentiate(padded, pad, grid.h, r.rate, r.accel);
  if (!grid.uniform) evaluateAt(grid, t, r);
  return r;
}

double checkFilteredAlike(const std::vector<double>& t, const Eigen::MatrixXd& x,
                          const ZeroPhaseConfig& config, const std::string& what,
                          CutoffChoice& choice) {
  if (choice.rule == CutoffRule::kFixed || x.cols() == 0 || t.size() < 3) return 0.0;
  validate(config);
  const AlikeGroup g = alikeGroup(FilteredAlike{t, x, what}, config);
  warnFilteredAlike(g, config, choice);
  return g.found ? g.topHz() : 0.0;
}

Eigen::MatrixXd lowPassZeroPhase(const std::vector<double>& t, const Eigen::MatrixXd& x,
                                 double cutoff, int order, int padding) {
  ZeroPhaseConfig config;
  config.rule = CutoffRule::kFixed;
  config.cutoff = cutoff;
  config.order = order;
  config.padding = padding;
  validate(config);
  checkInput(t, x);
  const Grid grid = gridOf(t);
  const Eigen::MatrixXd xg = grid.uniform ? x : resample(grid, t, x);
  const int pad = paddingOf(padding, order, static_cast<int>(xg.rows()));
  return atStamps(grid, t, smoothPadded(xg, relativeCutoff(grid, cutoff), order, pad), pad);
}

}  // namespace jle
