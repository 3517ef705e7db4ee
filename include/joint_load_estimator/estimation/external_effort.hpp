// External joint efforts from the measured ones, contact detection and contact wrenches
// (docs/external_loads.md, "External torques and contact wrenches"). ROS-free; the Pipeline feeds
// it one published sample at a time.
//
// Sign convention (DESIGN.md: a wrench is the one applied TO the robot): tau_ext is the
// generalised force the environment applies, tau_ext = J^T F for a wrench F on the robot,
// so with the joint equation M qdd + C qd + g + tau_friction = tau_measured + tau_ext:
//   residual:  tau_ext = tau_model(q, qd, qdd) + tau_friction - tau_measured
// (tau_model the loads' effort, tau_friction the friction term when friction/enabled:
// the measured efforts are then taken as motor efforts).
//   momentum observer (De Luca & Mattone, ICRA 2005; Haddadin, De Luca, Albu-Schaeffer,
//   IEEE T-RO 2017): p = M(q) qd, beta = tau_measured - tau_friction + C^T qd - g,
//   r' = K (p' - beta - r), so r follows tau_ext through a first-order lag of gain K
//   [1/s] (K = 2 pi observer_cutoff) and needs no qdd. Discretised with the trapezoid for
//   beta and implicit Euler for r: r_k = (r_{k-1} + K (p_k - p_{k-1} - dt (beta_k +
//   beta_{k-1}) / 2)) / (1 + K dt), stable for every dt.
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/joint_space.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace jle {

/// The wrench estimated at one contact link (ExternalEffortConfig::contacts[k]).
struct ContactEstimate {
  std::string link;
  /// With contact detection: in contact, and this contact can be the detected one (on the
  /// contact's link, or distal to it beyond joints it cannot load: a point force through
  /// their axes; failing any such contact, a 6-D one distal to it whose wrench reproduces
  /// every joint's external effort within its threshold); force, moment and covariance are
  /// zero when not. Without detection
  /// (thresholds and noise_multiple 0): always.
  bool active = false;
  /// Link frame, moment about the link origin (the contact force acts at the configured
  /// point) [N, N m]: the wrench applied TO the robot.
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  /// Covariance of (force, moment) above, link frame [N^2, N^2 m, N^2 m^2] (with
  /// uncertainty/enabled; zero otherwise).
  Matrix6d covariance = Matrix6d::Zero();
  /// sigma_min / sigma_max of the Jacobian used (force rows only for a point contact;
  /// [m/s, rad/s] rows for a wrench): 0 singular, 1 isotropic.
  double conditioning = 0.0;
  double sigma_min = 0.0;  ///< smallest singular value [m or 1]
  double damping = 0.0;    ///< lambda the damped least squares used (0 away from singularities)
};

/// Computes the external efforts and contact wrenches of each published sample.
/// Memory is allocated in the constructor only.
class ExternalEffort {
 public:
  /// `published`: the model segments of the published joints (LoadsRecord::segment).
  /// `friction_velocity_scale` > 0: the friction term is subtracted (friction/enabled);
  /// 0: not. Throws SettingsError naming the key or the link/joint (an unknown contact
  /// link or joint, a contact whose joints are not all published, too few joints).
  ExternalEffort(const Model<double>& model, const ExternalEffortConfig& config,
                 const std::vector<int>& published, const Eigen::Vector3d& gravity_world,
                 double friction_velocity_scale, bool uncertainty);

  /// One published sample at time t [s]: the estimate q, qd (model.nq), the base pose
  /// (floating base; ignored otherwise), per published joint the model effort (rigid
  /// body, without friction), the measured effort (NaN: none) and the model effort's
  /// variance (nullptr: none).
  void update(double t, const VectorX<double>& q, const VectorX<double>& qd,
              const BaseState<double>& base, const std::vector<double>& model_effort,
              const std::vector<double>& measured, const std::vector<double>* model_variance);
  /// Forgets the observer's and the detector's history (a jump of time); with
  /// noise_multiple, the calibration starts again (thresholds 0 until it ends).
  void reset();

  const ExternalEffortConfig& config() const { return config_; }
  /// Per published joint [N m or N]; NaN where it has no measured effort or does not move.
  const std::vector<double>& residual() const { return residual_; }
  const std::vector<double>& observer() const { return observer_; }
  /// The configured method's estimate, and its 1-sigma (with uncertainty).
  const std::vector<double>& external() const {
    return config_.method == ExternalMethod::kObserver ? observer_ : residual_;
  }
  const std::vector<double>& stddev() const { return stddev_; }
  const std::vector<ContactEstimate>& contacts() const { return contacts_; }
  /// Per published joint: the detection threshold in use [N m or N] (0: none yet).
  const std::vector<double>& thresholds() const { return threshold_; }
  /// Contact detection at the last sample: in contact; whether it started or ended at it;
  /// the contact's joint, the most distal published joint loaded (over its threshold,
  /// until below release_fraction of it) within the last link_window, re-evaluated at
  /// every sample where a joint is over its threshold (kept while the contact fades and at
  /// its end), and that joint's child link. A contact on link k loads joints 1..k only, so the
  /// contact is on that link or on a more distal one whose joints it does not load (a
  /// force through their axes): the link is the most proximal one the contact can be on.
  /// contactChanged: the contact's joint changed at this sample while it lasts (not at
  /// its start).
  bool inContact() const { return in_contact_; }
  bool contactStarted() const { return started_; }
  bool contactEnded() const { return ended_; }
  bool contactChanged() const { return changed_; }
  const std::string& contactJoint() const { return contact_joint_; }
  const std::string& contactLink() const { return contact_link_; }
  const JointSpace& jointSpace() const { return js_; }

 private:
  struct Contact {
    int segment = 0;
    Eigen::Vector3d point_segment = Eigen::Vector3d::Zero();
    Eigen::Matrix3d R_segment_link = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p_segment_link = Eigen::Vector3d::Zero();
    int rows = 6;
    int moving = 0;  // the moving segment the link is on (fixed joints lumped)
  };
  void setUpContacts();
  void setUpThresholds();
  void updateResidual(const std::vector<double>& model_effort, const std::vector<double>& measured,
                      const std::vector<double>* model_variance);
  void updateObserver(double t, const std::vector<double>& measured);
  enum class Explains { kNo, kYes, kIfItFits };
  Explains explains(std::size_t k) const;
  bool fits(const Eigen::Matrix<double, 6, 1>& F, int rows) const;
  void chooseActive();
  void solveContact(std::size_t k);
  bool calibrate(double t);
  double robustSigma(int m);
  void keepCalibrationSample();
  void detect(double t);

  Model<double> model_;
  ExternalEffortConfig config_;
  std::vector<int> published_;
  std::vector<int> row_;  // per published joint: its joint-space index, -1 if it does not move
  Eigen::Vector3d gravity_;
  double velocity_scale_;
  bool uncertainty_;
  double gain_;  // [1/s]
  Data<double> data_;
  JointSpace js_;
  std::vector<Contact> contact_setup_;
  std::vector<ContactEstimate> contacts_;
  std::vector<Explains> explained_;  // per contact, at the last sample (explains())
  std::vector<char> fit_;            // per contact: a 6-D one beyond whose wrench fits
  std::vector<double> residual_, observer_, stddev_, residual_var_;
  // Observer state per joint-space row.
  Eigen::VectorXd p_prev_, beta_prev_, r_;
  std::vector<char> row_started_;
  double t_prev_ = 0.0;
  bool started_observer_ = false;
  double observer_var_factor_ = 0.0;  // a / 2 of the last step (see update())
  // Contact wrench workspace.
  Eigen::MatrixXd J_, A_;
  Eigen::VectorXd tau_js_, var_js_;
  VectorX<double> zero_;  // qdd of the forward pass (the joint-space terms need none)
  // Detection.
  std::vector<double> abs_threshold_, threshold_;
  // Per published joint: loaded (over its threshold, until below release_fraction of
  // it), and when it last was [s].
  std::vector<char> loaded_;
  std::vector<double> last_loaded_;
  std::vector<int> depth_;
  int contact_index_ = -1;  // the contact's published joint
  // Calibration: every stride-th sample's tau_ext (row-major, sample x joint) up to
  // kCalibrationSamples; when full, every other one is dropped and the stride doubles.
  std::vector<double> calib_, calib_scratch_;
  long calib_seen_ = 0, calib_stride_ = 1;
  int calib_rows_ = 0;
  double settle_ = 0.0;  // [s] left out after a start or reset
  double t_start_ = 0.0;
  bool have_start_ = false, calibrated_ = false;
  bool detection_ = false;  // thresholds configured
  bool in_contact_ = false, started_ = false, ended_ = false, changed_ = false;
  std::string contact_joint_, contact_link_;
};

}  // namespace jle
