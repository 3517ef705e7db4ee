// Predicted against measured: the residual of every force/torque sensor (its
// reading minus the model's prediction of the wrench across its joint) and of a
// floating base, their diagnostics, and the sensors' bias calibration
// (~calibrate_bias, bias_file).
#include <tf2_eigen/tf2_eigen.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <joint_load_estimator/ros/estimator_node.hpp>
#include <sstream>

namespace jle {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

// A calibration fails when no loads are computed for this long [wall s] (the
// joint states stopped): the window would never fill.
constexpr double kNoSampleTimeout = 5.0;

geometry_msgs::Wrench toWrench(const Vector6& v) {
  geometry_msgs::Wrench w;
  w.force.x = v[0];
  w.force.y = v[1];
  w.force.z = v[2];
  w.torque.x = v[3];
  w.torque.y = v[4];
  w.torque.z = v[5];
  return w;
}

std::string formatVector(const Vector6& v, int start) {
  std::ostringstream out;
  out << std::setprecision(17) << "[" << v[start] << ", " << v[start + 1] << ", " << v[start + 2]
      << "]";
  return out.str();
}

Eigen::Vector3d readVector(const YAML::Node& node, const std::string& where) {
  if (!node || !node.IsSequence() || node.size() != 3)
    throw SettingsError(where + " must be a list of 3 numbers");
  Eigen::Vector3d v;
  try {
    for (std::size_t i = 0; i < 3; ++i) v[static_cast<int>(i)] = node[i].as<double>();
  } catch (const YAML::Exception&) {
    throw SettingsError(where + " must be a list of 3 numbers");
  }
  if (!v.allFinite()) throw SettingsError(where + " is not finite");
  return v;
}

}  // namespace

void EstimatorNode::publishConsistency(const ros::Time& stamp) {
  const Data<double>& data = estimator_->data();
  if (estimator_->model().floating_base) {
    base_force_max_ = std::max(base_force_max_, data.force[0].norm());
    base_moment_max_ = std::max(base_moment_max_, data.moment[0].norm());
  }
  if (sensor_topics_.empty()) return;
  const bool calibrating = calibrating_.load();
  std::unique_lock<std::mutex> lock(calibration_mutex_, std::defer_lock);
  bool collect = false;
  if (calibrating) {
    lock.lock();
    Calibration& c = calibration_;
    collect = c.active && !c.done && c.failure.empty();
    if (collect && !c.assume_still) {
      const VectorX<double>& qd = estimator_->qd();
      for (int i = 0; i < qd.size() && collect; ++i)
        if (estimator_->coordinateNeeded(i) && std::abs(qd[i]) > settings_.still_velocity) {
          std::ostringstream why;
          why << "the robot is not still: the estimated velocity of '"
              << estimator_->model().coordinate_names[static_cast<std::size_t>(i)] << "' is "
              << qd[i] << ", above still_velocity " << settings_.still_velocity;
          c.failure = why.str();
          collect = false;
        }
    }
    for (std::size_t k : sensor_topics_)
      if (collect && !estimator_->sensorUsed(static_cast<int>(k))) {
        c.failure = "sensor '" + wrench_topics_[k]->input.sensor_joint + "' is stale";
        collect = false;
      }
    if (!collect) calibration_cv_.notify_all();
  }
  for (std::size_t k : sensor_topics_) {
    WrenchTopic& topic = *wrench_topics_[k];
    if (!estimator_->sensorUsed(static_cast<int>(k))) continue;
    // Link frame, about the link origin (the joint origin) -> the reading's
    // frame.
    const Wrench<double> r = estimator_->sensorResidual(static_cast<int>(k));
    const Eigen::Matrix3d& R = topic.R_link_sensor;
    const Eigen::Vector3d f = R.transpose() * r.force;
    const Eigen::Vector3d m = R.transpose() * (r.moment - topic.p_link_sensor.cross(r.force));
    topic.max_force = std::max(topic.max_force, f.norm());
    topic.max_moment = std::max(topic.max_moment, m.norm());
    if (topic.consistency_pub.getNumSubscribers() > 0) {
      wrench_msg_.header.stamp = stamp;
      wrench_msg_.header.frame_id =
          topic.sensor_frame.empty() ? topic.input.link : topic.sensor_frame;
      wrench_msg_.wrench.force = tf2::toMsg(f, wrench_msg_.wrench.force);
      wrench_msg_.wrench.torque = tf2::toMsg(m, wrench_msg_.wrench.torque);
      topic.consistency_pub.publish(wrench_msg_);
    }
    if (collect) {
      // reading - bias = sign (residual + prediction), so the reading's offset
      // from sign * prediction is bias + sign * residual.
      Vector6 x;
      x << topic.bias_force + topic.input.sign * f,
          topic.bias_torque + topic.input.sign * m;
      Calibration& c = calibration_;
      const double n = static_cast<double>(c.samples + 1);
      const Vector6 delta = x - c.mean[k];
      c.mean[k] += delta / n;
      c.m2[k] += delta.cwiseProduct(x - c.mean[k]);
    }
  }
  if (collect) {
    Calibration& c = calibration_;
    const double t = estimator_->stamp();
    if (c.samples == 0) c.first_stamp = t;
    ++c.samples;
    c.last_sample = ros::WallTime::now();
    if (t - c.first_stamp >= c.duration) {
      c.done = true;
      calibration_cv_.notify_all();
    }
  }
}

