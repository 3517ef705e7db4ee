// Predicted against measured: the residual of every force/torque sensor (its
// reading minus the model's prediction of the wrench across its joint) and of a
// floating base, their diagnostics, and the sensors' bias calibration
// (~calibrate_bias, bias_file). The numbers come from the core (sensor_bias.hpp);
// this file converts, publishes and waits.
#include <tf2_eigen/tf2_eigen.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <joint_load_estimator/ros/estimator_node.hpp>
#include <sstream>

namespace jle {
namespace {

// A calibration fails when no loads are computed for this long [wall s] (the
// joint states stopped): the window would never fill.
constexpr double kNoSampleTimeout = 5.0;

geometry_msgs::Wrench toWrench(const SensorBias& b) {
  geometry_msgs::Wrench w;
  w.force = tf2::toMsg(b.force, w.force);
  w.torque = tf2::toMsg(b.torque, w.torque);
  return w;
}

}  // namespace

void EstimatorNode::setUpConsistency() {
  // Predicted against measured: every sensor's residual, the floating base's.
  for (std::size_t k = 0; k < settings_.estimator.wrenches.size(); ++k) {
    const std::string& joint = settings_.estimator.wrenches[k].sensor_joint;
    if (joint.empty()) continue;
    sensor_topics_.push_back(k);
    wrench_topics_[k].consistency_pub =
        private_nh_.advertise<geometry_msgs::WrenchStamped>("consistency/" + joint, 10);
  }
  const Model<double>& model = pipeline_->model();
  total_weight_ = model.totalMass() * settings_.estimator.gravity_world.norm();
  pending_bias_.assign(settings_.wrenches.size(), SensorBias());
  ros::AdvertiseServiceOptions calibrate =
      ros::AdvertiseServiceOptions::create<joint_load_estimator::CalibrateBias>(
          "calibrate_bias",
          [this](joint_load_estimator::CalibrateBias::Request& req,
                 joint_load_estimator::CalibrateBias::Response& res) {
            return onCalibrateBias(req, res);
          },
          ros::VoidConstPtr(), &service_queue_);
  calibrate_srv_ = private_nh_.advertiseService(calibrate);
  service_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &service_queue_);
  service_spinner_->start();
}

void EstimatorNode::applyPendingBias() {
  if (!bias_pending_.load()) return;
  std::lock_guard<std::mutex> lock(calibration_mutex_);
  for (std::size_t k : sensor_topics_)
    pipeline_->setSensorBias(static_cast<int>(k), pending_bias_[k].force, pending_bias_[k].torque);
  bias_pending_ = false;
}

void EstimatorNode::publishConsistency(const LoadsRecord& record, const ros::Time& stamp) {
  if (pipeline_->model().floating_base) {
    base_force_max_ = std::max(base_force_max_, record.base_force.norm());
    base_moment_max_ = std::max(base_moment_max_, record.base_moment.norm());
  }
  for (std::size_t k : sensor_topics_) {
    tallySign(record.inputs[k], settings_.wrenches[k].force_threshold, wrench_topics_[k].sign);
    if (record.inputs[k].used) publishResidual(record.inputs[k], k, stamp);
  }
  if (!sensor_topics_.empty() && calibrating_.load()) collectBiasSample(record);
}

void EstimatorNode::publishResidual(const InputRecord& input, std::size_t k,
                                    const ros::Time& stamp) {
  WrenchTopic& topic = wrench_topics_[k];
  const Wrench<double>& r = input.residual;
  topic.max_force = std::max(topic.max_force, r.force.norm());
  topic.max_moment = std::max(topic.max_moment, r.moment.norm());
  if (topic.consistency_pub.getNumSubscribers() == 0) return;
  wrench_msg_.header.stamp = stamp;
  wrench_msg_.header.frame_id = input.frame;
  tf2::toMsg(r.force, wrench_msg_.wrench.force);
  tf2::toMsg(r.moment, wrench_msg_.wrench.torque);
  topic.consistency_pub.publish(wrench_msg_);
}

void EstimatorNode::collectBiasSample(const LoadsRecord& record) {
  std::lock_guard<std::mutex> lock(calibration_mutex_);
  Calibration& c = calibration_;
  if (c.active && c.estimator.collecting()) {
    for (std::size_t i = 0; i < sensor_topics_.size(); ++i) {
      const std::size_t k = sensor_topics_[i];
      const int input = static_cast<int>(k);
      BiasSample& sample = c.sample[i];
      sample.used = record.inputs[k].used;
      if (sample.used)
        sample.offset =
            readingOffset(record.inputs[k].residual, settings_.estimator.wrenches[k].sign,
                          {pipeline_->sensorBiasForce(input), pipeline_->sensorBiasTorque(input)});
    }
    if (c.estimator.add(1e-9 * static_cast<double>(record.stamp), c.sample, record.qd, c.needed))
      c.last_sample = ros::WallTime::now();
  }
  // The service thread waits for the window to fill or fail.
  if (!(c.active && c.estimator.collecting())) calibration_cv_.notify_all();
}

