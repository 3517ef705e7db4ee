#include <joint_load_estimator/estimation/sensor_bias.hpp>
#include <joint_load_estimator/model/frames.hpp>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace jle {
namespace {

SensorBias split(const Eigen::Matrix<double, 6, 1>& x) {
  SensorBias b;
  b.force = x.head<3>();
  b.torque = x.tail<3>();
  return b;
}

}  // namespace

Wrench<double> residualInReading(const Wrench<double>& residual_link,
                                 const Eigen::Matrix3d& R_link_sensor,
                                 const Eigen::Vector3d& p_link_sensor) {
  Wrench<double> r;
  wrenchInFrame(R_link_sensor, p_link_sensor, residual_link.force, residual_link.moment, r.force,
                r.moment);
  return r;
}

Eigen::Matrix<double, 6, 1> readingOffset(const Wrench<double>& residual_reading, double sign,
                                          const SensorBias& bias) {
  Eigen::Matrix<double, 6, 1> x;
  x << bias.force + sign * residual_reading.force, bias.torque + sign * residual_reading.moment;
  return x;
}

BiasEstimator::BiasEstimator(std::vector<std::string> sensor_names,
                             std::vector<std::string> coordinate_names)
    : sensor_names_(std::move(sensor_names)), coordinate_names_(std::move(coordinate_names)) {}

void BiasEstimator::start(double duration, bool assume_still, double still_velocity) {
  if (!(duration > 0.0) || !std::isfinite(duration))
    throw std::invalid_argument("bias calibration: duration must be positive");
  if (!assume_still && !(still_velocity > 0.0))
    throw std::invalid_argument("bias calibration: still_velocity must be positive");
  started_ = true;
  done_ = false;
  assume_still_ = assume_still;
  duration_ = duration;
  still_velocity_ = still_velocity;
  first_stamp_ = 0.0;
  failure_.clear();
  samples_ = 0;
  mean_.assign(sensor_names_.size(), Vector6::Zero());
  m2_.assign(sensor_names_.size(), Vector6::Zero());
}

bool BiasEstimator::still(const Eigen::VectorXd& qd, const std::vector<char>& needed) {
  for (Eigen::Index i = 0; i < qd.size(); ++i) {
    if (!needed[static_cast<std::size_t>(i)] || !(std::abs(qd[i]) > still_velocity_)) continue;
    std::ostringstream why;
    why << "the robot is not still: the estimated velocity of '"
        << coordinate_names_[static_cast<std::size_t>(i)] << "' is " << qd[i]
        << ", above still_velocity " << still_velocity_;
    failure_ = why.str();
    return false;
  }
  return true;
}

bool BiasEstimator::fresh(const std::vector<BiasSample>& sensors) {
  for (std::size_t k = 0; k < sensors.size(); ++k)
    if (!sensors[k].used) {
      failure_ = "sensor '" + sensor_names_[k] + "' is stale";
      return false;
    }
  return true;
}

bool BiasEstimator::add(double stamp, const std::vector<BiasSample>& sensors,
                        const Eigen::VectorXd& qd, const std::vector<char>& needed) {
  if (sensors.size() != sensor_names_.size())
    throw std::invalid_argument("bias calibration: " + std::to_string(sensors.size()) +
                                " sensor samples for " + std::to_string(sensor_names_.size()) +
                                " sensors");
  if (static_cast<std::size_t>(qd.size()) != coordinate_names_.size() ||
      needed.size() != coordinate_names_.size())
    throw std::invalid_argument(
        "bias calibration: qd and needed must have one entry per coordinate (" +
        std::to_string(coordinate_names_.size()) + ")");
  if (!collecting()) return false;
  if (!assume_still_ && !still(qd, needed)) return false;
  if (!fresh(sensors)) return false;
  // Welford: the running mean and sum of squared deviations, one pass, no
  // cancellation between large sums.
  const double n = static_cast<double>(samples_ + 1);
  for (std::size_t k = 0; k < sensors.size(); ++k) {
    const Vector6& x = sensors[k].offset;
    const Vector6 delta = x - mean_[k];
    mean_[k] += delta / n;
    m2_[k] += delta.cwiseProduct(x - mean_[k]);
  }
  if (samples_ == 0) first_stamp_ = stamp;
  ++samples_;
  if (stamp - first_stamp_ >= duration_) done_ = true;
  return true;
}

void BiasEstimator::fail(const std::string& reason) {
  if (collecting()) failure_ = reason;
}

SensorBias BiasEstimator::mean(std::size_t k) const { return split(mean_.at(k)); }

SensorBias BiasEstimator::stddev(std::size_t k) const {
  const Vector6& m2 = m2_.at(k);
  if (samples_ < 2) return SensorBias();
  return split((m2 / static_cast<double>(samples_ - 1)).cwiseSqrt());
}

}  // namespace jle
