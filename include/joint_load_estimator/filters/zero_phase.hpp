// Offline zero-phase smoothing and differentiation of a whole record (positions-only
// joint states, and the wrench and plate columns filtered alike): a Butterworth low-pass
// run forward and backward, its cutoff given in Hz or chosen from the data. ROS-free.
// The method, its padding, its handling of irregular stamps and its measured errors are in
// docs/studies/zero_phase.md.
#pragma once

#include <joint_load_estimator/model/eigen_abi.hpp>

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
  /// Where the positions' spectrum meets its noise floor (the first plateau above the
  /// motion's steep fall): coloured noise is not taken for motion.
  kSpectrum,
  /// The zero-phase acceleration of the positions closest (mean square) to the central
  /// differences of measured velocities, whose noise is independent of the positions':
  /// needs the velocities.
  kVelocity,
  /// kVelocity when measured velocities are given and follow the positions (their
  /// difference from the rate at kSpectrum's cutoff below half the rate's mean square;
  /// CutoffChoice warns when they do not), kSpectrum otherwise.
  kAuto,
};

/// "given", "residual analysis", "generalised cross-validation", "noise spectrum",
/// "velocity evidence", "auto".
const char* toString(CutoffRule rule);
/// `text` "auto", "spectrum", "velocity", "gcv" or "residual" (the tools' --cutoff-rule)
/// into `rule`; false otherwise.
bool parseCutoffRule(const std::string& text, CutoffRule& rule);

/// The zero-phase filter. `order` is that of each pass (scipy.signal.butter(order) run by
/// filtfilt): the amplitude response of the whole is |H|^2, of order 2 * order, and the
/// cutoff is where one pass is at -3 dB (the whole at -6 dB).
struct ZeroPhaseConfig {
  double cutoff = 0.0;  ///< [Hz] low-pass cutoff; used when rule == kFixed
  /// kAuto by default: the measured-best rule (docs/studies/zero_phase.md, the table of chosen
  /// cutoffs and errors over the accuracy study's scenes).
  CutoffRule rule = CutoffRule::kAuto;
  /// [Hz] the highest cutoff an automatic rule chooses (what the bodies that the loads are
  /// computed for move at; the search also stops at 0.4 of the sampling rate). A choice
  /// on this bound or on the lowest one is reported in CutoffChoice::warnings.
  double max_cutoff = 50.0;
  int order = 4;  ///< Butterworth order of one pass, 1..8
  /// Samples added at each end by odd reflection before filtering; 0: 3 * (order + 1), as
  /// scipy.signal.filtfilt by default. At most the record's samples - 1.
  int padding = 0;
};

/// The cutoff an automatic rule chose, the rule that chose it (kAuto resolved), the
/// search's bounds [Hz], and what a user must hear: one line per warning (the choice on a
/// bound; another rule, or the measured velocities, disagreeing by more than
/// kCutoffDisagreement with the positions' own cutoff; the cutoff raised for channels
/// filtered alike, and those whose content reaches more than kCutoffDisagreement above
/// it). Empty warnings for kFixed.
struct CutoffChoice {
  double cutoff = 0.0;  ///< [Hz]
  CutoffRule rule = CutoffRule::kFixed;
  double lowest = 0.0, highest = 0.0;  ///< [Hz] the search's bounds
  /// [Hz] the positions' own cutoff (what `rule` chose), before the channels filtered alike
  /// raised it (FilteredAlike); equal to `cutoff` when they did not.
  double positions_cutoff = 0.0;
  std::vector<std::string> warnings;
};

/// Force, wrench or plate channels that are filtered with the positions' cutoff: samples x
/// channels ([N], [N m]) at their own stamps t [s] (strictly increasing, at least 3), and
/// what they are, for the warnings ("wrench input foot").
///
/// Given to an automatic rule, they may raise its cutoff. Sampled fast, their own spectrum
/// shows where their content ends (kSpectrum on them, up to max_cutoff): a contact force's
/// heel strikes reach 50 Hz and more, a slow F/T wrench a few Hz. Where that lies more than
/// kCutoffDisagreement above the positions' own cutoff f_p, the positions' choice would
/// smooth the loads' largest term: the cutoff rises from f_p towards it, as long as the
/// noise the rise lets into the positions' acceleration (its mean square change from f_p's:
/// above f_p their spectrum is noise) stays below the acceleration's own mean square at f_p
/// (as much noise as motion, the balance kSpectrum strikes per band, struck over the whole
/// acceleration). Not scored in the loads: the weights of the two (the body's inertias and
/// the contact's lever arms) are the model's, which the filter does not have. Measured
/// (bench/accuracy.cpp, docs/studies/zero_phase.md) on leg_gait_70hz, a running leg's
/// positions at 70 Hz with 2e-3 rad of noise flat to 15 Hz and its 1 kHz contact force: f_p
/// 4.99 Hz (noise spectrum; the best fixed cutoff for the motion alone, without the force,
/// is 4.59 Hz) erred 2.34 times the best fixed cutoff's 7.76 N m (10.8 Hz, the force filtered
/// alike); raised to 8.61 Hz, 1.13 times. On every arm scene no wrench reaches that far and
/// the choice is the positions' own. The choice raised says so in CutoffChoice::warnings, and
/// so does a channel whose content still reaches more than kCutoffDisagreement above it.
struct FilteredAlike {
  std::vector<double> t;
  Eigen::MatrixXd x;
  std::string what;
};