void EstimatorNode::diagnoseConsistency(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::string warnings;
  auto warn = [&](const std::string& w) { warnings += (warnings.empty() ? "" : "; ") + w; };
  char text[256];
  for (std::size_t k : sensor_topics_) {
    WrenchTopic& topic = *wrench_topics_[k];
    const std::string& joint = topic.input.sensor_joint;
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
  calibration_ = Calibration();
  calibration_.active = true;
  calibration_.assume_still = req.assume_still;
  calibration_.duration = req.duration;
  calibration_.last_sample = ros::WallTime::now();
  calibration_.mean.assign(wrench_topics_.size(), Vector6::Zero());
  calibration_.m2.assign(wrench_topics_.size(), Vector6::Zero());
  calibrating_ = true;
  // Loads are computed on the node's own thread; this one only waits for the
  // window.
  while (!calibration_.done && calibration_.failure.empty() && !shutting_down_ && ros::ok()) {
    if ((ros::WallTime::now() - calibration_.last_sample).toSec() > kNoSampleTimeout) {
      calibration_.failure = "no loads were computed for 5 s (no joint states?)";
      break;
    }
    calibration_cv_.wait_for(lock, std::chrono::milliseconds(100));
  }
  calibrating_ = false;
  calibration_.active = false;
  if (!calibration_.done) {
    res.message = calibration_.failure.empty() ? "the node is shutting down" : calibration_.failure;
    res.message += ": no bias changed";
    return true;
  }
  const long n = calibration_.samples;
  std::vector<std::string> frames;
  for (std::size_t k : sensor_topics_) {
    WrenchTopic& topic = *wrench_topics_[k];
    const Vector6& mean = calibration_.mean[k];
    const Vector6 stddev =
        n > 1 ? Vector6((calibration_.m2[k] / static_cast<double>(n - 1)).cwiseSqrt())
              : Vector6::Zero();
    topic.bias_force = mean.head<3>();
    topic.bias_torque = mean.tail<3>();
    frames.push_back(topic.sensor_frame);
    res.sensors.push_back(topic.input.sensor_joint);
    res.bias.push_back(toWrench(mean));
    res.stddev.push_back(toWrench(stddev));
  }
  lock.unlock();
  res.success = true;
  std::ostringstream message;
  message << "bias of " << res.sensors.size() << " sensor(s) estimated from " << n << " samples";
  const std::string error = saveBiasFile(res, n, frames);
  if (settings_.bias_file.empty())
    message << "; not stored (no bias_file)";
  else if (!error.empty())
    message << "; NOT stored: " << error;
  else
    res.file = settings_.bias_file;
  res.message = message.str();
  ROS_INFO("calibrate_bias: %s", res.message.c_str());
  return true;
}

std::string EstimatorNode::saveBiasFile(const joint_load_estimator::CalibrateBias::Response& res,
                                        long samples, const std::vector<std::string>& frames) {
  if (settings_.bias_file.empty()) return "";
  std::ostringstream out;
  out << "# Force/torque sensor offsets written by joint_load_estimator "
         "~calibrate_bias:\n"
         "# the reading minus the model's prediction, averaged while the robot "
         "was still, in\n"
         "# the sensor's frame and sign convention (moment about the frame's "
         "origin). The\n"
         "# node subtracts them from the readings when started with bias_file "
         "= this file.\n"
         "sensors:\n";
  for (std::size_t i = 0; i < res.sensors.size(); ++i) {
    Vector6 b, s;
    b << res.bias[i].force.x, res.bias[i].force.y, res.bias[i].force.z, res.bias[i].torque.x,
        res.bias[i].torque.y, res.bias[i].torque.z;
    s << res.stddev[i].force.x, res.stddev[i].force.y, res.stddev[i].force.z,
        res.stddev[i].torque.x, res.stddev[i].torque.y, res.stddev[i].torque.z;
    out << "  " << res.sensors[i] << ":\n"
        << "    frame: \"" << frames[i] << "\"\n"
        << "    force: " << formatVector(b, 0) << "          # [N]\n"
        << "    torque: " << formatVector(b, 3) << "         # [N m]\n"
        << "    force_stddev: " << formatVector(s, 0) << "   # [N] per-sample spread\n"
        << "    torque_stddev: " << formatVector(s, 3) << "  # [N m]\n"
        << "    samples: " << samples << "\n";
  }
  // Written beside the target and renamed: a reader never sees half a file.
  const std::string tmp = settings_.bias_file + ".tmp";
  {
    std::ofstream file(tmp);
    if (!(file << out.str()) || !file.flush()) return "cannot write '" + tmp + "'";
  }
  if (std::rename(tmp.c_str(), settings_.bias_file.c_str()) != 0)
    return "cannot rename '" + tmp + "' to '" + settings_.bias_file + "'";
  return "";
}

void EstimatorNode::loadBiasFile() {
  const std::string& path = settings_.bias_file;
  if (path.empty()) return;
  if (!std::ifstream(path).good()) {
    ROS_INFO("bias_file '%s' does not exist (yet): sensor biases are zero", path.c_str());
    return;
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw SettingsError("bias_file '" + path + "': " + e.what());
  }
  const YAML::Node sensors = root["sensors"];
  if (!sensors || !sensors.IsMap())
    throw SettingsError("bias_file '" + path + "': 'sensors' must be a map");
  for (const auto& entry : sensors) {
    const std::string name = entry.first.as<std::string>();
    WrenchTopic* topic = nullptr;
    for (std::size_t k : sensor_topics_)
      if (wrench_topics_[k]->input.sensor_joint == name) topic = wrench_topics_[k].get();
    if (!topic) {
      ROS_WARN("bias_file '%s': sensor '%s' is not configured: ignored", path.c_str(),
               name.c_str());
      continue;
    }
    const std::string where = "bias_file '" + path + "': sensors/" + name;
    const Eigen::Vector3d force = readVector(entry.second["force"], where + "/force");
    const Eigen::Vector3d torque = readVector(entry.second["torque"], where + "/torque");
    {
      std::lock_guard<std::mutex> lock(calibration_mutex_);  // a nodelet may already run
      topic->bias_force = force;
      topic->bias_torque = torque;
    }
    const std::string frame = entry.second["frame"] ? entry.second["frame"].as<std::string>() : "";
    if (!topic->settings.frame.empty() && !frame.empty() && frame != topic->settings.frame)
      ROS_WARN("%s: calibrated in frame '%s', configured frame is '%s'", where.c_str(),
               frame.c_str(), topic->settings.frame.c_str());
    ROS_INFO("sensor '%s': bias force [%g %g %g] N, torque [%g %g %g] N m from '%s'", name.c_str(),
             topic->bias_force.x(), topic->bias_force.y(), topic->bias_force.z(),
             topic->bias_torque.x(), topic->bias_torque.y(), topic->bias_torque.z(), path.c_str());
  }
}

}  // namespace jle
