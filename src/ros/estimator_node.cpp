#include <joint_load_estimator/ros/estimator_node.hpp>

#include <joint_load_estimator/ros/message_inputs.hpp>
#include <joint_load_estimator/urdf_reader.hpp>

#include <tf2_eigen/tf2_eigen.h>

#include <cmath>
#include <limits>

namespace jle {
namespace {

constexpr double kThrottle = 2.0;  // [s] between repeats of one error message
constexpr std::size_t kEffortHistory = 128;

bool allFinite(const std::vector<double>& v, std::size_t& bad) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) {
      bad = i;
      return false;
    }
  return true;
}

}  // namespace

EstimatorNode::EstimatorNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), private_nh_(private_nh), tf_listener_(tf_buffer_), updater_(nh, private_nh) {
  XmlRpc::XmlRpcValue params;
  if (!private_nh_.getParam(private_nh_.getNamespace(), params)) params = XmlRpc::XmlRpcValue();
  settings_ = parseSettings(params);

  std::string urdf;
  if (!nh_.getParam(settings_.robot_description, urdf))
    throw SettingsError("parameter '" + nh_.resolveName(settings_.robot_description) +
                        "' (robot_description) is not set or is not a string");
  const ModelOptions options = modelOptions(settings_);
  Model<double> model;
  try {
    model = modelFromUrdfString(urdf, options);
  } catch (const ModelError& e) {
    throw ModelError("robot_description '" + nh_.resolveName(settings_.robot_description) +
                     "': " + e.what());
  }
  for (const std::string& w : model.warnings) ROS_WARN("robot model: %s", w.c_str());
  if (model.floating_base && settings_.base_frame.empty())
    settings_.base_frame = model.link_name[0];
  completeSensorLinks(model, settings_);
  estimator_ = std::make_unique<Estimator>(model, settings_.estimator);

  for (int i = 0; i < model.nq; ++i) coordinate_of_[model.coordinate_names[i]] = i;
  for (int s : model.moving_segments) segment_of_[model.joint_name[s]] = s;
  if (settings_.estimator.joints.empty()) {
    published_segments_ = model.moving_segments;
  } else {
    for (const std::string& j : settings_.estimator.joints) {
      auto it = segment_of_.find(j);
      if (it == segment_of_.end()) {
        // A kept fixed joint is a valid output too.
        try {
          published_segments_.push_back(model.segmentOfJoint(j));
          continue;
        } catch (const std::invalid_argument&) {
        }
        throw SettingsError("parameter 'joints': '" + j + "' is not a joint of the model");
      }
      published_segments_.push_back(it->second);
    }
  }
  q_.assign(static_cast<std::size_t>(model.nq), 0.0);
  q_received_.assign(static_cast<std::size_t>(model.nq), false);
  effort_.assign(published_segments_.size(), std::numeric_limits<double>::quiet_NaN());

  const std::size_t n = published_segments_.size();
  loads_msg_.name.resize(n);
  loads_msg_.wrench.resize(n);
  loads_msg_.effort.resize(n);
  loads_msg_.measured_effort.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    loads_msg_.name[i] = model.joint_name[static_cast<std::size_t>(published_segments_[i])];

  loads_pub_ = private_nh_.advertise<joint_load_estimator::JointLoads>("joint_loads", 100);
  if (settings_.publish_wrench_topics)
    for (std::size_t i = 0; i < n; ++i)
      wrench_pubs_.push_back(
          private_nh_.advertise<geometry_msgs::WrenchStamped>("wrench/" + loads_msg_.name[i], 10));
  if (model.floating_base)
    residual_pub_ = private_nh_.advertise<geometry_msgs::WrenchStamped>("base_residual", 10);

  for (std::size_t k = 0; k < settings_.wrenches.size(); ++k) {
    auto topic = std::make_unique<WrenchTopic>();
    topic->settings = settings_.wrenches[k];
    topic->input = settings_.estimator.wrenches[k];
    if (!estimator_->inputNeeded(static_cast<int>(k))) {
      // Acts below none of the published joints: nothing to subscribe to.
      ROS_INFO("wrench '%s' on link '%s' affects none of the published joints: not subscribed",
               topic->settings.topic.c_str(), topic->input.link.c_str());
      wrench_topics_.push_back(std::move(topic));
      continue;
    }
    topic->subscriber = nh_.subscribe<geometry_msgs::WrenchStamped>(
        topic->settings.topic, 100,
        [this, k](const geometry_msgs::WrenchStamped::ConstPtr& msg) { onWrench(k, msg); },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    wrench_topics_.push_back(std::move(topic));
  }
  setUpPlates();
  joint_sub_ = nh_.subscribe(settings_.joint_states_topic, 100, &EstimatorNode::onJointState,
                             this, ros::TransportHints().tcpNoDelay());

  updater_.setHardwareID(model.link_name[0]);
  updater_.add("joint loads", this, &EstimatorNode::diagnose);

  // Predicted against measured: every sensor's residual, the floating base's.
  for (std::size_t k = 0; k < wrench_topics_.size(); ++k) {
    WrenchTopic& topic = *wrench_topics_[k];
    const std::string& joint = topic.input.sensor_joint;
    if (joint.empty()) continue;
    sensor_topics_.push_back(k);
    topic.consistency_pub = private_nh_.advertise<geometry_msgs::WrenchStamped>("consistency/" + joint, 10);
  }
  total_weight_ = model.totalMass() * settings_.estimator.gravity_world.norm();
  if (!sensor_topics_.empty() || model.floating_base)
    updater_.add("consistency", this, &EstimatorNode::diagnoseConsistency);
  loadBiasFile();
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
  ROS_INFO("joint_load_estimator: %d segments, %d coordinates, %zu joints published, %zu wrench "
           "inputs%s",
           model.nsegments(), model.nq, n, settings_.wrenches.size(),
           model.floating_base ? ", floating base" : "");
}

EstimatorNode::~EstimatorNode() {
  {
    std::lock_guard<std::mutex> lock(calibration_mutex_);
    shutting_down_ = true;
  }
  calibration_cv_.notify_all();
  if (service_spinner_) service_spinner_->stop();
}

double EstimatorNode::relative(const ros::Time& stamp) {
  // The estimator's time axis starts at the first stamp: seconds since 1970 in a double
  // resolve 2.4e-7 s only, too coarse to difference samples 1 ms apart (and the published
  // stamp would not be the joint state's). Kept across resets: a negative time is fine.
  if (time_ref_.isZero()) time_ref_ = stamp;
  return (stamp - time_ref_).toSec();
}

ros::Time EstimatorNode::absolute(double t) const { return time_ref_ + ros::Duration(t); }

bool EstimatorNode::checkTimeJump(const ros::Time& stamp) {
  // A looping bag (rosbag play -l) or a restarted simulation sends time backwards:
  // the filters' memory belongs to another timeline.
  const ros::Time now = ros::Time::now();
  // /clock and the joint states come on different connections, so the clock may go
  // back one message after the stamps did (or before): a clock going back is a jump
  // only while the stamps do not go forward, else one jump would reset twice.
  const bool clock_back = !last_now_.isZero() && now < last_now_ && !(stamp > last_stamp_);
  const bool stamp_back =
      !last_stamp_.isZero() && (last_stamp_ - stamp).toSec() > settings_.time_jump_threshold;
  last_now_ = now;
  if (!clock_back && !stamp_back) return false;
  ROS_WARN("time jumped back (from %.6f to %.6f): resetting the filters", last_stamp_.toSec(),
           stamp.toSec());
  estimator_->reset();
  effort_history_.clear();
  last_stamp_ = ros::Time();
  ++counters_.resets;
  return true;
}

void EstimatorNode::onJointState(const sensor_msgs::JointState::ConstPtr& msg) {
  const ros::Time received = ros::Time::now();
  ++counters_.joint_states;
  try {
    const std::size_t n = msg->name.size();
    if (msg->position.size() != n) {
      ROS_ERROR_THROTTLE(kThrottle, "joint_states: %zu names but %zu positions: message dropped",
                         n, msg->position.size());
      ++counters_.dropped_invalid;
      return;
    }
    if (!msg->velocity.empty() && msg->velocity.size() != n) {
      ROS_ERROR_THROTTLE(kThrottle, "joint_states: %zu names but %zu velocities: message dropped",
                         n, msg->velocity.size());
      ++counters_.dropped_invalid;
      return;
    }
    if (!msg->effort.empty() && msg->effort.size() != n) {
      ROS_ERROR_THROTTLE(kThrottle, "joint_states: %zu names but %zu efforts: message dropped", n,
                         msg->effort.size());
      ++counters_.dropped_invalid;
      return;
    }
    std::size_t bad = 0;
    for (const auto* field : {&msg->position, &msg->velocity, &msg->effort}) {
      if (!allFinite(*field, bad)) {
        const char* name = field == &msg->position   ? "position"
                           : field == &msg->velocity ? "velocity"
                                                     : "effort";
        ROS_ERROR_THROTTLE(kThrottle, "joint_states: %s of joint '%s' is %f: message dropped",
                           name, msg->name[bad].c_str(), (*field)[bad]);
        ++counters_.dropped_invalid;
        return;
      }
    }
    ros::Time stamp = msg->header.stamp;
    if (stamp.isZero()) stamp = received;
    checkTimeJump(stamp);

    bool unknown = false;
    for (std::size_t i = 0; i < n; ++i) {
      auto it = coordinate_of_.find(msg->name[i]);
      if (it == coordinate_of_.end()) {
        if (!segment_of_.count(msg->name[i])) {  // a mimic joint's value is not needed
          ROS_WARN_THROTTLE(kThrottle, "joint_states: joint '%s' is not in the model: ignored",
                            msg->name[i].c_str());
          unknown = true;
        }
        continue;
      }
      q_[static_cast<std::size_t>(it->second)] = msg->position[i];
      q_received_[static_cast<std::size_t>(it->second)] = true;
    }
    if (unknown) ++counters_.unknown_joints;
    if (!msg->effort.empty()) {
      for (std::size_t j = 0; j < published_segments_.size(); ++j)
        for (std::size_t i = 0; i < n; ++i)
          if (msg->name[i] == loads_msg_.name[j]) effort_[j] = msg->effort[i];
      effort_history_.emplace_back(relative(stamp), effort_);
      if (effort_history_.size() > kEffortHistory) effort_history_.pop_front();
    }
    for (std::size_t i = 0; i < q_.size(); ++i) {
      if (!q_received_[i] && estimator_->coordinateNeeded(static_cast<int>(i))) {
        ROS_ERROR_THROTTLE(kThrottle,
                           "joint_states: no position received yet for joint '%s': not "
                           "publishing",
                           estimator_->model().coordinate_names[i].c_str());
        return;
      }
    }

    BasePose base;
    if (estimator_->model().floating_base) {
      geometry_msgs::TransformStamped tf;
      try {
        tf = tf_buffer_.lookupTransform(settings_.world_frame, settings_.base_frame, stamp);
      } catch (const tf2::TransformException& e) {
        ROS_WARN_THROTTLE(kThrottle, "floating base: no pose of '%s' in '%s' at %.6f: %s",
                          settings_.base_frame.c_str(), settings_.world_frame.c_str(),
                          stamp.toSec(), e.what());
        ++counters_.dropped_frame;
        return;
      }
      base.position = tf2::transformToEigen(tf).translation();
      tf2::fromMsg(tf.transform.rotation, base.orientation);
    }

    const SampleStatus status = estimator_->addJointSample(relative(stamp), q_.data(), &base);
    switch (status) {
      case SampleStatus::kPublished:
        if (!estimator_->lastWasReused() || settings_.estimator.savings.republish_unchanged)
          publish(received);
        break;
      case SampleStatus::kDuplicate:
      case SampleStatus::kOutOfOrder:
        ++counters_.dropped_order;
        ROS_WARN_THROTTLE(kThrottle, "joint_states: %s %.9f (previous %.9f): message dropped",
                          toString(status), stamp.toSec(), last_stamp_.toSec());
        return;
      case SampleStatus::kNonFinite:
        ++counters_.dropped_invalid;
        ROS_ERROR_THROTTLE(kThrottle, "joint_states: non-finite stamp or base pose: dropped");
        return;
      case SampleStatus::kStale:
        ++counters_.stale;
        for (std::size_t k = 0; k < wrench_topics_.size(); ++k)
          if (estimator_->stale(static_cast<int>(k)))
            ROS_WARN_THROTTLE(kThrottle, "wrench input '%s' is stale: not publishing",
                              wrench_topics_[k]->settings.topic.c_str());
        for (std::size_t k = 0; k < plate_topics_.size(); ++k)
          if (estimator_->plateStale(static_cast<int>(k)))
            ROS_WARN_THROTTLE(kThrottle, "force plate '%s' is stale: not publishing",
                              plate_topics_[k]->settings.topic.c_str());
        break;
      default: break;
    }
    last_stamp_ = stamp;
  } catch (const std::exception& e) {
    // Nothing may leave a callback; the next message is processed as usual.
    ++counters_.dropped_invalid;
    ROS_ERROR_THROTTLE(kThrottle, "joint_states: %s", e.what());
  }
}

bool EstimatorNode::resolveFrame(WrenchTopic& topic, const std::string& frame,
                                 const ros::Time& stamp, Eigen::Matrix3d& R, Eigen::Vector3d& p) {
  const Model<double>& model = estimator_->model();
  const std::string& link = topic.input.link;
  if (frame == topic.last_frame && topic.rigid) {
    R = topic.R_link_frame;
    p = topic.p_link_frame;
    return true;
  }
  // A URDF frame on the same segment as the link: a constant transform from the model.
  if (rigidFrameInLink(model, link, frame, topic.R_link_frame, topic.p_link_frame)) {
    topic.rigid = true;
    topic.last_frame = frame;
    R = topic.R_link_frame;
    p = topic.p_link_frame;
    return true;
  }
  topic.rigid = false;
  topic.last_frame = frame;
  try {
    const geometry_msgs::TransformStamped tf =
        tf_buffer_.lookupTransform(link, frame, stamp, ros::Duration(0.0));
    const Eigen::Isometry3d X = tf2::transformToEigen(tf);
    R = X.rotation();
    p = X.translation();
    return true;
  } catch (const tf2::TransformException& e) {
    ROS_ERROR_THROTTLE(kThrottle, "wrench '%s': frame '%s' is neither a URDF link nor known to "
                       "tf2 relative to '%s': %s",
                       topic.settings.topic.c_str(), frame.c_str(), link.c_str(), e.what());
    return false;
  }
}

void EstimatorNode::onWrench(std::size_t k, const geometry_msgs::WrenchStamped::ConstPtr& msg) {
  ++counters_.wrenches;
  try {
    WrenchTopic& topic = *wrench_topics_[k];
    Eigen::Vector3d f, m;
    tf2::fromMsg(msg->wrench.force, f);
    tf2::fromMsg(msg->wrench.torque, m);
    if (!f.allFinite() || !m.allFinite()) {
      ROS_ERROR_THROTTLE(kThrottle, "wrench '%s': non-finite force or torque: dropped",
                         topic.settings.topic.c_str());
      ++counters_.dropped_invalid;
      return;
    }
    const std::string& frame =
        topic.settings.frame.empty() ? msg->header.frame_id : topic.settings.frame;
    if (frame.empty()) {
      ROS_ERROR_THROTTLE(kThrottle, "wrench '%s': empty header.frame_id and no 'frame' "
                         "configured: dropped", topic.settings.topic.c_str());
      ++counters_.dropped_frame;
      return;
    }
    const ros::Time stamp = msg->header.stamp.isZero() ? ros::Time::now() : msg->header.stamp;
    // A looping bag may deliver the new loop's first wrench before its first joint
    // state: the jump is detected here too, so that wrench is not refused as old.
    checkTimeJump(stamp);
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    if (!resolveFrame(topic, frame, stamp, R, p)) {
      ++counters_.dropped_frame;
      return;
    }
    if (!topic.input.sensor_joint.empty()) {
      // The sensor's offset, as it reports; the residual goes out in the reading's frame.
      {
        std::lock_guard<std::mutex> lock(calibration_mutex_);
        f -= topic.bias_force;
        m -= topic.bias_torque;
        topic.sensor_frame = frame;
      }
      topic.R_link_sensor = R;
      topic.p_link_sensor = p;
    }
    // Expressed in the link frame, moment about the link origin.
    Eigen::Vector3d f_link, m_link;
    wrenchInLink(R, p, f, m, f_link, m_link);
    if (!estimator_->addWrench(static_cast<int>(k), relative(stamp), f_link, m_link)) {
      ++counters_.dropped_order;
      ROS_WARN_THROTTLE(kThrottle, "wrench '%s': stamp %.9f not newer than the last: dropped",
                        topic.settings.topic.c_str(), stamp.toSec());
    }
  } catch (const std::exception& e) {
    ++counters_.dropped_invalid;
    ROS_ERROR_THROTTLE(kThrottle, "wrench input %zu: %s", k, e.what());
  }
}

void EstimatorNode::publish(const ros::Time& received) {
  const Data<double>& data = estimator_->data();
  const ros::Time stamp = absolute(estimator_->stamp());
  // The measured efforts that belong to the stamp the estimate describes.
  const std::vector<double>* measured = nullptr;
  for (auto it = effort_history_.rbegin(); it != effort_history_.rend(); ++it)
    if (it->first == estimator_->stamp()) {
      measured = &it->second;
      break;
    }
  loads_msg_.header.stamp = stamp;
  for (std::size_t i = 0; i < published_segments_.size(); ++i) {
    const std::size_t s = static_cast<std::size_t>(published_segments_[i]);
    geometry_msgs::Wrench& w = loads_msg_.wrench[i];
    w.force.x = data.force[s].x();
    w.force.y = data.force[s].y();
    w.force.z = data.force[s].z();
    w.torque.x = data.moment[s].x();
    w.torque.y = data.moment[s].y();
    w.torque.z = data.moment[s].z();
    loads_msg_.effort[i] = data.effort[s];
    loads_msg_.measured_effort[i] =
        measured ? (*measured)[i] : std::numeric_limits<double>::quiet_NaN();
    if (!wrench_pubs_.empty() && wrench_pubs_[i].getNumSubscribers() > 0) {
      wrench_msg_.header.stamp = stamp;
      wrench_msg_.header.frame_id = estimator_->model().link_name[s];
      wrench_msg_.wrench = w;
      wrench_pubs_[i].publish(wrench_msg_);
    }
  }
  if (settings_.estimator.uncertainty.enabled) {
    // Sized on first use, then reused (no allocation per message).
    const bool diagonal = settings_.estimator.uncertainty.diagonal_only;
    const std::size_t per_joint = diagonal ? 6 : 36;
    loads_msg_.covariance.resize(per_joint * published_segments_.size());
    loads_msg_.effort_stddev.resize(published_segments_.size());
    for (std::size_t i = 0; i < published_segments_.size(); ++i) {
      const Eigen::Matrix<double, 6, 6>& C = estimator_->covariance(published_segments_[i]);
      double* out = &loads_msg_.covariance[per_joint * i];
      for (int r = 0; r < 6; ++r)
        if (diagonal)
          out[r] = C(r, r);
        else
          for (int c = 0; c < 6; ++c) out[6 * r + c] = C(r, c);
      loads_msg_.effort_stddev[i] = std::sqrt(estimator_->effortVariance(published_segments_[i]));
    }
  }
  for (std::size_t i = 0; i < loads_msg_.effort_per_kg.size(); ++i)
    loads_msg_.effort_per_kg[i] = loads_msg_.effort[i] / body_mass_;
  publishPlates(stamp);
  loads_pub_.publish(loads_msg_);
  if (residual_pub_ && residual_pub_.getNumSubscribers() > 0) {
    wrench_msg_.header.stamp = stamp;
    wrench_msg_.header.frame_id = estimator_->model().link_name[0];
    wrench_msg_.wrench.force = tf2::toMsg(data.force[0], wrench_msg_.wrench.force);
    wrench_msg_.wrench.torque = tf2::toMsg(data.moment[0], wrench_msg_.wrench.torque);
    residual_pub_.publish(wrench_msg_);
  }
  publishConsistency(stamp);
  ++counters_.published;
  const double latency = (ros::Time::now() - received).toSec();
  latency_sum_ += latency;
  latency_max_ = std::max(latency_max_, latency);
  ++latency_count_;
  updater_.update();
}

void EstimatorNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const ros::WallTime now = ros::WallTime::now();
  const double dt = (now - last_diag_).toSec();
  const double in_rate = dt > 0 ? (counters_.joint_states - received_at_last_diag_) / dt : 0.0;
  const double out_rate = dt > 0 ? (counters_.published - published_at_last_diag_) / dt : 0.0;
  last_diag_ = now;
  received_at_last_diag_ = counters_.joint_states;
  published_at_last_diag_ = counters_.published;
  std::string stale;
  for (std::size_t k = 0; k < wrench_topics_.size(); ++k)
    if (estimator_->stale(static_cast<int>(k)))
      stale += (stale.empty() ? "" : ", ") + wrench_topics_[k]->settings.topic;
  for (std::size_t k = 0; k < plate_topics_.size(); ++k)
    if (estimator_->plateStale(static_cast<int>(k)))
      stale += (stale.empty() ? "" : ", ") + plate_topics_[k]->settings.topic;
  if (counters_.published == 0)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no loads published yet");
  else if (!stale.empty())
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "stale wrench inputs: " + stale);
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "publishing");
  status.add("input rate [Hz]", in_rate);
  status.add("output rate [Hz]", out_rate);
  status.add("mean latency [s]", latency_count_ ? latency_sum_ / latency_count_ : 0.0);
  status.add("max latency [s]", latency_max_);
  status.add("joint states received", counters_.joint_states);
  status.add("wrenches received", counters_.wrenches);
  status.add("loads published", counters_.published);
  status.add("dropped: invalid", counters_.dropped_invalid);
  status.add("dropped: stamp order", counters_.dropped_order);
  status.add("dropped: unresolved frame", counters_.dropped_frame);
  status.add("messages with unknown joints", counters_.unknown_joints);
  status.add("not published: stale input", counters_.stale);
  status.add("time jumps back", counters_.resets);
  status.add("force plate samples received", counters_.plate_samples);
  status.add("stale inputs", stale);
  latency_sum_ = 0.0;
  latency_max_ = 0.0;
  latency_count_ = 0;
}

