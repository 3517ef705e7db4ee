// What a differentiator is (DifferentiatorConfig: the type, its parameters and their
// checks), apart from the filters themselves (differentiation.hpp), so that the settings
// (config.hpp) do not carry the filter bank into every file that reads them.
#pragma once

#include <joint_load_estimator/settings/fields.hpp>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <tuple>

namespace jle {
enum class DifferentiatorType : std::uint8_t {
  kFiniteDifference,  ///< exact through order+1 points (3-point, 2nd order by default)
  kSavitzkyGolay,     ///< least-squares polynomial of `order` over `window` samples
  kKalman,            ///< white-noise acceleration or jerk model
  /// Kalman filters of `kalman_model` on a grid of bandwidths, the one whose innovations
  /// are the likeliest over the recent samples selected, the noise estimated online
  /// (bandwidth_selection.hpp).
  kAdaptive,
};

enum class KalmanModel : std::uint8_t {
  kConstantAcceleration,  ///< state (x, x', x''), white noise on x'''
  kConstantJerk,          ///< state (x, x', x'', x'''), white noise on x''''
};

/// The node's default (config/default.yaml) is defaultDifferentiator() (config.hpp): the
/// constant-jerk Kalman filter, its default process noise 1e4 (processNoise()), measurement
/// noise 1e-4 rad, auto_bandwidth. The adaptive
/// filter is an option: better on the accuracy study's scenes of real logs, worse on clean ones,
/// and its noise gain understates the q'' noise (docs/how_it_works.md "Differentiators").
struct DifferentiatorConfig {
  DifferentiatorType type = DifferentiatorType::kKalman;
  /// Savitzky-Golay: samples in the fit and degree of the polynomial (2..5). The
  /// estimate describes the sample `delay` steps before the newest: 0 is causal,
  /// (window - 1) / 2 is centred. Finite differences use window = order + 1.
  int window = 9;
  int order = 2;
  int delay = 0;
  /// Kalman: spectral density of the white noise driving the highest derivative
  /// [unit^2 / s^(2n-1)] (0: the model's default, processNoise()), and standard
  /// deviation of the position measurement [unit].
  KalmanModel kalman_model = KalmanModel::kConstantJerk;
  double process_noise = 0.0;
  double measurement_noise = 1e-4;
  /// Kalman: delay [s] of the smoothed estimate behind the newest sample's stamp (0: the
  /// causal filter). With lag > 0 the filter runs forward as with 0 and remembers its
  /// states; the estimate of a sample is made once the newest stamp is `lag` after its
  /// own, within h (the median of the last 5 intervals): the sample nearest to newest -
  /// lag, kept from sample to sample while within h of it, so that at a steady rate each
  /// sample makes one estimate (at jittered stamps: within h plus the intervals' spread;
  /// where the rate drops or after a gap, the samples made overdue are due at once, up to
  /// the nearest: DifferentiatorBank::next()). A Rauch-Tung-Striebel backward pass from the newest
  /// sample smooths the next B estimates with the data that followed them, B half the
  /// samples pending (about two backward steps per sample). At least n samples (3 or 4,
  /// the model's state) follow an estimated sample: a lag shorter than n intervals is n.
  /// Adaptive: the same smoother, its process noise the selected filter's at each sample.
  double lag = 0.0;
  /// Kalman with a lag: the smoother's bandwidth set from the data (true): where the
  /// joint positions' spectrum so far meets its noise floor (SpectralCutoff::Rule::
  /// kNoiseFloor, as the offline zero-phase rule: coloured noise is not taken for motion;
  /// 2 s blocks, from the second one on), at least kLagFloor / lag; where the spectrum
  /// shows no floor (data without noise), the highest cutoff (max_bandwidth, at most 0.45
  /// of the rate, averaged to 500 Hz); as the process noise r^2 h (2 pi f)^(2n) (r
  /// measurement_noise, h the recent interval: the smoother's gain is 1/2 at f, as the
  /// zero-phase Butterworth of order n's at its cutoff), process_noise until the first
  /// choice (a smoother: raised to kLagFloor / lag where its bandwidth is below). Without a lag
  /// (the causal filter) alike, but the bandwidth only ever raised above process_noise's, never
  /// lowered (its lag would grow with it), no lag floor, and for positions only where the spectrum
  /// shows no floor (DifferentiatorBank::raiseOnly: a rate's filter takes the crossing too). A
  /// smoother of rates (raiseOnly) runs at a higher bandwidth while its innovations show motion
  /// that it misses (DifferentiatorBank::kMissedMotionBoost). false: process_noise throughout.
  bool auto_bandwidth = false;
  /// Adaptive: the bandwidths [Hz] its filters span (the crossover of signal and noise
  /// spectra; log-spaced by kBandwidthRatio), and the standard deviation of the position
  /// noise [unit] if known (0: estimated online from the innovations), and the time
  /// constant [s] of the likelihood that selects the bandwidth.
  double min_bandwidth = 0.5;
  double max_bandwidth = 50.0;
  double noise = 0.0;
  double memory = 1.0;
  /// A gap between samples longer than this [s] restarts the filter (its memory no
  /// longer describes the signal).
  double max_gap = 0.5;

