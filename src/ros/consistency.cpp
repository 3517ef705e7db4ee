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

void EstimatorNode::publishConsistency(const ros::Time& stamp) {
  const Data<double>& data = estimator_->data();
  if (estimator_->model().floating_base) {
    base_force_max_ = std::max(base_force_max_, data.force[0].norm());
    base_moment_max_ = std::max(base_moment_max_, data.moment[0].norm());
  }
  for (std::size_t k : sensor_topics_) {
    if (!estimator_->sensorUsed(static_cast<int>(k))) continue;
    WrenchTopic& topic = *wrench_topics_[k];
    topic.residual = residualInReading(estimator_->sensorResidual(static_cast<int>(k)),
                                       topic.R_link_sensor, topic.p_link_sensor);
    publishResidual(topic, stamp);
  }
  if (!sensor_topics_.empty() && calibrating_.load()) collectBiasSample();
}

void EstimatorNode::publishResidual(WrenchTopic& topic, const ros::Time& stamp) {
  const Wrench<double>& r = topic.residual;
  topic.max_force = std::max(topic.max_force, r.force.norm());
  topic.max_moment = std::max(topic.max_moment, r.moment.norm());
  if (topic.consistency_pub.getNumSubscribers() == 0) return;
  wrench_msg_.header.stamp = stamp;
  wrench_msg_.header.frame_id =
      topic.sensor_frame.empty() ? topic.settings.input.link : topic.sensor_frame;
  wrench_msg_.wrench.force = tf2::toMsg(r.force, wrench_msg_.wrench.force);
  wrench_msg_.wrench.torque = tf2::toMsg(r.moment, wrench_msg_.wrench.torque);
  topic.consistency_pub.publish(wrench_msg_);
}

void EstimatorNode::collectBiasSample() {
  std::lock_guard<std::mutex> lock(calibration_mutex_);
  Calibration& c = calibration_;
  if (c.active && c.estimator.collecting()) {
    for (std::size_t i = 0; i < sensor_topics_.size(); ++i) {
      const std::size_t k = sensor_topics_[i];
      const WrenchTopic& topic = *wrench_topics_[k];
      BiasSample& sample = c.sample[i];
      sample.used = estimator_->sensorUsed(static_cast<int>(k));
      if (sample.used)
        sample.offset = readingOffset(topic.residual, topic.settings.input.sign, topic.bias);
    }
    if (c.estimator.add(estimator_->stamp(), c.sample, estimator_->qd(), c.needed))
      c.last_sample = ros::WallTime::now();
  }
  // The service thread waits for the window to fill or fail.
  if (!(c.active && c.estimator.collecting())) calibration_cv_.notify_all();
}

void EstimatorNode::diagnoseConsistency(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::string warnings;
  auto warn = [&](const std::string& w) { warnings += (warnings.empty() ? "" : "; ") + w; };
  char text[256];
  for (std::size_t k : sensor_topics_) {
    WrenchTopic& topic = *wrench_topics_[k];
    const std::string& joint = topic.settings.input.sensor_joint;
    if (topic.max_force > topic.settings.force_threshold) {
      std::snprintf(text, sizeof text, "sensor %s: residual force %.3g N > %.3g N", joint.c_str(),
                    topic.max_force, topic.settings.force_threshold);
      warn(text);
    }
    if (topic.max_moment > topic.settings.moment_threshold) {
      std::snprintf(text, sizeof text, "sensor %s: residual moment %.3g N m > %.3g N m",
                    joint.c_str(), topic.max_moment, topic.settings.moment_threshold);
      warn(text);
    }
    status.add(joint + ": max |residual force| [N]", topic.max_force);
    status.add(joint + ": max |residual moment| [N m]", topic.max_moment);
    topic.max_force = 0.0;
    topic.max_moment = 0.0;
  }
  if (estimator_->model().floating_base) {
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
  const Model<double>& model = estimator_->model();
  std::vector<std::string> sensors;
  for (std::size_t k : sensor_topics_)
    sensors.push_back(wrench_topics_[k]->settings.input.sensor_joint);
  Calibration& c = calibration_;
  c.estimator = BiasEstimator(sensors, model.coordinate_names);
  c.estimator.start(duration, assume_still, settings_.still_velocity);
  c.sample.assign(sensor_topics_.size(), BiasSample());
  c.needed.assign(static_cast<std::size_t>(model.nq), 0);
  for (int i = 0; i < model.nq; ++i)
    c.needed[static_cast<std::size_t>(i)] = estimator_->coordinateNeeded(i);
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
    WrenchTopic& topic = *wrench_topics_[sensor_topics_[i]];
    BiasFileEntry entry;
    entry.joint = topic.settings.input.sensor_joint;
    entry.frame = topic.sensor_frame;
    entry.bias = bias.mean(i);
    entry.stddev = bias.stddev(i);
    topic.bias = entry.bias;
    res.sensors.push_back(entry.joint);
    res.bias.push_back(toWrench(entry.bias));
    res.stddev.push_back(toWrench(entry.stddev));
    entries.push_back(entry);
  }
  return entries;
}

void EstimatorNode::loadBiasFile() {
  std::vector<BiasFileSensor> sensors;
  for (std::size_t k : sensor_topics_)
    sensors.push_back(
        {wrench_topics_[k]->settings.input.sensor_joint, wrench_topics_[k]->settings.frame});
  const std::vector<SensorBias> biases = jle::loadBiasFile(settings_.bias_file, sensors);
  std::lock_guard<std::mutex> lock(calibration_mutex_);  // a nodelet may already run
  for (std::size_t i = 0; i < sensor_topics_.size(); ++i)
    wrench_topics_[sensor_topics_[i]]->bias = biases[i];
}

}  // namespace jle
