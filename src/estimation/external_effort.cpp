#include <joint_load_estimator/estimation/external_effort.hpp>
#include <joint_load_estimator/model/friction.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace jle {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Calibration samples kept per joint: a median of 1024 has a relative scatter of ~4 %.
constexpr int kCalibrationSamples = 1024;
// sigma of zero-mean Gaussian noise / its median absolute value.
constexpr double kMadToSigma = 1.482602218505602;
// Calibration samples farther than this many robust sigmas are outliers.
constexpr double kInlierSigmas = 5.0;
// [m] a point force this close to a joint's axis cannot load it (1 mm: 0.02 N m of 20 N).
constexpr double kBlindLever = 1e-3;

[[noreturn]] void fail(const std::string& key, const std::string& what) {
  throw SettingsError("parameter '" + key + "' " + what);
}

std::string contactKey(std::size_t k, const char* key) {
  return "external_effort/contacts[" + std::to_string(k) + "]/" + key;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

}  // namespace

ExternalEffort::ExternalEffort(const Model<double>& model, const ExternalEffortConfig& config,
                               const std::vector<int>& published,
                               const Eigen::Vector3d& gravity_world, double friction_velocity_scale,
                               bool uncertainty)
    : model_(model),
      config_(config),
      published_(published),
      gravity_(gravity_world),
      velocity_scale_(friction_velocity_scale),
      uncertainty_(uncertainty),
      gain_(2.0 * kPi * config.observer_cutoff),
      data_(model_),
      js_(model_) {
  validate(config_);
  const std::size_t n = published_.size();
  row_.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) row_[i] = js_.index[published_[i]];
  residual_.assign(n, kNaN);
  observer_.assign(n, kNaN);
  stddev_.assign(uncertainty_ ? n : 0, 0.0);
  residual_var_.assign(n, 0.0);
  const int nj = js_.size();
  p_prev_ = Eigen::VectorXd::Zero(nj);
  beta_prev_ = Eigen::VectorXd::Zero(nj);
  r_ = Eigen::VectorXd::Zero(nj);
  row_started_.assign(static_cast<std::size_t>(nj), 0);
  tau_js_ = Eigen::VectorXd::Zero(nj);
  var_js_ = Eigen::VectorXd::Zero(nj);
  J_ = Eigen::MatrixXd::Zero(6, nj);
  zero_ = VectorX<double>::Zero(model_.nq);
  setUpContacts();
  setUpThresholds();
}

void ExternalEffort::setUpContacts() {
  std::vector<char> is_published(static_cast<std::size_t>(model_.nsegments()), 0);
  for (int s : published_) is_published[s] = 1;
  for (std::size_t k = 0; k < config_.contacts.size(); ++k) {
    const ContactLinkConfig& c = config_.contacts[k];
    int f = 0;
    try {
      f = model_.frameIndex(c.link);
    } catch (const std::invalid_argument& e) {
      fail(contactKey(k, "link"), std::string("names ") + e.what());
    }
    const Frame<double>& fr = model_.frames[f];
    Contact setup;
    setup.segment = fr.segment;
    setup.R_segment_link = fr.R_segment_frame;
    setup.p_segment_link = fr.p_segment_frame;
    setup.point_segment = fr.p_segment_frame + fr.R_segment_frame * c.point;
    setup.rows = c.force_only ? 3 : 6;
    int joints = 0;
    setup.moving = js_.index[fr.segment] >= 0 ? fr.segment : js_.moving_parent[fr.segment];
    for (int s = setup.moving; s >= 0; s = js_.moving_parent[s], ++joints)
      if (!is_published[s])
        fail(contactKey(k, "link"), "'" + c.link + "' needs the external effort of joint '" +
                                        model_.joint_name[s] +
                                        "', which is not published (joints)");
    if (joints < setup.rows)
      fail(contactKey(k, "link"), "'" + c.link + "' has " + std::to_string(joints) +
                                      " moving joints above it; a " +
                                      (c.force_only ? "force" : "wrench") + " needs " +
                                      std::to_string(setup.rows) + " (force_only: 3)");
    contact_setup_.push_back(setup);
    ContactEstimate e;
    e.link = c.link;
    contacts_.push_back(e);
    explained_.push_back(Explains::kNo);
    fit_.push_back(0);
  }
  A_ = Eigen::MatrixXd::Zero(6, js_.size());
}

