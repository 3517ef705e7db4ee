#include <joint_load_estimator/ros/estimator_node.hpp>

#include <joint_load_estimator/model/urdf_reader.hpp>

#include <tf2_eigen/tf2_eigen.h>

#include <cstdio>

namespace jle {
namespace {

constexpr double kThrottle = 2.0;  // [s] between repeats of one kind of message

// The master's /run_id (roslaunch and roscore set it, new at every start), or empty.
std::string masterRunId() {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = "/run_id";
  if (!ros::master::execute("getParam", args, result, payload, false)) return {};
  return payload.getType() == XmlRpc::XmlRpcValue::TypeString ? std::string(payload) : "";
}
// [s] without a joint state: the loads have stopped (an ERROR in the diagnostics).
constexpr double kSilence = 1.0;
// ~joint_loads messages kept for reuse; beyond them, a message still held by a
// subscriber (in a queue of the same process or of TCP) is replaced by a new one.
constexpr std::size_t kLoadsPool = 8;

// Under use_sim_time, ros::Time::now() is 0 until the first /clock message: a stamp 0
// cannot be replaced by the clock (every one reads as a duplicate of the last), and a
// jump of time the clock shows is not seen. Said by wall time: ROS_*_THROTTLE counts by
// ros::Time, which stands still at 0.
const char* const kNoClock =
    "use_sim_time is true but no /clock message has come (ros::Time::now() is 0): a joint "
    "state stamped 0 cannot take the clock's time and jumps of time go unseen; publish "
    "/clock (rosbag play --clock) or set use_sim_time false";

bool noClock() { return ros::Time::isSimTime() && ros::Time::now().isZero(); }

}  // namespace

EstimatorNode::EstimatorNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh),
      private_nh_(private_nh),
      tf_listener_(tf_buffer_),
      frames_(tf_buffer_),
      updater_(nh, private_nh) {
  // ~reconfigure/* belong to the server of the last run: it starts from these settings.
  private_nh_.deleteParam("reconfigure");
  if (!private_nh_.getParam(private_nh_.getNamespace(), params_)) params_ = XmlRpc::XmlRpcValue();
  settings_ = parseSettings(params_);
  frames_.setWait(settings_.tf_wait);
  const Model<double> model = loadModel();
  pipeline_ = std::make_unique<Pipeline>(model, settings_, &frames_);
  settings_ = pipeline_->settings();  // with the sensors' links and the base frame filled in
  prepare(pipeline_->record(), loads_msg_);
  prepare(pipeline_->record(), efforts_msg_);
  if (pipeline_->hasSmoothed()) {
    prepare(pipeline_->smoothedRecord(), smoothed_.loads_msg);
    prepare(pipeline_->smoothedRecord(), smoothed_.efforts_msg);
  }
  advertise();
  setUpConsistency();
  applyBiasFile(*pipeline_);  // before the first wrench can arrive
  subscribe();
  setUpReconfigure();
  updater_.setHardwareID(model.link_name[0]);
  updater_.add("joint loads", this, &EstimatorNode::diagnose);
  if (!sensor_topics_.empty() || model.floating_base)
    updater_.add("consistency", this, &EstimatorNode::diagnoseConsistency);
  master_watch_ = std::make_unique<MasterWatch>(masterRunId());
  diagnostics_timer_ = nh_.createWallTimer(ros::WallDuration(settings_.diagnostic_period),
                                           &EstimatorNode::onDiagnosticsTimer, this);
  ROS_INFO(
      "joint_load_estimator: %d segments, %d coordinates, %zu joints published, %zu wrench "
      "inputs%s",
      model.nsegments(), model.nq, pipeline_->record().joint.size(), settings_.wrenches.size(),
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

std::string resolveParameter(const ros::NodeHandle& nh, const std::string& name) {
  try {
    return nh.resolveName(name);
  } catch (const ros::InvalidNameException& e) {
    throw SettingsError("parameter '~robot_description' is '" + name.substr(0, 80) +
                        "': neither the name of the parameter holding the URDF nor a URDF (" +
                        e.what() + ")");
  }
}

Model<double> EstimatorNode::loadModel() {
  std::string urdf = settings_.robot_description;
  std::string param = private_nh_.resolveName("robot_description") + " (the URDF itself)";
  if (!isUrdfText(urdf)) {
    param = resolveParameter(nh_, settings_.robot_description);
    if (!nh_.getParam(settings_.robot_description, urdf))
      throw SettingsError("parameter '" + param +
                          "' (robot_description) is not set or is not a string");
  }
  try {
    Model<double> model = modelFromUrdfString(urdf, modelOptions(settings_));
    for (const std::string& w : model.warnings) ROS_WARN("robot model: %s", w.c_str());
    return model;
  } catch (const ModelError& e) {
    throw ModelError("robot_description '" + param + "': " + e.what());
  }
}

void EstimatorNode::advertise() {
  const LoadsRecord& record = pipeline_->record();
  loads_pub_ = private_nh_.advertise<joint_load_estimator::JointLoads>("joint_loads", 100);
  efforts_pub_ = private_nh_.advertise<sensor_msgs::JointState>("joint_efforts", 100);
  if (settings_.publish_wrench_topics)
    for (const std::string& joint : record.joint)
      wrench_pubs_.push_back(
          private_nh_.advertise<geometry_msgs::WrenchStamped>("wrench/" + joint, 10));
  if (pipeline_->model().floating_base)
    residual_pub_ = private_nh_.advertise<geometry_msgs::WrenchStamped>("base_residual", 10);
  external_outputs_.advertise(private_nh_, record);
  if (pipeline_->hasSmoothed()) {
    smoothed_.loads_pub =
        private_nh_.advertise<joint_load_estimator::JointLoads>("smoothed/joint_loads", 100);
    smoothed_.efforts_pub =
        private_nh_.advertise<sensor_msgs::JointState>("smoothed/joint_efforts", 100);
    if (settings_.publish_wrench_topics)
      for (const std::string& joint : record.joint)
        smoothed_.wrench_pubs.push_back(
            private_nh_.advertise<geometry_msgs::WrenchStamped>("smoothed/wrench/" + joint, 10));
  }
  wrench_topics_.resize(settings_.wrenches.size());
  plate_topics_.resize(settings_.force_plates.size());
  for (std::size_t k = 0; k < plate_topics_.size(); ++k)
    plate_topics_[k].cop_pub = private_nh_.advertise<geometry_msgs::PointStamped>(
        "cop/" + settings_.estimator.plates[k].plate.name, 10);
}

template <class Event>
ros::Subscriber EstimatorNode::subscribeInput(const std::string& topic,
                                              const boost::function<void(const Event&)>& callback) {
  ros::SubscribeOptions options;
  options.initByFullCallbackType<const Event&>(topic, 100, callback);
  options.transport_hints = ros::TransportHints().tcpNoDelay();
  if (settings_.inline_callbacks) {
    options.callback_queue = &inline_queue_;
    options.allow_concurrent_callbacks = true;  // serialised by callbacks_mutex_ instead
  }
  return nh_.subscribe(options);
}

void EstimatorNode::subscribe() {
  joint_health_ = InputHealth(nh_.resolveName(settings_.joint_states_topic));
  for (std::size_t k = 0; k < wrench_topics_.size(); ++k) {
    const std::string& topic = settings_.wrenches[k].topic;
    wrench_topics_[k].health = InputHealth(topic);
    if (!pipeline_->inputNeeded(static_cast<int>(k))) {  // nothing to subscribe to
      ROS_INFO("wrench '%s' on link '%s' affects none of the published joints: not subscribed",
               topic.c_str(), settings_.estimator.wrenches[k].link.c_str());
      continue;
    }
    wrench_topics_[k].subscriber = subscribeInput<WrenchEvent>(
        topic, [this, k](const WrenchEvent& event) { onWrench(k, event); });
  }
  for (std::size_t k = 0; k < plate_topics_.size(); ++k) {
    plate_topics_[k].health = InputHealth(settings_.force_plates[k].topic);
    if (!pipeline_->plateNeeded(static_cast<int>(k))) {
      ROS_INFO(
          "force plate '%s' under link '%s' affects none of the published joints: not "
          "subscribed",
          settings_.estimator.plates[k].plate.name.c_str(),
          settings_.estimator.plates[k].plate.link.c_str());
      continue;
    }
    plate_topics_[k].subscriber =
        subscribeInput<WrenchEvent>(settings_.force_plates[k].topic,
                                    [this, k](const WrenchEvent& event) { onPlate(k, event); });
  }
  joint_sub_ = subscribeInput<JointStateEvent>(
      settings_.joint_states_topic, [this](const JointStateEvent& event) { onJointState(event); });
}

void EstimatorNode::report(Outcome outcome) {
  if (pipeline_->jumped())
    ROS_WARN("time jumped %s (from %.6f to %.6f): resetting the filters",
             pipeline_->jumpedForward() ? "forward" : "back",
             toRosTime(pipeline_->jumpFrom()).toSec(), toRosTime(pipeline_->jumpTo()).toSec());
  if (!pipeline_->unknownJoint().empty())
    ROS_WARN_THROTTLE(kThrottle, "%s: joint '%s' is not in the model: ignored",
                      settings_.joint_states_topic.c_str(), pipeline_->unknownJoint().c_str());
  if (!pipeline_->nonFiniteEffort().empty())
    ROS_WARN_THROTTLE(kThrottle, "%s: effort of joint '%s' is not finite: not compared",
                      settings_.joint_states_topic.c_str(), pipeline_->nonFiniteEffort().c_str());
  if (!pipeline_->nonFiniteVelocity().empty())
    ROS_WARN_THROTTLE(kThrottle,
                      "%s: velocity of joint '%s' is not finite: that velocity is not used "
                      "(the velocity filter's prediction instead)",
                      settings_.joint_states_topic.c_str(), pipeline_->nonFiniteVelocity().c_str());
  if (!pipeline_->mimicContradiction().empty())
    ROS_WARN_THROTTLE(kThrottle, "%s: %s", settings_.joint_states_topic.c_str(),
                      pipeline_->mimicContradiction().c_str());
  // A gripper's own joint states are normal: said once, counted in the diagnostics.
  if (outcome == Outcome::kNoJoint) {
    ROS_INFO_ONCE("%s (counted under 'not used: no needed joint')", pipeline_->problem().c_str());
    return;
  }
  if (pipeline_->problem().empty()) return;
  if (last_log_.size() > 1024) last_log_.clear();  // bounded: names come from the inputs
  double& last = last_log_[problemKey(pipeline_->problem())];
  const double now = ros::WallTime::now().toSec();
  if (last != 0.0 && now - last < kThrottle) return;
  last = now;
  // What no later message repairs is an error; order, staleness, a missing pose are not.
  if (outcome == Outcome::kInvalid || outcome == Outcome::kWaiting || outcome == Outcome::kFrame ||
      outcome == Outcome::kNonFinite)
    ROS_ERROR("%s", pipeline_->problem().c_str());
  else
    ROS_WARN("%s", pipeline_->problem().c_str());
}

void EstimatorNode::onJointState(const JointStateEvent& event) {
  std::lock_guard<std::mutex> lock(callbacks_mutex_);
  if (settings_.inline_callbacks && event.getPublisherName() != ros::this_node::getName()) {
    // From another process: this runs in roscpp's network thread, inside the
    // subscription's lock; publishing the loads from here could deadlock with an
    // in-process publisher (which holds roscpp's publication lock while it delivers).
    ++exceptions_;
    ROS_ERROR_THROTTLE(kThrottle,
                       "joint_states from '%s' (another process): with inline_callbacks only "
                       "publishers in the same nodelet manager are taken (dropped; set "
                       "inline_callbacks: false)",
                       event.getPublisherName().c_str());
    return;
  }
  const ros::Time received = ros::Time::now();
  const double queue_wait = (received - event.getReceiptTime()).toSec();
  queue_wait_sum_ += queue_wait;
  queue_wait_max_ = std::max(queue_wait_max_, queue_wait);
  ++queue_wait_count_;
  const sensor_msgs::JointState& msg = *event.getConstMessage();
  if (received.isZero() && ros::Time::isSimTime()) {
    static double said = 0.0;  // wall time [s]; callbacks are serialized (callbacks_mutex_)
    const double wall = ros::WallTime::now().toSec();
    if (wall - said >= kThrottle) {
      said = wall;
      ROS_WARN("%s", kNoClock);
    }
  }
  try {
    applyPendingBias();
    const Outcome outcome = feed(*pipeline_, msg, received);
    last_joint_outcome_ = outcome;
    joint_health_.take(event.getPublisherName(), msg.header.seq, outcome,
                       ros::WallTime::now().toSec());
    report(outcome);
    if (outcome == Outcome::kPublished) publish(received);
    publishDrained(received);
  } catch (const std::exception& e) {
    // Nothing may leave a callback; the next message is processed as usual.
    ++exceptions_;
    ROS_ERROR_THROTTLE(kThrottle, "joint_states: %s", e.what());
  }
}

void EstimatorNode::onWrench(std::size_t k, const WrenchEvent& event) {
  std::lock_guard<std::mutex> lock(callbacks_mutex_);
  const geometry_msgs::WrenchStamped& msg = *event.getConstMessage();
  try {
    applyPendingBias();
    const ros::Time received = ros::Time::now();
    const Outcome outcome = feedWrench(*pipeline_, static_cast<int>(k), msg, received);
    wrench_topics_[k].health.take(event.getPublisherName(), msg.header.seq, outcome,
                                  ros::WallTime::now().toSec());
    report(outcome);
    publishDrained(received);
  } catch (const std::exception& e) {
    ++exceptions_;
    ROS_ERROR_THROTTLE(kThrottle, "wrench input %zu: %s", k, e.what());
  }
}

void EstimatorNode::onPlate(std::size_t k, const WrenchEvent& event) {
  std::lock_guard<std::mutex> lock(callbacks_mutex_);
  const geometry_msgs::WrenchStamped& msg = *event.getConstMessage();
  try {
    const ros::Time received = ros::Time::now();
    const Outcome outcome = feedPlate(*pipeline_, static_cast<int>(k), msg, received);
    plate_topics_[k].health.take(event.getPublisherName(), msg.header.seq, outcome,
                                 ros::WallTime::now().toSec());
    report(outcome);
    publishDrained(received);
  } catch (const std::exception& e) {
    ++exceptions_;
    ROS_ERROR_THROTTLE(kThrottle, "force plate input %zu: %s", k, e.what());
  }
}

joint_load_estimator::JointLoadsPtr EstimatorNode::freeLoadsMessage() {
  // use_count() 1: only the pool holds it, and only this thread hands it out.
  for (const joint_load_estimator::JointLoadsPtr& msg : loads_pool_)
    if (msg.use_count() == 1) return msg;
  auto msg = boost::make_shared<joint_load_estimator::JointLoads>(loads_msg_);
  if (loads_pool_.size() < kLoadsPool) loads_pool_.push_back(msg);
  return msg;
}

void EstimatorNode::publish(const ros::Time& received) {
  const LoadsRecord& record = pipeline_->record();
  const joint_load_estimator::JointLoadsPtr loads = freeLoadsMessage();
  toMessage(record, *loads);
  for (std::size_t i = 0; i < wrench_pubs_.size(); ++i)
    if (wrench_pubs_[i].getNumSubscribers() > 0) {
      toWrenchMessage(record, i, wrench_msg_);
      wrench_pubs_[i].publish(wrench_msg_);
    }
  const ros::Time stamp = loads->header.stamp;
  publishPlates(record, stamp);
  loads_pub_.publish(joint_load_estimator::JointLoadsConstPtr(loads));
  if (efforts_pub_.getNumSubscribers() > 0) {
    toJointState(record, efforts_msg_);
    efforts_pub_.publish(efforts_msg_);
  }
  if (residual_pub_ && residual_pub_.getNumSubscribers() > 0) {
    wrench_msg_.header.stamp = stamp;
    wrench_msg_.header.frame_id = pipeline_->model().link_name[0];
    tf2::toMsg(record.base_force, wrench_msg_.wrench.force);
    tf2::toMsg(record.base_moment, wrench_msg_.wrench.torque);
    residual_pub_.publish(wrench_msg_);
  }
  publishConsistency(record, stamp);
  external_outputs_.publish(record);
  const double latency = (ros::Time::now() - received).toSec();
  latency_sum_ += latency;
  latency_max_ = std::max(latency_max_, latency);
  ++latency_count_;
}

void EstimatorNode::publishDrained(const ros::Time& received) {
  // A smoother's loads still to come when time jumped back or the filter was replaced.
  while (pipeline_->takeDrained()) publish(received);
  if (!pipeline_->hasSmoothed()) return;
  if (pipeline_->smoothedPublished()) publishSmoothed();
  while (pipeline_->takeDrainedSmoothed()) publishSmoothed();
}

void EstimatorNode::publishSmoothed() {
  const LoadsRecord& record = pipeline_->smoothedRecord();
  toMessage(record, smoothed_.loads_msg);
  smoothed_.loads_pub.publish(smoothed_.loads_msg);
  if (smoothed_.efforts_pub.getNumSubscribers() > 0) {
    toJointState(record, smoothed_.efforts_msg);
    smoothed_.efforts_pub.publish(smoothed_.efforts_msg);
  }
  for (std::size_t i = 0; i < smoothed_.wrench_pubs.size(); ++i)
    if (smoothed_.wrench_pubs[i].getNumSubscribers() > 0) {
      toWrenchMessage(record, i, wrench_msg_);
      smoothed_.wrench_pubs[i].publish(wrench_msg_);
    }
}

void EstimatorNode::publishPlates(const LoadsRecord& record, const ros::Time& stamp) {
  for (std::size_t k = 0; k < plate_topics_.size(); ++k) {
    const PlateReading& r = record.plates[k].reading;
    if (!r.contact) continue;
    cop_msg_.header.stamp = stamp;
    cop_msg_.header.frame_id = record.plates[k].frame;
    cop_msg_.point.x = r.cop_plate.x();
    cop_msg_.point.y = r.cop_plate.y();
    cop_msg_.point.z = r.cop_plate.z();
    plate_topics_[k].cop_pub.publish(cop_msg_);
  }
}

void EstimatorNode::onDiagnosticsTimer(const ros::WallTimerEvent&) {
  // The status functions take callbacks_mutex_; the publication comes after they
  // return: roscpp publishes under its own lock, which an in-process publisher holds
  // while it delivers a message inline (inline_callbacks), so holding ours across a
  // publication would invert the order of the two locks.
  try {
    watchMaster();
    updater_.force_update();
  } catch (const std::exception& e) {
    ++exceptions_;
    ROS_ERROR_THROTTLE(kThrottle, "diagnostics: %s", e.what());
  }
}

void EstimatorNode::watchMaster() {
  const bool reachable = ros::master::check();
  const std::string& uri = ros::master::getURI();
  switch (master_watch_->update(reachable, reachable ? masterRunId() : std::string())) {
    case MasterWatch::Event::kNone: return;
    case MasterWatch::Event::kLost:
      ROS_ERROR(
          "the ROS master %s does not answer: no new connection can be made while it is "
          "down (those made keep working); if it is restarted, this node must be too",
          uri.c_str());
      return;
    case MasterWatch::Event::kBack:
      ROS_WARN("the ROS master %s answers again, the same one (run_id '%s'): nothing lost",
               uri.c_str(), master_watch_->runId().c_str());
      return;
    case MasterWatch::Event::kRestarted: break;
  }
  const MasterWatch& w = *master_watch_;
  ROS_ERROR(
      "the ROS master %s was restarted (run_id '%s', now '%s'): it knows none of this "
      "node's topics, so publishers started from now on never reach it and its outputs "
      "reach no new subscriber. Restart this node (respawn=\"true\" in the launch file "
      "and exit_on_master_restart: true do it)%s",
      uri.c_str(), w.previousRunId().empty() ? "unknown" : w.previousRunId().c_str(),
      w.runId().empty() ? "unknown" : w.runId().c_str(),
      settings_.exit_on_master_restart ? ": exit_on_master_restart: shutting down" : "");
  if (settings_.exit_on_master_restart) ros::requestShutdown();
}

void EstimatorNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(callbacks_mutex_);
  const PipelineCounters& c = pipeline_->counters();
  const long received = c.received(InputKind::kJointState);
  const long published = c.count(Outcome::kPublished);
  const ros::WallTime now = ros::WallTime::now();
  const double dt = (now - last_diag_).toSec();
  last_diag_ = now;
  status.add("input rate [Hz]", dt > 0 ? (received - received_at_last_diag_) / dt : 0.0);
  status.add("output rate [Hz]", dt > 0 ? (published - published_at_last_diag_) / dt : 0.0);
  received_at_last_diag_ = received;
  published_at_last_diag_ = published;
  const std::string stale = pipeline_->staleInputs();
  const std::string inputs = diagnoseInputs(status);
  if (!inputs.empty())
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, inputs);
  else if (!stale.empty())
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "stale wrench inputs: " + stale);
  else if (published > 0 && pipeline_->record().status != kTrusted)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "loads not trusted: " + describeStatus(pipeline_->record().status));
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "publishing");
  diagnoseLevel(status, published);  // what stops the loads comes first
  status.add("last loads", describeStatus(pipeline_->record().status));
  external_outputs_.diagnose(status);
  status.add("mean latency [s]", latency_count_ ? latency_sum_ / latency_count_ : 0.0);
  status.add("max latency [s]", latency_max_);
  status.add("mean queue wait [s]", queue_wait_count_ ? queue_wait_sum_ / queue_wait_count_ : 0.0);
  status.add("max queue wait [s]", queue_wait_max_);
  status.add("tf waits (for a late transform)", frames_.waits());
  status.add("tf waits run out", frames_.waitsRunOut());
  status.add("max tf wait [s]", frames_.longestWait());
  frames_.clearLongestWait();
  status.add("joint states received", received);
  status.add("wrenches received", c.received(InputKind::kWrench));
  status.add("loads published", published);
  diagnoseCounts(status);
  status.add("stale inputs", stale);
  latency_sum_ = 0.0;
  latency_max_ = 0.0;
  latency_count_ = 0;
  queue_wait_sum_ = 0.0;
  queue_wait_max_ = 0.0;
  queue_wait_count_ = 0;
}