  /// Every field, in the order declared: what a comparison compares. A field added above
  /// and not here does not compile (the static_assert below counts them).
  auto fields() const {
    return std::tie(type, window, order, delay, kalman_model, process_noise, measurement_noise, lag,
                    auto_bandwidth, min_bandwidth, max_bandwidth, noise, memory, max_gap);
  }
};
static_assert(namesEveryField<DifferentiatorConfig>(),
              "DifferentiatorConfig::fields() must name every field");

/// The process noise the Kalman filter of `c` runs with: c.process_noise, or where it is
/// 0 the model's default: 1e4 for constant jerk [unit^2/s^7], 10 for constant
/// acceleration [unit^2/s^5]. Both put the bandwidth (q / r^2)^(1 / (2n)) at 31.6 rad/s
/// with the default r = 1e-4; measured (accuracy study, 21 scenes, r = 1e-4): constant
/// acceleration with q = 10 is within 1.30x of its best q per scene on geometric mean
/// (2.12x at worst), where 1e4 was 5.3x (36.6x).
inline double processNoise(const DifferentiatorConfig& c) {
  constexpr double kConstantJerk = 1e4, kConstantAcceleration = 10.0;
  if (c.process_noise > 0.0) return c.process_noise;
  return c.kalman_model == KalmanModel::kConstantAcceleration ? kConstantAcceleration
                                                              : kConstantJerk;
}

/// The configuration as its filter reads it: the fields only other types read set to
/// their defaults (a Kalman or adaptive bank has no window, order or delay; a fit or a
/// finite difference no Kalman model, noise, bandwidths or lag; a finite difference's
/// window is order + 1), and the process noise as the filter runs it.
inline DifferentiatorConfig asRun(DifferentiatorConfig c) {
  const DifferentiatorConfig defaults;
  if (c.type == DifferentiatorType::kKalman || c.type == DifferentiatorType::kAdaptive) {
    c.window = defaults.window;
    c.order = defaults.order;
    c.delay = defaults.delay;
    c.process_noise = processNoise(c);  // 0 is the model's default: the same filter
    return c;
  }
  const int window = c.type == DifferentiatorType::kFiniteDifference ? defaults.window : c.window;
  DifferentiatorConfig fit = defaults;
  fit.type = c.type;
  fit.window = window;
  fit.order = c.order;
  fit.delay = c.delay;
  fit.max_gap = c.max_gap;
  fit.process_noise = processNoise(fit);
  return fit;
}

/// Whether two configurations make the same filter: every field the type reads equal
/// (asRun), so that a change of another type's setting (a Savitzky-Golay order while a
/// Kalman filter runs) keeps the filters.
inline bool sameDifferentiator(const DifferentiatorConfig& a, const DifferentiatorConfig& b) {
  return asRun(a).fields() == asRun(b).fields();
}

/// Checks a configuration once (the bank on construction, validate(EstimatorConfig) in
/// config.hpp); throws std::invalid_argument naming the parameter as config/default.yaml
/// spells it ("parameter 'differentiator/order' must be 2..5 ...").
inline void validate(const DifferentiatorConfig& c) {
  constexpr double kMaxLag = 10.0;  // [s] a smoother's delay: beyond it, an offline job
  const auto fail = [](const char* key, const std::string& what) {
    throw std::invalid_argument(std::string("parameter 'differentiator/") + key + "' " + what);
  };
  if (c.type == DifferentiatorType::kAdaptive) {
    if (!(c.min_bandwidth > 0.0) || !std::isfinite(c.min_bandwidth))
      fail("min_bandwidth", "must be finite and > 0 [Hz]");
    if (!(c.max_bandwidth >= c.min_bandwidth) || !std::isfinite(c.max_bandwidth))
      fail("max_bandwidth", "must be finite and >= min_bandwidth [Hz]");
    if (!(c.noise >= 0.0) || !std::isfinite(c.noise))
      fail("noise", "must be finite and >= 0 (0: estimated online)");
    if (!(c.memory > 0.0) || !std::isfinite(c.memory)) fail("memory", "must be finite and > 0 [s]");
    if (!(c.lag >= 0.0) || !(c.lag <= kMaxLag))
      fail("lag", "must be 0..10 [s] (0: the causal filter)");
  } else if (c.type == DifferentiatorType::kKalman) {
    if (!(c.process_noise >= 0.0) || !std::isfinite(c.process_noise))
      fail("process_noise", "must be finite and >= 0 (0: the model's default)");
    if (!(c.measurement_noise > 0.0) || !std::isfinite(c.measurement_noise))
      fail("measurement_noise", "must be finite and > 0");
    if (!(c.lag >= 0.0) || !(c.lag <= kMaxLag))
      fail("lag", "must be 0..10 [s] (0: the causal filter)");
    if (c.auto_bandwidth && (!(c.min_bandwidth > 0.0) || !std::isfinite(c.min_bandwidth)))
      fail("min_bandwidth", "must be finite and > 0 [Hz]");
    if (c.auto_bandwidth &&
        (!(c.max_bandwidth >= c.min_bandwidth) || !std::isfinite(c.max_bandwidth)))
      fail("max_bandwidth", "must be finite and >= min_bandwidth [Hz]");
  } else {
    if (c.lag != 0.0) fail("lag", "applies to types kalman and adaptive only (it must be 0)");
    if (c.order < 2 || c.order > 5)
      fail("order", "must be 2..5 (a second derivative needs a quadratic), it is " +
                        std::to_string(c.order));
    const int window = c.type == DifferentiatorType::kFiniteDifference ? c.order + 1 : c.window;
    if (window < c.order + 1 || window > 101)
      fail("window", "must be order+1..101, it is " + std::to_string(c.window));
    if (c.delay < 0 || c.delay >= window)
      fail("delay", "must be 0..window-1, it is " + std::to_string(c.delay));
  }
  if (!(c.max_gap > 0.0) || !std::isfinite(c.max_gap))
    fail("max_gap", "must be finite and > 0 [s]");
}

}  // namespace jle