void ExternalEffort::setUpThresholds() {
  const std::size_t n = published_.size();
  abs_threshold_.assign(n, config_.threshold);
  threshold_.assign(n, 0.0);
  depth_.assign(n, 0);
  last_loaded_.assign(n, -kInfinity);
  loaded_.assign(n, 0);
  calib_.assign(static_cast<std::size_t>(kCalibrationSamples) * n, 0.0);
  calib_scratch_.assign(kCalibrationSamples, 0.0);
  // The observer starts at zero and follows tau_ext through its lag: e^-5 of a start-up
  // error is left after 5 time constants.
  settle_ = config_.method == ExternalMethod::kObserver ? std::max(config_.settle_time, 5.0 / gain_)
                                                        : config_.settle_time;
  for (const auto& jt : config_.joint_thresholds) {
    bool found = false;
    for (std::size_t i = 0; i < n; ++i)
      if (model_.joint_name[published_[i]] == jt.first) {
        abs_threshold_[i] = jt.second;
        found = true;
      }
    if (!found)
      fail("external_effort/joint_thresholds/" + jt.first, "names no published moving joint");
  }
  for (std::size_t i = 0; i < n; ++i)
    for (int s = published_[i]; s > 0; s = model_.parent[s]) ++depth_[i];
  if (config_.noise_multiple == 0.0) {
    calibrated_ = true;
    threshold_ = abs_threshold_;
  }
  detection_ =
      config_.noise_multiple > 0.0 ||
      std::any_of(abs_threshold_.begin(), abs_threshold_.end(), [](double v) { return v > 0.0; });
}

void ExternalEffort::reset() {
  std::fill(row_started_.begin(), row_started_.end(), 0);
  r_.setZero();
  started_observer_ = false;
  have_start_ = false;
  if (config_.noise_multiple > 0.0) {
    calibrated_ = false;
    std::fill(threshold_.begin(), threshold_.end(), 0.0);
    calib_seen_ = 0;
    calib_stride_ = 1;
    calib_rows_ = 0;
  }
  in_contact_ = started_ = ended_ = changed_ = false;
  std::fill(last_loaded_.begin(), last_loaded_.end(), -kInfinity);
  std::fill(loaded_.begin(), loaded_.end(), 0);
  contact_index_ = -1;
}

void ExternalEffort::update(double t, const VectorX<double>& q, const VectorX<double>& qd,
                            const BaseState<double>& base, const std::vector<double>& model_effort,
                            const std::vector<double>& measured,
                            const std::vector<double>* model_variance) {
  BaseState<double> still;  // the joint-space equations hold for a base at rest
  still.R_world_base = base.R_world_base;
  still.p_world_base = base.p_world_base;
  forwardKinematics(model_, data_, q, qd, zero_, gravity_, still);
  updateJointSpace(model_, data_, gravity_, js_);
  updateResidual(model_effort, measured, model_variance);
  updateObserver(t, measured);
  const std::vector<double>& ext = external();
  tau_js_.setZero();
  var_js_.setZero();
  for (std::size_t i = 0; i < published_.size(); ++i) {
    const int j = row_[i];
    if (j < 0 || !std::isfinite(ext[i])) continue;
    tau_js_[j] = ext[i];
    var_js_[j] = config_.method == ExternalMethod::kObserver
                     ? observer_var_factor_ * config_.effort_noise * config_.effort_noise
                     : residual_var_[i];
  }
  if (uncertainty_)
    for (std::size_t i = 0; i < published_.size(); ++i)
      stddev_[i] = row_[i] >= 0 ? std::sqrt(var_js_[row_[i]]) : 0.0;
  detect(t);
  for (std::size_t k = 0; k < contacts_.size(); ++k) solveContact(k);
  chooseActive();
}

void ExternalEffort::updateResidual(const std::vector<double>& model_effort,
                                    const std::vector<double>& measured,
                                    const std::vector<double>* model_variance) {
  const double noise2 = config_.effort_noise * config_.effort_noise;
  for (std::size_t i = 0; i < published_.size(); ++i) {
    const int s = published_[i];
    if (row_[i] < 0 || !std::isfinite(measured[i])) {
      residual_[i] = kNaN;
      continue;
    }
    double predicted = model_effort[i];
    if (velocity_scale_ > 0.0)
      predicted +=
          frictionEffort(model_.damping[s], model_.friction[s], data_.qd[s], velocity_scale_);
    residual_[i] = predicted - measured[i];
    residual_var_[i] = noise2 + (model_variance ? (*model_variance)[i] : 0.0);
  }
}