/// The ratio between two rules' cutoffs beyond which CutoffChoice warns.
constexpr double kCutoffDisagreement = 2.5;

/// Zero-phase smoothed value, first and second derivative of every channel at the input
/// stamps: rows are samples, columns channels, in the channels' unit [u], [u/s], [u/s^2];
/// and the cutoff used [Hz].
struct ZeroPhaseResult {
  Eigen::MatrixXd value, rate, accel;
  double cutoff = 0.0;
  CutoffChoice choice;  ///< how `cutoff` was chosen
};

/// Samples x channels in, at the stamps t [s] (strictly increasing, possibly irregular;
/// at least 3); one cutoff for all channels (kinematics and forces filtered alike),
/// returned in `cutoff`. Irregular stamps are resampled on a uniform grid at the median
/// period, filtered there and evaluated back at t (docs/studies/zero_phase.md). Throws
/// std::invalid_argument naming what is wrong (sizes, stamps, config).
/// `velocities`: empty, or measured rates of the same channels at the same stamps
/// (samples x channels, [u/s]; non-finite entries left out): the evidence of kVelocity and
/// kAuto, and a cross-check of the other automatic rules. `alike`: the force, wrench and
/// plate channels that the caller filters with the returned cutoff (lowPassZeroPhase),
/// which an automatic rule's cutoff rises for (FilteredAlike) and which are checked as
/// checkFilteredAlike does; not filtered here.
ZeroPhaseResult smoothZeroPhase(const std::vector<double>& t, const Eigen::MatrixXd& x,
                                const ZeroPhaseConfig& config,
                                const Eigen::MatrixXd& velocities = Eigen::MatrixXd(),
                                const std::vector<FilteredAlike>& alike = {});

/// The same filter (cutoff [Hz] given, no derivatives) for force, wrench and plate
/// columns: samples x channels in and out, at the stamps t [s]; `padding` as in
/// ZeroPhaseConfig.
Eigen::MatrixXd lowPassZeroPhase(const std::vector<double>& t, const Eigen::MatrixXd& x,
                                 double cutoff, int order, int padding = 0);

/// The force, wrench or plate channels x (samples x channels at the stamps t [s]) that an
/// automatic `choice` of the positions' cutoff filters alike (what smoothZeroPhase checks
/// for the channels given to it as `alike`): where their own spectrum
/// meets its noise floor (CutoffRule::kSpectrum up to config.max_cutoff), returned [Hz];
/// and a warning naming `what` into choice.warnings where that lies more than
/// kCutoffDisagreement above choice.cutoff: content (an impact, a heel strike) that the
/// positions' cutoff smooths away from the loads. 0 (and nothing said) for a fixed cutoff,
/// or where the channels show no noise floor (no fast content above their noise, or none
/// at all).
double checkFilteredAlike(const std::vector<double>& t, const Eigen::MatrixXd& x,
                          const ZeroPhaseConfig& config, const std::string& what,
                          CutoffChoice& choice);

/// The cutoff [Hz] that config.rule chooses for the channels x at stamps t (config.cutoff
/// for kFixed), without filtering the result; `velocities` as in smoothZeroPhase.
double chooseCutoff(const std::vector<double>& t, const Eigen::MatrixXd& x,
                    const ZeroPhaseConfig& config,
                    const Eigen::MatrixXd& velocities = Eigen::MatrixXd());

/// The same choice with its rule, bounds and warnings; `alike` as in smoothZeroPhase.
CutoffChoice selectCutoff(const std::vector<double>& t, const Eigen::MatrixXd& x,
                          const ZeroPhaseConfig& config,
                          const Eigen::MatrixXd& velocities = Eigen::MatrixXd(),
                          const std::vector<FilteredAlike>& alike = {});

/// Checks a configuration once; throws std::invalid_argument naming the member
/// ("zero_phase cutoff must be finite and > 0 [Hz] ...").
void validate(const ZeroPhaseConfig& config);

}  // namespace jle