// ---------------------------------------------------------------------------------
// Force plates and the mass-normalised efforts.

void EstimatorNode::setUpPlates() {
  const Model<double>& model = estimator_->model();
  if (settings_.body_mass != 0.0) {
    body_mass_ = settings_.body_mass > 0.0 ? settings_.body_mass : model.totalMass();
    if (!(body_mass_ > 0.0))
      throw SettingsError("parameter 'body_mass' is -1 but the URDF's total mass is " +
                          std::to_string(body_mass_) + " kg");
    loads_msg_.effort_per_kg.resize(loads_msg_.effort.size());
  }
  for (std::size_t k = 0; k < settings_.force_plates.size(); ++k) {
    auto plate = std::make_unique<PlateTopic>();
    plate->settings = settings_.force_plates[k];
    plate->input = settings_.estimator.plates[k];
    const std::string& name = plate->input.plate.name;
    plate->cop_pub = private_nh_.advertise<geometry_msgs::PointStamped>("cop/" + name, 10);
    if (!estimator_->plateNeeded(static_cast<int>(k))) {
      ROS_INFO("force plate '%s' under link '%s' affects none of the published joints: not "
               "subscribed", name.c_str(), plate->input.plate.link.c_str());
      plate_topics_.push_back(std::move(plate));
      continue;
    }
    plate->subscriber = nh_.subscribe<geometry_msgs::WrenchStamped>(
        plate->settings.topic, 100,
        [this, k](const geometry_msgs::WrenchStamped::ConstPtr& msg) { onPlate(k, msg); },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    plate_topics_.push_back(std::move(plate));
  }
}

bool EstimatorNode::resolvePlatePose(PlateTopic& plate, const std::string& frame) {
  if (plate.pose_known && frame == plate.frame) return true;
  if (plate.settings.pose_configured) {  // the estimator holds the configured pose
    plate.frame = frame;
    plate.pose_known = true;
    return true;
  }
  // A lab plate is fixed in the world: looked up until found, then kept. The estimator's
  // world is world_frame for a floating base, the URDF root link for a fixed one.
  const Model<double>& model = estimator_->model();
  const std::string& world = model.floating_base ? settings_.world_frame : model.link_name[0];
  try {
    const geometry_msgs::TransformStamped tf =
        tf_buffer_.lookupTransform(world, frame, ros::Time(0));
    const Eigen::Isometry3d X = tf2::transformToEigen(tf);
    for (std::size_t k = 0; k < plate_topics_.size(); ++k)
      if (plate_topics_[k].get() == &plate)
        estimator_->setPlatePose(static_cast<int>(k), X.rotation(), X.translation());
    plate.frame = frame;
    plate.pose_known = true;
    return true;
  } catch (const tf2::TransformException& e) {
    ROS_WARN_THROTTLE(kThrottle, "force plate '%s': no pose of frame '%s' in '%s' from tf2 (and "
                      "no position/orientation configured): %s",
                      plate.input.plate.name.c_str(), frame.c_str(), world.c_str(),
                      e.what());
    return false;
  }
}

void EstimatorNode::onPlate(std::size_t k, const geometry_msgs::WrenchStamped::ConstPtr& msg) {
  ++counters_.plate_samples;
  try {
    PlateTopic& plate = *plate_topics_[k];
    const std::string& name = plate.input.plate.name;
    Eigen::Vector3d f, m;
    tf2::fromMsg(msg->wrench.force, f);
    tf2::fromMsg(msg->wrench.torque, m);
    if (!f.allFinite() || !m.allFinite()) {
      ROS_ERROR_THROTTLE(kThrottle, "force plate '%s': non-finite force or torque: dropped",
                         name.c_str());
      ++counters_.dropped_invalid;
      return;
    }
    const std::string& frame =
        plate.settings.frame.empty() ? msg->header.frame_id : plate.settings.frame;
    if (frame.empty() && !plate.settings.pose_configured) {
      ROS_ERROR_THROTTLE(kThrottle, "force plate '%s': empty header.frame_id and no 'frame' "
                         "configured: dropped", name.c_str());
      ++counters_.dropped_frame;
      return;
    }
    const ros::Time stamp = msg->header.stamp.isZero() ? ros::Time::now() : msg->header.stamp;
    checkTimeJump(stamp);  // as for wrenches: a looping bag
    if (!resolvePlatePose(plate, frame)) {
      ++counters_.dropped_frame;
      return;
    }
    if (!estimator_->addPlateSample(static_cast<int>(k), relative(stamp), f, m)) {
      ++counters_.dropped_order;
      ROS_WARN_THROTTLE(kThrottle, "force plate '%s': stamp %.9f not newer than the last: dropped",
                        name.c_str(), stamp.toSec());
    }
  } catch (const std::exception& e) {
    ++counters_.dropped_invalid;
    ROS_ERROR_THROTTLE(kThrottle, "force plate input %zu: %s", k, e.what());
  }
}

void EstimatorNode::publishPlates(const ros::Time& stamp) {
  for (std::size_t k = 0; k < plate_topics_.size(); ++k) {
    const PlateReading& r = estimator_->plateReading(static_cast<int>(k));
    if (!r.contact) continue;
    const PlateTopic& plate = *plate_topics_[k];
    cop_msg_.header.stamp = stamp;
    cop_msg_.header.frame_id = plate.frame;
    cop_msg_.point.x = r.cop_plate.x();
    cop_msg_.point.y = r.cop_plate.y();
    cop_msg_.point.z = r.cop_plate.z();
    plate.cop_pub.publish(cop_msg_);
  }
}

}  // namespace jle