void ExternalEffort::updateObserver(double t, const std::vector<double>& measured) {
  const double dt = started_observer_ ? t - t_prev_ : 0.0;
  const bool step = started_observer_ && dt > 0.0;
  if (started_observer_ && !(dt > 0.0)) std::fill(row_started_.begin(), row_started_.end(), 0);
  const double a = step ? gain_ * dt / (1.0 + gain_ * dt) : 0.0;
  observer_var_factor_ = a / 2.0;  // trapezoid-averaged white noise through the lag
  for (std::size_t i = 0; i < published_.size(); ++i) {
    const int j = row_[i];
    if (j < 0) continue;
    const int s = published_[i];
    if (!std::isfinite(measured[i])) {
      row_started_[j] = 0;
      observer_[i] = kNaN;
      continue;
    }
    double beta = measured[i] + js_.coriolis_transpose[j] - js_.gravity[j];
    if (velocity_scale_ > 0.0)
      beta -= frictionEffort(model_.damping[s], model_.friction[s], data_.qd[s], velocity_scale_);
    const double p = js_.momentum[j];
    if (row_started_[j] && step) {
      const double drive = p - p_prev_[j] - 0.5 * dt * (beta + beta_prev_[j]);
      r_[j] = (r_[j] + gain_ * drive) / (1.0 + gain_ * dt);
    } else {
      r_[j] = 0.0;  // starts from "no contact": the lag settles in a few 1 / K
      row_started_[j] = 1;
    }
    p_prev_[j] = p;
    beta_prev_[j] = beta;
    observer_[i] = r_[j];
  }
  t_prev_ = t;
  started_observer_ = true;
}

namespace {

// Damped least squares of J^T F = tau_ext for the first R rows of J (rows: point
// velocity, angular velocity) through the R x R normal matrix G = J J^T = V S^2 V^T:
// F = V diag(1 / (s^2 + lambda^2)) V^T J tau, lambda^2 = damping^2 (1 - (s_min /
// threshold)^2) below the singular threshold, 0 above (Maciejewski & Klein 1988). An
// R x R eigen-decomposition (R = 3 or 6) instead of the SVD of the R x n J: no allocation,
// and the squared condition number costs ~1e-12 relative here (s_min / s_max > 1e-2).
template <int R>
void dampedSolve(const Eigen::MatrixXd& J, const Eigen::VectorXd& tau,
                 const ExternalEffortConfig& config, Eigen::MatrixXd& P, Vector6d& F,
                 ContactEstimate& e) {
  using MatrixR = Eigen::Matrix<double, R, R>;
  const MatrixR G = J.topRows<R>() * J.topRows<R>().transpose();
  const Eigen::SelfAdjointEigenSolver<MatrixR> eig(G);
  const Eigen::Matrix<double, R, 1> s2 = eig.eigenvalues().cwiseMax(0.0);  // ascending
  const double s_min = std::sqrt(s2[0]);
  const double ratio = s_min / config.singular_threshold;
  const double lambda2 =
      ratio < 1.0 ? config.damping * config.damping * (1.0 - ratio * ratio) : 0.0;
  e.sigma_min = s_min;
  e.conditioning = s2[R - 1] > 0.0 ? s_min / std::sqrt(s2[R - 1]) : 0.0;
  e.damping = std::sqrt(lambda2);
  Eigen::Matrix<double, R, 1> inverse;
  for (int r = 0; r < R; ++r) inverse[r] = s2[r] + lambda2 > 0.0 ? 1.0 / (s2[r] + lambda2) : 0.0;
  const MatrixR Ginv = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
  P.topRows<R>().noalias() = Ginv * J.topRows<R>();  // tau -> F (world, moment about the point)
  F.setZero();
  F.head<R>().noalias() = P.topRows<R>() * tau;
}

}  // namespace