void EstimatorNode::diagnoseLevel(diagnostic_updater::DiagnosticStatusWrapper& status,
                                  long published) {
  using diagnostic_msgs::DiagnosticStatus;
  const double last = joint_health_.lastReceived();
  const double silent = ros::WallTime::now().toSec() - (last > 0.0 ? last : started_.toSec());
  char text[64];
  std::snprintf(text, sizeof text, "no joint states for %.1f s", silent);
  if (silent > kSilence)
    status.summary(DiagnosticStatus::ERROR, text);
  else if (!pipeline_->missingJoint().empty())
    status.summary(DiagnosticStatus::ERROR,
                   "waiting for joint '" + pipeline_->missingJoint() + "'");
  else if (last_joint_outcome_ == Outcome::kStale)
    status.summary(DiagnosticStatus::ERROR,
                   "not publishing: input '" + pipeline_->stoppingInputs() + "' stale");
  else if (noClock())
    status.summary(DiagnosticStatus::WARN, "use_sim_time without /clock");
  else if (published == 0)
    status.summary(DiagnosticStatus::WARN, "no loads published yet");
}

std::string EstimatorNode::diagnoseInputs(diagnostic_updater::DiagnosticStatusWrapper& status) {
  // The first input whose every reading of the period was dropped, or that lost
  // messages: a WARN.
  std::string warning;
  auto one = [&](InputHealth& h) {
    const InputHealth::Period p = h.since();
    status.add("input '" + h.topic() + "': received", h.received());
    status.add("input '" + h.topic() + "': lost (header.seq gaps)", h.lost());
    if (!warning.empty()) return;
    if (p.received > 0 && p.used == 0)
      warning = "input '" + h.topic() + "': every reading dropped (" + toString(p.last_drop) + ")";
    else if (p.lost > 0)
      warning = "input '" + h.topic() + "': " + std::to_string(p.lost) + " messages lost";
  };
  one(joint_health_);
  for (WrenchTopic& w : wrench_topics_)
    if (w.subscriber) one(w.health);
  for (PlateTopic& p : plate_topics_)
    if (p.subscriber) one(p.health);
  return warning;
}

