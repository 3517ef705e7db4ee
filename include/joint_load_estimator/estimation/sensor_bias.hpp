// A force/torque sensor's residual as the sensor reports it, and the estimate of its
// offset (bias) from a window of samples taken while the robot is still.
#pragma once

#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/eigen_abi.hpp>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace jle {

/// A sensor's offset in its reading's frame and sign convention (as it reports):
/// force [N] and torque [N m] about the reading frame's origin, subtracted from each
/// reading.
struct SensorBias {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
};

/// A sensor's residual (Estimator::LastSample::sensorResidual: measured minus predicted joint
/// wrench, in the sensor link's frame, moment about its origin) re-expressed in the
/// reading's frame S, moment about S's origin, S's pose in the link being
/// (R_link_sensor, p_link_sensor [m]). Its sign is the measured wrench's (the load on
/// the distal side).
Wrench<double> residualInReading(const Wrench<double>& residual_link,
                                 const Eigen::Matrix3d& R_link_sensor,
                                 const Eigen::Vector3d& p_link_sensor);

/// The reading's offset from `sign` times the prediction that a residual implies, in
/// the reading's frame and sign (force [N]; torque [N m]): the reading minus `bias` is
/// sign (residual + prediction), so the offset is bias + sign * residual.
/// `residual_reading` as residualInReading returns it; `sign` WrenchInputConfig::sign.
Eigen::Matrix<double, 6, 1> readingOffset(const Wrench<double>& residual_reading, double sign,
                                          const SensorBias& bias);

/// One sensor's part of a calibration sample.
struct BiasSample {
  /// False when the sensor's reading was not used at this sample (stale): the
  /// calibration then fails naming the sensor.
  bool used = false;
  /// readingOffset() of this sample: (force [N]; torque [N m]), reading frame and sign.
  Eigen::Matrix<double, 6, 1> offset = Eigen::Matrix<double, 6, 1>::Zero();
};

/// Estimates every sensor's offset as the mean of its per-sample offsets over a window
/// of sample stamps (Welford's running mean and variance), refusing the window if the
/// robot moves or a sensor goes stale. Idle until start(); then collecting until the
/// window is full (done) or a sample is refused (failed). Holds no clock: the caller
/// gives stamps, and ends a window that receives no samples with fail().
class BiasEstimator {
 public:
  using Vector6 = Eigen::Matrix<double, 6, 1>;

  BiasEstimator() = default;
  /// `sensor_names` (one per sensor, the order of every per-sensor vector) and
  /// `coordinate_names` (Model::coordinate_names) name them in failure reasons.
  BiasEstimator(std::vector<std::string> sensor_names, std::vector<std::string> coordinate_names);

  /// Begins a window spanning `duration` [s] of sample stamps (> 0, finite), forgetting
  /// the previous one. Unless `assume_still`, a sample where a needed coordinate's
  /// |q-dot| exceeds `still_velocity` [rad/s or m/s] (> 0) fails the window. Throws
  /// std::invalid_argument naming the bad argument.
  void start(double duration, bool assume_still, double still_velocity);

  /// Takes the sample of stamp [s]: one BiasSample per sensor, the estimated
  /// velocities `qd` (size nq) and which coordinates the loads need (`needed`, size
  /// nq, non-zero: needed). Returns true if the sample was taken; false when not
  /// collecting, or when it fails the window (not still, a sensor stale). The window
  /// is done once the stamps span `duration`. Throws std::invalid_argument on sizes.
  bool add(double stamp, const std::vector<BiasSample>& sensors, const Eigen::VectorXd& qd,
           const std::vector<char>& needed);

  /// Fails a collecting window for `reason` (e.g. no samples arrive); ignored otherwise.
  void fail(const std::string& reason);

  /// Started, neither done nor failed.
  bool collecting() const { return started_ && !done_ && failure_.empty(); }
  /// The window is full: mean() and stddev() are the estimate.
  bool done() const { return done_; }
  /// Why the window failed (empty: it did not).
  const std::string& failure() const { return failure_; }
  /// Samples taken in the window.
  long samples() const { return samples_; }
  /// Number of sensors (of sensor_names).
  std::size_t sensors() const { return sensor_names_.size(); }
  /// Sensor k's mean offset: its bias once done().
  SensorBias mean(std::size_t k) const;
  /// Sensor k's sample standard deviation of the per-sample offsets, per component
  /// [N, N m] (zero below two samples).
  SensorBias stddev(std::size_t k) const;

 private:
  bool still(const Eigen::VectorXd& qd, const std::vector<char>& needed);
  bool fresh(const std::vector<BiasSample>& sensors);

  std::vector<std::string> sensor_names_, coordinate_names_;
  bool started_ = false, done_ = false;
  bool assume_still_ = true;
  double duration_ = 0.0, still_velocity_ = 0.0, first_stamp_ = 0.0;
  std::string failure_;
  long samples_ = 0;
  std::vector<Vector6> mean_, m2_;  // per sensor: running mean, sum of squared deviations
};

}  // namespace jle