// With detection: whether contact k can be the detected one. A contact on link k loads
// joints 1..k only; the contact's joint is the most distal one loaded. A contact proximal
// to it cannot load it (kNo). One distal to it must leave the joints between unloaded: a
// point force can only through their axes (J_'s point-velocity rows zero there: kYes, else
// kNo); a 6-D wrench always can (one condition a joint), so it is the contact if its
// wrench fits (kIfItFits: ExternalEffort::fits). J_ is k's.
ExternalEffort::Explains ExternalEffort::explains(std::size_t k) const {
  if (!detection_) return Explains::kYes;
  if (!in_contact_ || contact_index_ < 0) return Explains::kNo;
  const int detected = published_[static_cast<std::size_t>(contact_index_)];
  const Contact& c = contact_setup_[k];
  Explains x = Explains::kYes;
  for (int s = c.moving; s >= 0; s = js_.moving_parent[s]) {
    if (s == detected) return x;
    if (c.rows == 6)
      x = Explains::kIfItFits;
    else if (J_.col(js_.index[s]).head<3>().norm() > kBlindLever)
      return Explains::kNo;
  }
  return Explains::kNo;
}

// Whether contact k's wrench F (its first `rows`) reproduces the external effort: at every
// published joint with a threshold, |tau_ext - (J^T F)| within it. J_ is k's.
bool ExternalEffort::fits(const Vector6d& F, int rows) const {
  for (std::size_t i = 0; i < published_.size(); ++i) {
    const int j = row_[i];
    if (j < 0 || !(threshold_[i] > 0.0)) continue;
    const double predicted = J_.col(j).head(rows).dot(F.head(rows));
    if (std::abs(tau_js_[j] - predicted) > threshold_[i]) return false;
  }
  return true;
}

void ExternalEffort::solveContact(std::size_t k) {
  const Contact& c = contact_setup_[k];
  ContactEstimate& e = contacts_[k];
  pointJacobian(model_, data_, js_, c.segment, c.point_segment, J_);
  explained_[k] = explains(k);
  Vector6d F;
  if (c.rows == 3)
    dampedSolve<3>(J_, tau_js_, config_, A_, F, e);
  else
    dampedSolve<6>(J_, tau_js_, config_, A_, F, e);
  fit_[k] = explained_[k] == Explains::kIfItFits && fits(F, c.rows);
  // To the link frame, moment about the link origin: T (6 x 6) acting on (f; m_point).
  const Eigen::Matrix3d R_world_link = data_.R_world[c.segment] * c.R_segment_link;
  const Eigen::Vector3d lever =
      R_world_link.transpose() * data_.R_world[c.segment] * (c.point_segment - c.p_segment_link);
  Matrix6d T = Matrix6d::Zero();
  T.topLeftCorner<3, 3>() = R_world_link.transpose();
  T.bottomRightCorner<3, 3>() = R_world_link.transpose();
  T.bottomLeftCorner<3, 3>() = skew(lever) * R_world_link.transpose();
  const Vector6d W = T * F;
  e.force = W.head<3>();
  e.moment = W.tail<3>();
  if (uncertainty_) {
    const Eigen::MatrixXd P = T.leftCols(c.rows) * A_.topRows(c.rows);
    e.covariance.noalias() = P * var_js_.asDiagonal() * P.transpose();
  }
}

// The contacts that can be the detected one: those on its link (or beyond joints a point
// force through their axes cannot load); failing any, the 6-D ones beyond it whose
// wrench fits. A 6-D wrench on a 7-joint arm reproduces most efforts within the
// thresholds: it is the candidate of last resort, not beside one that needs no such
// assumption. The others report no wrench.
void ExternalEffort::chooseActive() {
  const bool specific =
      std::find(explained_.begin(), explained_.end(), Explains::kYes) != explained_.end();
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    ContactEstimate& e = contacts_[k];
    e.active = explained_[k] == Explains::kYes || (!specific && fit_[k]);
    if (e.active) continue;
    e.force.setZero();  // the Jacobian's figures stay: the diagnostics' conditioning
    e.moment.setZero();
    e.covariance.setZero();
  }
}

void ExternalEffort::keepCalibrationSample() {
  const std::size_t n = published_.size();
  if (calib_seen_++ % calib_stride_ != 0) return;
  if (calib_rows_ == kCalibrationSamples) {  // full: keep every other sample
    for (int r = 0; r < kCalibrationSamples / 2; ++r)
      std::copy_n(calib_.begin() + static_cast<long>(2 * r * n), n,
                  calib_.begin() + static_cast<long>(r * n));
    calib_rows_ = kCalibrationSamples / 2;
    calib_stride_ *= 2;
    if ((calib_seen_ - 1) % calib_stride_ != 0) return;
  }
  const std::vector<double>& ext = external();
  std::copy(ext.begin(), ext.end(), calib_.begin() + static_cast<long>(calib_rows_ * n));
  ++calib_rows_;
}