void EstimatorNode::diagnoseCounts(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const PipelineCounters& c = pipeline_->counters();
  status.add("dropped: invalid", c.count(Outcome::kInvalid) + exceptions_);
  status.add("dropped: stamp order", c.count(Outcome::kOrder));
  status.add("dropped: rogue stamp", c.count(Outcome::kRogueStamp));
  status.add("dropped: implausible", c.count(Outcome::kImplausible));
  status.add("not published: non-finite loads", c.count(Outcome::kNonFinite));
  status.add("dropped: unresolved frame", c.count(Outcome::kFrame) + c.count(Outcome::kNoBasePose));
  status.add("dropped: no base pose", c.count(Outcome::kNoBasePose));
  status.add("not used: no needed joint", c.count(Outcome::kNoJoint));
  status.add("not published: waiting for a joint", c.count(Outcome::kWaiting));
  status.add("not published: unchanged", c.count(Outcome::kUnchanged));
  status.add("messages with unknown joints", c.unknown_joints);
  status.add("efforts not compared: non-finite", c.nonfinite_efforts);
  status.add("velocities not used: non-finite", c.nonfinite_velocities);
  status.add("mimic joints contradicting their leader", c.mimic_contradictions);
  status.add("merged: joint states of one instant from several publishers",
             c.count(Outcome::kMerged));
  status.add("samples with a joint held from an earlier message", c.held_samples);
  status.add("joints with measured velocities", pipeline_->velocitiesUsed());
  if (pipeline_->hasSmoothed()) {
    status.add("smoothed stream: bandwidth [Hz]", pipeline_->smoothedBandwidth());
    const std::string bound = pipeline_->smoothedBandwidthBound();
    if (!bound.empty()) status.add("smoothed stream: bandwidth on a bound", bound);
    status.add("smoothed stream: rates from",
               pipeline_->smoothedVelocities() ? "measured velocities" : "positions");
  }
  status.add("not published: stale input", c.count(Outcome::kStale));
  status.add("time jumps back", c.backJumps());
  status.add("time jumps forward", c.forward_jumps);
  status.add("force plate samples received", c.received(InputKind::kPlate));
}

}  // namespace jle
