// Covariance of the joint wrenches the Estimator publishes (UncertaintyConfig,
// docs/studies/uncertainty.md): what is set up once for a model (CovarianceModel), the per-sample
// matrices (CovarianceWorkspace), and the free functions that fill them. ROS-free; the
// propagation itself is described in src/estimation/covariance.cpp.
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <vector>

namespace jle {

struct UncertaintyConfig;  // config.hpp
struct WrenchInputConfig;  // config.hpp

/// The fixed part of the propagation for one model and the segments the estimator
/// computes: the noise variances, the wrench inputs' noise, the subtrees and, per
/// coordinate, the segments its sweep visits.
struct CovarianceModel {
  /// The noise of a wrench input a computed segment needs: variances [N^2, N^2 m^2] per
  /// component, at model frame `frame`.
  struct InputNoise {
    int frame = 0;
    double var_force = 0.0;
    double var_moment = 0.0;
  };

  CovarianceModel() = default;
  /// input_frames[k]: the model frame wrench input k acts at, -1 where no computed segment
  /// needs it. kinematics_segments: closed under parents; dynamics_segments: closed under
  /// children (the estimator's). Throws std::invalid_argument naming the setting (of the
  /// uncertainty or of a wrench input) that is negative or not finite. With the
  /// uncertainty disabled only the checks are made.
  CovarianceModel(const Model<double>& model, const UncertaintyConfig& uncertainty,
                  const std::vector<WrenchInputConfig>& wrenches,
                  const std::vector<int>& input_frames, const std::vector<int>& kinematics_segments,
                  const std::vector<int>& dynamics_segments);

  bool enabled = false;
  bool diagonal_only = false;
  bool linearize_state = true;
  double var_position = 0.0;                                             ///< [rad^2 or m^2]
  double mass_fraction = 0.0, com_offset = 0.0, inertia_fraction = 0.0;  ///< UncertaintyConfig
  double period = 0.0, gain_tolerance = 0.0;                             ///< [s], relative
  std::vector<InputNoise> inputs;                                        ///< those with noise
  std::vector<int> kinematics_segments, dynamics_segments;
  std::vector<int> subtree_end;  ///< per segment: its subtree is [i, subtree_end[i])
  std::vector<char> in_dynamics, in_kinematics;  ///< per segment
  /// Per coordinate: the computed segments it moves (the subtrees of the joints it
  /// drives), empty if none; with several disjoint subtrees (mimic joints), the computed
  /// segments above them (which see the sum of their effects), deepest first.
  std::vector<std::vector<int>> sweep, sweep_ancestors;
  std::vector<char> single_root;  ///< per coordinate
};

/// The per-sample matrices of the propagation, sized once (no allocation per sample).
struct CovarianceWorkspace {
  using Matrix6 = Eigen::Matrix<double, 6, 6>;

  CovarianceWorkspace() = default;
  CovarianceWorkspace(const CovarianceModel& cm, int segments);

  /// Per segment: the covariance of its joint wrench (child frame, (fx fy fz mx my mz),
  /// moment about the joint origin [N^2, N^2 m, N^2 m^2]).
  std::vector<Matrix6> covariance;
  std::vector<Matrix6> local;  ///< per segment: covariance of its own terms, then of its subtree
  /// Per segment, one coordinate's sweep (columns: the noise directions): tangents of
  /// omega, alpha, the origin acceleration, then of the force and moment (segment frame).
  std::vector<Eigen::Matrix3d> t_w, t_al, t_acc, t_f, t_n;
  std::vector<Eigen::Matrix<double, 6, 3>> jacobian;  ///< per segment: ancestors of a mimic's sweep
  std::vector<int> sweep_mark;  ///< per segment: the coordinate being swept + 1, or 0

  /// uncertainty.period: the last three computed covariances (newest first) per segment,
  /// their stamps [s] and noise gains, and how many are valid.
  std::vector<Matrix6> last, prev, prev2;
  double time[3] = {0.0, 0.0, 0.0};
  Eigen::Matrix3d gain[3] = {Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero(),
                             Eigen::Matrix3d::Zero()};
  int history = 0;
};

/// uncertainty.period: at stamp t [s] with the filter's noise gain `gain`, the quadratic
/// through the last three computed covariances when t is less than a period after the
/// newest and `gain` is within gain_tolerance of the gain of each of the three (true);
/// false: the covariance is to be computed (computeCovariance). A stamp not after the
/// newest, more than three periods after it, or a gain away from the newest's restarts
/// the history. While a filter settles (after a start, a gap or a reset) its gain moves
/// from one node to the next, so those samples are all computed.
bool extrapolateCovariance(const CovarianceModel& cm, CovarianceWorkspace& ws,
                           const Eigen::Matrix3d& gain, double t);

/// The covariance of the joint wrenches of `nominal` (the loads just computed, in double,
/// with the kinematics of the estimate) at stamp t [s], with the filter's noise gain
/// `gain` (DifferentiatorBank::noiseGain); kept for the extrapolation a period apart.
void computeCovariance(const CovarianceModel& cm, CovarianceWorkspace& ws,
                       const Model<double>& model, const Data<double>& nominal,
                       const Eigen::Matrix3d& gain, double t);

/// The variance of a joint's effort [N^2 m^2 or N^2] from its wrench covariance C
/// (0 for a joint that does not move; clamped at 0: an extrapolated C may be indefinite).
double effortVariance(const Model<double>& model, const Eigen::Matrix<double, 6, 6>& C,
                      int segment);

}  // namespace jle