// sigma of the first m values of calib_scratch_ (each |tau_ext|): the median gives a
// robust sigma, 1.4826 median; the RMS of the values within kInlierSigmas of it is the
// sigma returned when larger: a Gaussian's own (nothing of it lies beyond), and the
// heavier tails of the model error the free motion carries (the observer's on the Panda:
// peaks 4.5 times its RMS) kept, while a transient's or a jolt's samples are dropped.
double ExternalEffort::robustSigma(int m) {
  if (m == 0) return 0.0;
  const auto mid = calib_scratch_.begin() + m / 2;
  std::nth_element(calib_scratch_.begin(), mid, calib_scratch_.begin() + m);
  const double robust = kMadToSigma * *mid;
  double sum = 0.0;
  int inliers = 0;
  for (int r = 0; r < m; ++r)
    if (calib_scratch_[r] <= kInlierSigmas * robust) {
      sum += calib_scratch_[r] * calib_scratch_[r];
      ++inliers;
    }
  return std::max(robust, std::sqrt(sum / std::max(1, inliers)));
}

// The noise calibration after a start or a reset: the first settle_ s are the filters'
// transient and left out; the next calibration_time s give each joint's sigma
// (robustSigma: a few outliers, such as a filter's jolt after a lost message, move a
// median little and an RMS much). True once
// the thresholds are set. Allocates nothing.
bool ExternalEffort::calibrate(double t) {
  if (calibrated_) return true;
  if (!have_start_) {
    have_start_ = true;
    t_start_ = t;
  }
  if (t - t_start_ < settle_) return false;
  keepCalibrationSample();
  if (t - t_start_ < settle_ + config_.calibration_time) return false;
  const std::size_t n = published_.size();
  for (std::size_t i = 0; i < n; ++i) {
    int m = 0;
    for (int r = 0; r < calib_rows_; ++r) {
      const double v = calib_[static_cast<std::size_t>(r) * n + i];
      if (std::isfinite(v)) calib_scratch_[m++] = std::abs(v);
    }
    threshold_[i] = std::max(abs_threshold_[i], config_.noise_multiple * robustSigma(m));
  }
  calibrated_ = true;
  return false;
}

void ExternalEffort::detect(double t) {
  started_ = ended_ = changed_ = false;
  if (!calibrate(t)) return;
  const std::vector<double>& ext = external();
  const std::size_t n = published_.size();
  bool over = false, above_release = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(threshold_[i] > 0.0) || !std::isfinite(ext[i])) continue;
    // A joint is loaded from when it goes over its threshold until it falls below
    // release_fraction of it, as the contact is.
    const double m = std::abs(ext[i]);
    const bool above = m >= config_.release_fraction * threshold_[i];
    loaded_[i] = m > threshold_[i] || (loaded_[i] && above);
    over = over || m > threshold_[i];
    above_release = above_release || above;
    if (loaded_[i]) last_loaded_[i] = t;
  }
  if (!in_contact_ && over) {
    in_contact_ = started_ = true;
  } else if (in_contact_ && !above_release) {
    in_contact_ = false;
    ended_ = true;
  }
  // A contact on link k loads joints 1..k only: the contact's joint is the most distal one
  // loaded within link_window, re-evaluated while some joint is over its threshold (not
  // while the contact fades: its distal joints, nearer their thresholds, fade first).
  if (!in_contact_ || !over) return;
  int joint = -1;
  for (std::size_t i = 0; i < n; ++i)
    if (t - last_loaded_[i] <= config_.link_window &&
        (joint < 0 || depth_[i] > depth_[static_cast<std::size_t>(joint)]))
      joint = static_cast<int>(i);
  if (joint < 0 || (!started_ && joint == contact_index_)) return;
  changed_ = !started_;
  contact_index_ = joint;
  contact_joint_ = model_.joint_name[published_[static_cast<std::size_t>(joint)]];
  contact_link_ = model_.link_name[published_[static_cast<std::size_t>(joint)]];
}

}  // namespace jle