void EstimatorNode::diagnoseConsistency(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(callbacks_mutex_);
  std::string warnings;
  auto warn = [&](const std::string& w) { warnings += (warnings.empty() ? "" : "; ") + w; };
  char text[256];
  for (std::size_t k : sensor_topics_) {
    WrenchTopic& topic = wrench_topics_[k];
    const WrenchTopicSettings& limits = settings_.wrenches[k];
    const std::string& joint = settings_.estimator.wrenches[k].sensor_joint;
    if (topic.max_force > limits.force_threshold) {
      std::snprintf(text, sizeof text, "sensor %s: residual force %.3g N > %.3g N", joint.c_str(),
                    topic.max_force, limits.force_threshold);
      warn(text);
    }
    if (topic.max_moment > limits.moment_threshold) {
      std::snprintf(text, sizeof text, "sensor %s: residual moment %.3g N m > %.3g N m",
                    joint.c_str(), topic.max_moment, limits.moment_threshold);
      warn(text);
    }
    const std::string sign = signWarning(joint, settings_.estimator.wrenches[k].sign, topic.sign);
    if (!sign.empty()) {
      warn(sign);
      ROS_WARN_THROTTLE(10.0, "%s", sign.c_str());
    }
    status.add(joint + ": max |residual force| [N]", topic.max_force);
    status.add(joint + ": max |residual moment| [N m]", topic.max_moment);
    topic.max_force = 0.0;
    topic.max_moment = 0.0;
  }
  if (pipeline_->model().floating_base) {
    const double limit = settings_.base_residual_threshold * total_weight_;
    if (base_force_max_ > limit) {
      std::snprintf(text, sizeof text,
                    "base residual force %.3g N > %.3g N (%.3g of the weight %.3g N)",
                    base_force_max_, limit, settings_.base_residual_threshold, total_weight_);
      warn(text);
    }
    status.add("base: max |residual force| [N]", base_force_max_);
    status.add("base: max |residual moment| [N m]", base_moment_max_);
    base_force_max_ = 0.0;
    base_moment_max_ = 0.0;
  }
  if (warnings.empty())
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "measurements agree with the model");
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, warnings);
}

bool EstimatorNode::onCalibrateBias(joint_load_estimator::CalibrateBias::Request& req,
                                    joint_load_estimator::CalibrateBias::Response& res) {
  res.success = false;
  if (sensor_topics_.empty()) {
    res.message =
        "no force/torque sensor is configured (a wrench input with "
        "sensor_joint)";
    return true;
  }
  if (!(req.duration > 0.0) || !std::isfinite(req.duration)) {
    res.message = "duration must be positive";
    return true;
  }
  std::unique_lock<std::mutex> lock(calibration_mutex_);
  if (calibration_.active) {
    res.message = "a calibration is already running";
    return true;
  }
  startCalibration(req.duration, req.assume_still);
  waitForCalibration(lock);
  const BiasEstimator& bias = calibration_.estimator;
  if (!bias.done()) {
    res.message = bias.failure().empty() ? "the node is shutting down" : bias.failure();
    res.message += ": no bias changed";
    return true;
  }
  const long n = bias.samples();
  const std::vector<BiasFileEntry> entries = applyCalibration(res);
  bias_pending_ = true;
  lock.unlock();
  res.success = true;
  std::ostringstream message;
  message << "bias of " << res.sensors.size() << " sensor(s) estimated from " << n << " samples";
  const std::string& path = settings_.bias_file;
  const std::string error = path.empty() ? "" : saveBiasFile(path, entries, n);
  if (path.empty())
    message << "; not stored (no bias_file)";
  else if (!error.empty())
    message << "; NOT stored: " << error;
  else
    res.file = path;
  res.message = message.str();
  ROS_INFO("calibrate_bias: %s", res.message.c_str());
  return true;
}

void EstimatorNode::startCalibration(double duration, bool assume_still) {
  const Model<double>& model = pipeline_->model();
  std::vector<std::string> sensors;
  for (std::size_t k : sensor_topics_)
    sensors.push_back(settings_.estimator.wrenches[k].sensor_joint);
  Calibration& c = calibration_;
  c.estimator = BiasEstimator(sensors, model.coordinate_names);
  c.estimator.start(duration, assume_still, settings_.still_velocity);
  c.sample.assign(sensor_topics_.size(), BiasSample());
  c.needed.assign(static_cast<std::size_t>(model.nq), 0);
  for (int i = 0; i < model.nq; ++i)
    c.needed[static_cast<std::size_t>(i)] = pipeline_->coordinateNeeded(i);
  c.last_sample = ros::WallTime::now();
  c.active = true;
  calibrating_ = true;
}

void EstimatorNode::waitForCalibration(std::unique_lock<std::mutex>& lock) {
  Calibration& c = calibration_;
  // Loads are computed on the node's own thread; this one only waits for the
  // window.
  while (c.estimator.collecting() && !shutting_down_ && ros::ok()) {
    if ((ros::WallTime::now() - c.last_sample).toSec() > kNoSampleTimeout) {
      c.estimator.fail("no loads were computed for 5 s (no joint states?)");
      break;
    }
    calibration_cv_.wait_for(lock, std::chrono::milliseconds(100));
  }
  calibrating_ = false;
  c.active = false;
}

std::vector<BiasFileEntry> EstimatorNode::applyCalibration(
    joint_load_estimator::CalibrateBias::Response& res) {
  const BiasEstimator& bias = calibration_.estimator;
  std::vector<BiasFileEntry> entries;
  for (std::size_t i = 0; i < sensor_topics_.size(); ++i) {
    const std::size_t k = sensor_topics_[i];
    BiasFileEntry entry;
    entry.joint = settings_.estimator.wrenches[k].sensor_joint;
    entry.frame = pipeline_->wrenchFrame(static_cast<int>(k));
    entry.bias = bias.mean(i);
    entry.stddev = bias.stddev(i);
    pending_bias_[k] = entry.bias;  // handed to the pipeline on the callbacks' thread
    res.sensors.push_back(entry.joint);
    res.bias.push_back(toWrench(entry.bias));
    res.stddev.push_back(toWrench(entry.stddev));
    entries.push_back(entry);
  }
  return entries;
}

}  // namespace jle
