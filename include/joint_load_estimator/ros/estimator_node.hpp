// The ROS wrapper: reads the parameters and the model, converts messages for the
// Pipeline (pipeline.hpp) and its records to messages. No physics, no decisions.
#pragma once

#include <joint_load_estimator/CalibrateBias.h>
#include <joint_load_estimator/EstimatorConfig.h>
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/estimation/sensor_bias.hpp>
#include <joint_load_estimator/estimation/sensor_sign.hpp>
#include <joint_load_estimator/pipeline/pipeline.hpp>
#include <joint_load_estimator/ros/bias_file.hpp>
#include <joint_load_estimator/ros/conversions.hpp>
#include <joint_load_estimator/ros/external_outputs.hpp>
#include <joint_load_estimator/ros/inline_callback_queue.hpp>
#include <joint_load_estimator/ros/input_health.hpp>
#include <joint_load_estimator/ros/master_watch.hpp>
#include <joint_load_estimator/ros/settings.hpp>

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace jle {

/// `name` (~robot_description's value, not URDF text) resolved in `nh`; a name ROS refuses
/// throws SettingsError saying that it is neither a parameter's name nor a URDF.
std::string resolveParameter(const ros::NodeHandle& nh, const std::string& name);

class EstimatorNode {
 public:
  /// Reads the parameters and the model, subscribes and advertises. Throws
  /// SettingsError or ModelError (naming the key, link or joint) on bad configuration.
  EstimatorNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  /// Stops the ~calibrate_bias thread (waking a calibration in progress).
  ~EstimatorNode();
  EstimatorNode(const EstimatorNode&) = delete;
  EstimatorNode& operator=(const EstimatorNode&) = delete;

  const PipelineCounters& counters() const { return pipeline_->counters(); }

 private:
  struct WrenchTopic {
    ros::Subscriber subscriber;
    InputHealth health;
    // Sensor inputs (sensor_joint): the residual's output ~consistency/<sensor_joint> and
    // its extremes.
    ros::Publisher consistency_pub;
    double max_force = 0.0, max_moment = 0.0;  // |residual| since the last diagnosis
    SignTally sign;  // readings against the prediction since the last diagnosis
  };

  // ~calibrate_bias in progress: fed by publishConsistency(), read by the service
  // thread.
  struct Calibration {
    bool active = false;             // a service call is waiting for its window
    ros::WallTime last_sample;       // when the window last took a sample (or started)
    BiasEstimator estimator;         // one sensor per entry of sensor_topics_, in their order
    std::vector<BiasSample> sample;  // the sample handed to it (kept: no allocation)
    std::vector<char> needed;        // per coordinate: whether the loads need it
  };

  struct PlateTopic {
    ros::Subscriber subscriber;
    InputHealth health;
    ros::Publisher cop_pub;
  };

  Model<double> loadModel();
  void advertise();
  void subscribe();
  void setUpConsistency();
  using JointStateEvent = ros::MessageEvent<const sensor_msgs::JointState>;
  using WrenchEvent = ros::MessageEvent<const geometry_msgs::WrenchStamped>;
  // An input subscription (queue of 100, tcpNoDelay), inline with inline_callbacks.
  template <class Event>
  ros::Subscriber subscribeInput(const std::string& topic,
                                 const boost::function<void(const Event&)>& callback);
  void onJointState(const JointStateEvent& event);
  void onWrench(std::size_t k, const WrenchEvent& event);
  void onPlate(std::size_t k, const WrenchEvent& event);
  // Logs what the pipeline said of the last message, each problem throttled on its own.
  void report(Outcome outcome);
  void publish(const ros::Time& received);
  // The immediate stream's loads a reset or a retune drained, then the smoothed stream's.
  void publishDrained(const ros::Time& received);
  // The smoothed stream's record on ~smoothed/... (settings.smoothed).
  void publishSmoothed();
  // A ~joint_loads message to fill: one of the pool that no subscriber holds any more,
  // else a new one (published as a shared pointer, so that a subscriber in the same
  // process gets the message itself, not a serialised copy).
  joint_load_estimator::JointLoadsPtr freeLoadsMessage();
  void publishPlates(const LoadsRecord& record, const ros::Time& stamp);
  // /diagnostics on a wall-clock timer (diagnostic_period): it keeps its rate whatever
  // the inputs and the (sim) clock do.
  void onDiagnosticsTimer(const ros::WallTimerEvent& event);
  // The master this node registered with, polled on the diagnostics timer: one that
  // stops answering, or is replaced (a restarted roscore), said with an error.
  void watchMaster();
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  // The first of the reasons why the loads are not flowing, or empty (diagnose()).
  void diagnoseLevel(diagnostic_updater::DiagnosticStatusWrapper& status, long published);
  // Per input: received, used, lost; an input whose readings are all dropped is WARN.
  std::string diagnoseInputs(diagnostic_updater::DiagnosticStatusWrapper& status);
  void diagnoseCounts(diagnostic_updater::DiagnosticStatusWrapper& status);
  // Predicted against measured (sensor residuals, floating-base residual).
  void publishConsistency(const LoadsRecord& record, const ros::Time& stamp);
  void publishResidual(const InputRecord& input, std::size_t k, const ros::Time& stamp);
  void collectBiasSample(const LoadsRecord& record);
  void diagnoseConsistency(diagnostic_updater::DiagnosticStatusWrapper& status);
  bool onCalibrateBias(joint_load_estimator::CalibrateBias::Request& req,
                       joint_load_estimator::CalibrateBias::Response& res);
  void startCalibration(double duration, bool assume_still);
  void waitForCalibration(std::unique_lock<std::mutex>& lock);
  std::vector<BiasFileEntry> applyCalibration(joint_load_estimator::CalibrateBias::Response& res);
  void applyPendingBias();
  // ~reconfigure (reconfigure.cpp): live tuning through dynamic_reconfigure.
  void setUpReconfigure();
  void onReconfigure(joint_load_estimator::EstimatorConfig& config, std::uint32_t level);

  ros::NodeHandle nh_, private_nh_;
  Settings settings_;
  // The input callbacks and the diagnostics timer take it: with inline_callbacks they
  // run in the threads that deliver the messages (one per publisher in the process).
  std::mutex callbacks_mutex_;
  InlineCallbackQueue inline_queue_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  Tf2FrameSource frames_;
  std::unique_ptr<Pipeline> pipeline_;
  ros::Subscriber joint_sub_;
  std::vector<WrenchTopic> wrench_topics_;
  std::vector<PlateTopic> plate_topics_;
  ros::Publisher loads_pub_, residual_pub_;
  std::vector<ros::Publisher> wrench_pubs_;
  ExternalOutputs external_outputs_;            // external_effort/enabled
  joint_load_estimator::JointLoads loads_msg_;  // the template: names and sizes
  std::vector<joint_load_estimator::JointLoadsPtr> loads_pool_;
  ros::Publisher efforts_pub_;           // ~joint_efforts (sensor_msgs/JointState)
  sensor_msgs::JointState efforts_msg_;  // the JointLoads' names, q, q-dot, efforts
  geometry_msgs::WrenchStamped wrench_msg_;
  geometry_msgs::PointStamped cop_msg_;
  // The smoothed stream: ~smoothed/joint_loads, ~smoothed/joint_efforts,
  // ~smoothed/wrench/<joint> (advertised only with smoothed/enabled).
  struct SmoothedTopics {
    ros::Publisher loads_pub, efforts_pub;
    std::vector<ros::Publisher> wrench_pubs;
    joint_load_estimator::JointLoads loads_msg;
    sensor_msgs::JointState efforts_msg;
  } smoothed_;
  diagnostic_updater::Updater updater_;
  ros::WallTimer diagnostics_timer_;
  std::unique_ptr<MasterWatch> master_watch_;
  InputHealth joint_health_;
  Outcome last_joint_outcome_ = Outcome::kUsed;  // of the last joint state
  ros::WallTime started_ = ros::WallTime::now();
  // When each problem (problemKey) was last logged [wall s], and callbacks that threw.
  std::unordered_map<std::size_t, double> last_log_;
  long exceptions_ = 0;
  long published_at_last_diag_ = 0, received_at_last_diag_ = 0;
  ros::WallTime last_diag_ = ros::WallTime::now();
  double latency_sum_ = 0.0, latency_max_ = 0.0;  // callback entry -> loads published [s]
  long latency_count_ = 0;
  // Receipt of a joint state (in roscpp's subscription queue) -> its callback [s].
  double queue_wait_sum_ = 0.0, queue_wait_max_ = 0.0;
  long queue_wait_count_ = 0;
  // Consistency.
  std::vector<std::size_t> sensor_topics_;               // indices of the sensor inputs
  double base_force_max_ = 0.0, base_moment_max_ = 0.0;  // since the last diagnosis
  double total_weight_ = 0.0;                            // [N] m |g|
  // ~calibrate_bias runs on its own queue and thread, so that collecting its window
  // does not stall the joint-state callbacks it is waiting for. The biases it finds are
  // handed to the pipeline on the callbacks' thread (bias_pending_).
  std::mutex calibration_mutex_;
  std::condition_variable calibration_cv_;
  Calibration calibration_;
  std::atomic<bool> calibrating_{false};
  std::atomic<bool> bias_pending_{false};
  std::vector<SensorBias> pending_bias_;  // per wrench input, guarded
  bool shutting_down_ = false;
  ros::CallbackQueue service_queue_;
  ros::ServiceServer calibrate_srv_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
  // ~reconfigure: the parameters as read at start, with every change applied since (the
  // one reader, parseSettings, maps and checks them), and the server.
  XmlRpc::XmlRpcValue params_;
  boost::recursive_mutex reconfigure_mutex_;  // the server's, held by updateConfig() too
  std::unique_ptr<dynamic_reconfigure::Server<joint_load_estimator::EstimatorConfig>> reconfigure_;
  std::string reconfigure_status_;  // ~reconfigure's `status`: the answer to the last change
};

}  // namespace jle
