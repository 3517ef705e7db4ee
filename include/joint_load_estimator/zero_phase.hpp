// Offline zero-phase smoothing and differentiation of a whole record (positions-only
// joint states, and the wrench and plate columns filtered alike): a Butterworth low-pass
// run forward and backward, its cutoff given in Hz or chosen from the data. ROS-free.
// The method, its padding, its handling of irregular stamps and its measured errors are in
// docs/zero_phase.md.
#pragma once

#include <joint_load_estimator/eigen_abi.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace jle {

/// How the cutoff of the zero-phase filter is chosen.
enum class CutoffRule : std::uint8_t {
  kFixed,     ///< ZeroPhaseConfig::cutoff
  kResidual,  ///< Winter's residual analysis (Biomechanics and Motor Control, ch. 3)
  kGcv,       ///< generalised cross-validation of the Butterworth smoother
};

/// "given", "residual analysis", "generalised cross-validation".
const char* toString(CutoffRule rule);
/// `text` "gcv" or "residual" (the tools' --cutoff-rule) into `rule`; false otherwise.
bool parseCutoffRule(const std::string& text, CutoffRule& rule);

/// The zero-phase filter. `order` is that of each pass (scipy.signal.butter(order) run by
/// filtfilt): the amplitude response of the whole is |H|^2, of order 2 * order, and the
/// cutoff is where one pass is at -3 dB (the whole at -6 dB).
struct ZeroPhaseConfig {
  double cutoff = 0.0;  ///< [Hz] low-pass cutoff; used when rule == kFixed
  /// GCV by default: the measured-better rule (docs/zero_phase.md: effort RMS error 0.75
  /// times the residual rule's, median over 20 Panda scenes).
  CutoffRule rule = CutoffRule::kGcv;
  int order = 4;  ///< Butterworth order of one pass, 1..8
  /// Samples added at each end by odd reflection before filtering; 0: 3 * (order + 1), as
  /// scipy.signal.filtfilt by default. At most the record's samples - 1.
  int padding = 0;
};

/// Zero-phase smoothed value, first and second derivative of every channel at the input
/// stamps: rows are samples, columns channels, in the channels' unit [u], [u/s], [u/s^2];
/// and the cutoff used [Hz].
struct ZeroPhaseResult {
  Eigen::MatrixXd value, rate, accel;
  double cutoff = 0.0;
};

/// Samples x channels in, at the stamps t [s] (strictly increasing, possibly irregular;
/// at least 3); one cutoff for all channels (kinematics and forces filtered alike),
/// returned in `cutoff`. Irregular stamps are resampled on a uniform grid at the median
/// period, filtered there and evaluated back at t (docs/zero_phase.md). Throws
/// std::invalid_argument naming what is wrong (sizes, stamps, config).
ZeroPhaseResult smoothZeroPhase(const std::vector<double>& t, const Eigen::MatrixXd& x,
                                const ZeroPhaseConfig& config);

/// The same filter (cutoff [Hz] given, no derivatives) for force, wrench and plate
/// columns: samples x channels in and out, at the stamps t [s]; `padding` as in
/// ZeroPhaseConfig.
Eigen::MatrixXd lowPassZeroPhase(const std::vector<double>& t, const Eigen::MatrixXd& x,
                                 double cutoff, int order, int padding = 0);

/// The cutoff [Hz] that config.rule chooses for the channels x at stamps t (config.cutoff
/// for kFixed), without filtering the result.
double chooseCutoff(const std::vector<double>& t, const Eigen::MatrixXd& x,
                    const ZeroPhaseConfig& config);

/// Checks a configuration once; throws std::invalid_argument naming the member
/// ("zero_phase cutoff must be finite and > 0 [Hz] ...").
void validate(const ZeroPhaseConfig& config);

}  // namespace jle
