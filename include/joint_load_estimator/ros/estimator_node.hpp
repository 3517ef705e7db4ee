// The ROS wrapper: owns the Estimator, forwards messages to it, publishes its loads.
#pragma once

#include <joint_load_estimator/CalibrateBias.h>
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/estimator.hpp>
#include <joint_load_estimator/ros/settings.hpp>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace jle {

/// Counters shown in diagnostics and used by the tests.
struct NodeCounters {
  long joint_states = 0;   ///< JointState messages received
  long wrenches = 0;       ///< WrenchStamped messages received
  long published = 0;      ///< JointLoads published
  long dropped_invalid = 0;    ///< malformed or non-finite messages
  long dropped_order = 0;      ///< duplicate or out-of-order stamps
  long dropped_frame = 0;      ///< wrenches in a frame that could not be resolved
  long unknown_joints = 0;     ///< messages naming joints the model does not have
  long stale = 0;              ///< samples not published because an input was stale
  long resets = 0;             ///< backward time jumps
  long plate_samples = 0;      ///< force plate WrenchStamped messages received (plates also
                               ///< count in dropped_* like wrenches)
};

class EstimatorNode {
 public:
  /// Reads the parameters and the model, subscribes and advertises. Throws
  /// SettingsError or ModelError (naming the key, link or joint) on bad configuration.
  EstimatorNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  /// Stops the ~calibrate_bias thread (waking a calibration in progress).
  ~EstimatorNode();
  EstimatorNode(const EstimatorNode&) = delete;
  EstimatorNode& operator=(const EstimatorNode&) = delete;

  const NodeCounters& counters() const { return counters_; }

 private:
  struct WrenchTopic {
    WrenchTopicSettings settings;
    WrenchInputConfig input;  // settings_.estimator.wrenches[k], its link completed
    ros::Subscriber subscriber;
    std::string last_frame;  // cache of the constant frame resolution
    bool rigid = false;      // expressed-in frame rigidly attached to the target link
    Eigen::Matrix3d R_link_frame = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p_link_frame = Eigen::Vector3d::Zero();
    // Sensor inputs (sensor_joint): the frame of the last reading and its pose in the
    // link (the residual is published in it), the consistency output and its extremes.
    std::string sensor_frame;
    Eigen::Matrix3d R_link_sensor = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p_link_sensor = Eigen::Vector3d::Zero();
    ros::Publisher consistency_pub;  // ~consistency/<sensor_joint>
    double max_force = 0.0, max_moment = 0.0;  // |residual| since the last diagnosis
    // The sensor's offset as it reports (its frame and sign), subtracted from each
    // reading. Written by ~calibrate_bias: guarded by calibration_mutex_.
    Eigen::Vector3d bias_force = Eigen::Vector3d::Zero(), bias_torque = Eigen::Vector3d::Zero();
  };

  // ~calibrate_bias in progress: fed by publish(), read by the service thread.
  struct Calibration {
    bool active = false, done = false;
    bool assume_still = true;
    double duration = 0.0, first_stamp = 0.0;
    std::string failure;  // non-empty: refused while collecting
    long samples = 0;
    ros::WallTime last_sample;
    // Per wrench topic: running mean and sum of squared deviations (Welford) of the
    // offset estimates, reading frame and sign: (force, torque).
    std::vector<Eigen::Matrix<double, 6, 1>> mean, m2;
  };

  struct PlateTopic {
    PlateTopicSettings settings;
    PlateInputConfig input;  // settings_.estimator.plates[k]
    ros::Subscriber subscriber;
    ros::Publisher cop_pub;
    std::string frame;  // the plate frame whose pose the estimator holds (COP frame_id)
    bool pose_known = false;
  };

  void onJointState(const sensor_msgs::JointState::ConstPtr& msg);
  void onPlate(std::size_t k, const geometry_msgs::WrenchStamped::ConstPtr& msg);
  bool resolvePlatePose(PlateTopic& plate, const std::string& frame);
  void setUpPlates();
  void publishPlates(const ros::Time& stamp);
  void onWrench(std::size_t k, const geometry_msgs::WrenchStamped::ConstPtr& msg);
  bool resolveFrame(WrenchTopic& topic, const std::string& frame, const ros::Time& stamp,
                    Eigen::Matrix3d& R, Eigen::Vector3d& p);
  bool checkTimeJump(const ros::Time& stamp);
  double relative(const ros::Time& stamp);
  ros::Time absolute(double t) const;
  void publish(const ros::Time& received);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  // Predicted against measured (sensor residuals, floating-base residual).
  void publishConsistency(const ros::Time& stamp);
  void diagnoseConsistency(diagnostic_updater::DiagnosticStatusWrapper& status);
  bool onCalibrateBias(joint_load_estimator::CalibrateBias::Request& req,
                       joint_load_estimator::CalibrateBias::Response& res);
  void loadBiasFile();
  std::string saveBiasFile(const joint_load_estimator::CalibrateBias::Response& res, long samples,
                           const std::vector<std::string>& frames);

  ros::NodeHandle nh_, private_nh_;
  Settings settings_;
  std::unique_ptr<Estimator> estimator_;
  std::unordered_map<std::string, int> coordinate_of_;  // joint name -> index in q
  std::unordered_map<std::string, int> segment_of_;     // moving joint name -> segment
  std::vector<int> published_segments_;
  std::vector<double> q_;            // latest position of each coordinate
  std::vector<bool> q_received_;
  std::vector<double> effort_;       // latest measured effort per published joint (NaN: none)
  // Measured efforts by stamp, to pair them with a delayed estimate.
  std::deque<std::pair<double, std::vector<double>>> effort_history_;
  ros::Subscriber joint_sub_;
  std::vector<std::unique_ptr<WrenchTopic>> wrench_topics_;
  ros::Publisher loads_pub_, residual_pub_;
  std::vector<ros::Publisher> wrench_pubs_;
  joint_load_estimator::JointLoads loads_msg_;
  geometry_msgs::WrenchStamped wrench_msg_;
  std::vector<std::unique_ptr<PlateTopic>> plate_topics_;
  geometry_msgs::PointStamped cop_msg_;
  double body_mass_ = 0.0;  // [kg] the divisor of effort_per_kg; 0: not published
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  diagnostic_updater::Updater updater_;
  ros::Time last_stamp_;
  ros::Time time_ref_;  // origin of the estimator's time axis
  ros::Time last_now_;
  NodeCounters counters_;
  long published_at_last_diag_ = 0, received_at_last_diag_ = 0;
  ros::WallTime last_diag_ = ros::WallTime::now();
  double latency_sum_ = 0.0, latency_max_ = 0.0;
  long latency_count_ = 0;
  // Consistency.
  std::vector<std::size_t> sensor_topics_;  // indices into wrench_topics_ of the sensors
  double base_force_max_ = 0.0, base_moment_max_ = 0.0;  // since the last diagnosis
  double total_weight_ = 0.0;                             // [N] m |g|
  // ~calibrate_bias runs on its own queue and thread, so that collecting its window
  // does not stall the joint-state callbacks it is waiting for.
  std::mutex calibration_mutex_;
  std::condition_variable calibration_cv_;
  Calibration calibration_;
  std::atomic<bool> calibrating_{false};
  bool shutting_down_ = false;
  ros::CallbackQueue service_queue_;
  ros::ServiceServer calibrate_srv_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
};

}  // namespace jle
