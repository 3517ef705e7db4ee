// Covariance of the joint wrenches the Estimator publishes (docs/uncertainty.md).
//
// The wrench y_i of segment i (force, moment: child frame, about the joint origin)
// depends on
//  - each coordinate's estimate e_j = (q, qd, qdd)_j, whose noise has the covariance
//    sigma^2 G (G the filter's noise gain), independent between coordinates;
//  - the filtered wrench inputs (noise sigma^2 G_00 per component, independent);
//  - the inertial parameters of each segment (independent between segments).
// These are independent of each other, so
//    Cov(y_i) = sum_j J_ij sigma^2 G J_ij^T + sum_{k in subtree(i)} X_ik C_k X_ik^T,
// with J_ij = d y_i / d e_j and C_k the covariance of segment k's own terms (its
// inertial wrench and the inputs acting on it) carried to i by the force transform X_ik.
// y is linear in qdd, in the inputs and in the mass and inertia: those parts are exact.
// Its dependence on q and qd (and on the centre of mass) is linearised at the estimate.
#include <joint_load_estimator/estimator.hpp>

#include <joint_load_estimator/kinematics.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jle {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

// X C X^T for the force transform X = [R 0; [r]R R] that carries a wrench (f, n about
// the origin of frame B) into frame A about A's origin, B at orientation R, origin r in A.
// Done by 3x3 blocks: a quarter of the work of the 6x6 products.
void addForceCongruence(const Eigen::Matrix3d& R, const Eigen::Vector3d& r, const Matrix6& C,
                        Matrix6& out) {
  // Y = R_blockdiag C R_blockdiag^T, then out += T Y T^T with T = [I 0; [r] I].
  Matrix6 Y;
  Y.topLeftCorner<3, 3>().noalias() = R * C.topLeftCorner<3, 3>() * R.transpose();
  Y.topRightCorner<3, 3>().noalias() = R * C.topRightCorner<3, 3>() * R.transpose();
  Y.bottomRightCorner<3, 3>().noalias() = R * C.bottomRightCorner<3, 3>() * R.transpose();
  Y.bottomLeftCorner<3, 3>() = Y.topRightCorner<3, 3>().transpose();
  const Eigen::Matrix3d S = skew(r);
  // T Y T^T = [A, A S^T + B; S A + B^T, S A S^T + S B + B^T S^T + D], Y = [A B; B^T D].
  const Eigen::Matrix3d SA = S * Y.topLeftCorner<3, 3>();
  const Eigen::Matrix3d SB = S * Y.topRightCorner<3, 3>();
  out.topLeftCorner<3, 3>() += Y.topLeftCorner<3, 3>();
  const Eigen::Matrix3d lower = SA + Y.bottomLeftCorner<3, 3>();
  out.bottomLeftCorner<3, 3>() += lower;
  out.topRightCorner<3, 3>() += lower.transpose();
  out.bottomRightCorner<3, 3>().noalias() += SA * S.transpose();
  out.bottomRightCorner<3, 3>() += SB + SB.transpose() + Y.bottomRightCorner<3, 3>();
}

// The wrench (f, n about B's origin, B frame) in A about A's origin.
Vector6 forceToParent(const Eigen::Matrix3d& R, const Eigen::Vector3d& r, const Vector6& w) {
  Vector6 out;
  out.head<3>().noalias() = R * w.head<3>();
  out.tail<3>().noalias() = R * w.tail<3>();
  out.tail<3>() += r.cross(out.head<3>());
  return out;
}

// Spatial inertia of a segment about its origin, in its frame: the acceleration
// (linear at the origin, angular) to the wrench (f, n about the origin).
Matrix6 spatialInertia(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& I_com) {
  const Eigen::Matrix3d C = skew(c);
  Matrix6 I;
  I.topLeftCorner<3, 3>() = m * Eigen::Matrix3d::Identity();
  I.topRightCorner<3, 3>() = -m * C;
  I.bottomLeftCorner<3, 3>() = m * C;
  I.bottomRightCorner<3, 3>() = I_com - m * C * C;  // [c]^T [c] = -[c][c]
  return I;
}

void checkNoise(double value, const std::string& name) {
  if (!(value >= 0.0) || !std::isfinite(value))
    throw std::invalid_argument(name + " must be finite and non-negative");
}

}  // namespace

void Estimator::setUpCovariance() {
  const UncertaintyConfig& u = config_.uncertainty;
  checkNoise(u.position_noise, "uncertainty.position_noise");
  checkNoise(u.mass_fraction, "uncertainty.mass_fraction");
  checkNoise(u.com_offset, "uncertainty.com_offset");
  checkNoise(u.inertia_fraction, "uncertainty.inertia_fraction");
  for (const WrenchInputConfig& c : config_.wrenches) {
    checkNoise(c.force_noise, "wrench input '" + c.name + "': force_noise");
    checkNoise(c.moment_noise, "wrench input '" + c.name + "': moment_noise");
  }
  const int n = model_.nsegments();
  const std::size_t ns = static_cast<std::size_t>(n);
  covariance_.assign(ns, Matrix6::Zero());
  if (!u.enabled) return;
  composite_.assign(ns, Matrix6::Zero());
  local_.assign(ns, Matrix6::Zero());
  jacobian_.assign(ns, Eigen::Matrix<double, 6, 3>::Zero());
  motion_.assign(ns, Vector6::Zero());
  // Segments are numbered depth first: each subtree is a range of indices.
  subtree_end_.resize(ns);
  for (int i = 0; i < n; ++i) subtree_end_[i] = i + 1;
  for (int i = n - 1; i > 0; --i)
    subtree_end_[model_.parent[i]] = std::max(subtree_end_[model_.parent[i]], subtree_end_[i]);
  for (int i = 0; i < n; ++i)
    for (int k = i + 1; k < subtree_end_[i]; ++k)
      if (model_.parent[k] < i)
        throw std::logic_error("covariance: segments are not numbered depth first");
  in_dynamics_.assign(ns, 0);
  for (int i : dynamics_segments_) in_dynamics_[i] = 1;
  coordinate_segments_.assign(static_cast<std::size_t>(model_.nq), {});
  for (int i : kinematics_segments_)
    if (model_.coordinate[i] >= 0 && isMoving(model_.joint_type[i]))
      coordinate_segments_[model_.coordinate[i]].push_back(i);
  affected_.assign(static_cast<std::size_t>(model_.nq), {});
  std::vector<char> mark(ns);
  for (int j = 0; j < model_.nq; ++j) {
    mark.assign(ns, 0);
    for (int s : coordinate_segments_[j]) {
      for (int k = s; k < subtree_end_[s]; ++k) mark[k] = 1;
      for (int p = model_.parent[s]; p >= 0; p = model_.parent[p]) mark[p] = 1;
    }
    for (int i : dynamics_segments_)
      if (mark[i]) affected_[j].push_back(i);
  }
  q_pert_ = q_;
  qd_pert_ = qd_;
}

void Estimator::loadsPass(Data<double>& data, const VectorX<double>& q, const VectorX<double>& qd,
                          const BaseState<double>& base_state) {
  forwardKinematics(model_, data, q, qd, qdd_, config_.gravity_world, base_state,
                    kinematics_segments_, false);
  for (std::size_t k = 0; k < inputs_.size(); ++k) {
    if (!inputs_[k].needed) continue;
    const int c = wrench_channel_ + 6 * static_cast<int>(k);
    const Eigen::Vector3d f(bank_.value(c), bank_.value(c + 1), bank_.value(c + 2));
    const Eigen::Vector3d m(bank_.value(c + 3), bank_.value(c + 4), bank_.value(c + 5));
    addExternalWrench(model_, data, inputs_[k].frame, f, m, WrenchFrame::kLocal);
  }
  inverseDynamics(model_, data, dynamics_segments_);
}

void Estimator::computeCovariance(const BaseState<double>& base_state) {
  const UncertaintyConfig& u = config_.uncertainty;
  // The kinematics in double: data_ itself, or a double pass beside the float one.
  if (config_.precision == Precision::kFloat) loadsPass(cov_nominal_, q_, qd_, base_state);
  const Data<double>& nom = config_.precision == Precision::kFloat ? cov_nominal_ : data_;
  const Eigen::Matrix3d G = bank_.noiseGain();
  for (int i : dynamics_segments_) {
    covariance_[i].setZero();
    local_[i].setZero();
  }

  // The state part, coordinate by coordinate.
  const double var_q = u.position_noise * u.position_noise;
  if (var_q > 0.0) {
    // Composite inertia of each subtree about its joint origin (the CRBA recursion):
    // what a rigid acceleration of the subtree costs in joint wrench.
    for (int i : dynamics_segments_)
      composite_[i] = spatialInertia(model_.mass[i], model_.com[i], model_.inertia_com[i]);
    for (auto it = dynamics_segments_.rbegin(); it != dynamics_segments_.rend(); ++it) {
      const int i = *it, p = model_.parent[i];
      if (p >= 0 && in_dynamics_[p])
        addForceCongruence(nom.R_parent_child[i], nom.p_parent_child[i], composite_[i],
                           composite_[p]);
    }
    const Eigen::Matrix3d Sigma = var_q * G;
    const double var_qdd = var_q * G(2, 2);
    for (int j = 0; j < model_.nq; ++j) {
      if (coordinate_segments_[j].empty()) continue;
      const std::vector<int>& affected = affected_[j];
      for (int i : affected) jacobian_[i].setZero();
      // d y / d qdd_j, exact: qdd_j accelerates each driven subtree rigidly (no velocity
      // changes), which costs the composite inertia times that acceleration below the
      // joint and is passed on unchanged (transformed) above it.
      for (int s : coordinate_segments_[j]) {
        Vector6 S = Vector6::Zero();
        if (model_.joint_type[s] == JointType::kRevolute)
          S.tail<3>() = model_.multiplier[s] * model_.axis[s];
        else
          S.head<3>() = model_.multiplier[s] * model_.axis[s];
        motion_[s] = S;
        for (int k = s + 1; k < subtree_end_[s]; ++k) {
          const Vector6& mp = motion_[model_.parent[k]];
          const Eigen::Matrix3d& R = nom.R_parent_child[k];
          const Eigen::Vector3d& r = nom.p_parent_child[k];
          motion_[k].tail<3>().noalias() = R.transpose() * mp.tail<3>();
          motion_[k].head<3>().noalias() = R.transpose() * (mp.head<3>() + mp.tail<3>().cross(r));
        }
        for (int k = s; k < subtree_end_[s]; ++k)
          if (in_dynamics_[k]) jacobian_[k].col(2).noalias() += composite_[k] * motion_[k];
        if (in_dynamics_[s]) {
          Vector6 w = composite_[s] * S;
          for (int c = s, p = model_.parent[s]; p >= 0 && in_dynamics_[p];
               c = p, p = model_.parent[p]) {
            w = forceToParent(nom.R_parent_child[c], nom.p_parent_child[c], w);
            jacobian_[p].col(2) += w;
          }
        }
      }
      if (u.linearize_state) {
        // d y / d q_j and d y / d qd_j: forward differences of the loads. The step
        // leaves a relative error of about h times the curvature over the slope (1e-6
        // for angles of order 1) and a rounding error of eps |y| / h (1e-10 |y|).
        constexpr double h = 1e-6;  // [rad or m, rad/s or m/s]
        q_pert_ = q_;
        q_pert_[j] += h;
        loadsPass(cov_data_, q_pert_, qd_, base_state);
        for (int i : affected) {
          jacobian_[i].col(0).head<3>() = (cov_data_.force[i] - nom.force[i]) / h;
          jacobian_[i].col(0).tail<3>() = (cov_data_.moment[i] - nom.moment[i]) / h;
        }
        qd_pert_ = qd_;
        qd_pert_[j] += h;
        loadsPass(cov_data_, q_, qd_pert_, base_state);
        for (int i : affected) {
          jacobian_[i].col(1).head<3>() = (cov_data_.force[i] - nom.force[i]) / h;
          jacobian_[i].col(1).tail<3>() = (cov_data_.moment[i] - nom.moment[i]) / h;
        }
        for (int i : affected) {
          const Eigen::Matrix<double, 6, 3>& J = jacobian_[i];
          const Eigen::Matrix<double, 6, 3> JS = J * Sigma;
          if (u.diagonal_only)
            covariance_[i].diagonal() += JS.cwiseProduct(J).rowwise().sum();
          else
            covariance_[i].noalias() += JS * J.transpose();
        }
      } else {
        for (int i : affected) {
          const Vector6 d = jacobian_[i].col(2);
          if (u.diagonal_only)
            covariance_[i].diagonal() += var_qdd * d.cwiseAbs2();
          else
            covariance_[i].noalias() += var_qdd * d * d.transpose();
        }
      }
    }
  }

  // Each segment's own terms: the wrench inputs acting on it and its inertial parameters.
  bool any_local = false;
  const double g00 = G(0, 0);  // the inputs are filtered like the positions (value output)
  for (std::size_t k = 0; k < inputs_.size(); ++k) {
    const WrenchInputConfig& c = inputs_[k].config;
    if (!inputs_[k].needed || (c.force_noise == 0.0 && c.moment_noise == 0.0)) continue;
    const Frame<double>& fr = model_.frames[inputs_[k].frame];
    Matrix6 D = Matrix6::Zero();
    D.diagonal() << Eigen::Vector3d::Constant(c.force_noise * c.force_noise * g00),
        Eigen::Vector3d::Constant(c.moment_noise * c.moment_noise * g00);
    addForceCongruence(fr.R_segment_frame, fr.p_segment_frame, D, local_[fr.segment]);
    any_local = true;
  }
  if (u.mass_fraction > 0.0 || u.com_offset > 0.0 || u.inertia_fraction > 0.0) {
    any_local = true;
    for (int i : dynamics_segments_) {
      const double m = model_.mass[i];
      const Eigen::Vector3d& c = model_.com[i];
      const Eigen::Vector3d& w = nom.omega[i];
      const Eigen::Vector3d& al = nom.alpha[i];
      const Eigen::Vector3d a_com = nom.acc[i] + al.cross(c) + w.cross(w.cross(c));
      Vector6 d;
      if (u.mass_fraction > 0.0 && m > 0.0) {  // exact: the loads are linear in m
        d << a_com, c.cross(a_com);
        local_[i].noalias() += (u.mass_fraction * u.mass_fraction * m * m) * d * d.transpose();
      }
      if (u.com_offset > 0.0 && m > 0.0) {  // linearised: the moment is quadratic in c
        for (int axis = 0; axis < 3; ++axis) {
          const Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
          const Eigen::Vector3d df = m * (al.cross(e) + w.cross(w.cross(e)));
          d << df, e.cross(m * a_com) + c.cross(df);
          local_[i].noalias() += (u.com_offset * u.com_offset) * d * d.transpose();
        }
      }
      if (u.inertia_fraction > 0.0) {  // exact: linear in the tensor's scale
        const Eigen::Matrix3d& I = model_.inertia_com[i];
        Eigen::Vector3d dn = I * al;
        if (model_.gyroscopic[i]) dn += w.cross(I * w);
        d << Eigen::Vector3d::Zero(), dn;
        local_[i].noalias() += (u.inertia_fraction * u.inertia_fraction) * d * d.transpose();
      }
    }
  }
  if (any_local) {
    // Up the tree: each segment's wrench carries the covariance of its whole subtree.
    for (auto it = dynamics_segments_.rbegin(); it != dynamics_segments_.rend(); ++it) {
      const int i = *it, p = model_.parent[i];
      if (u.diagonal_only)
        covariance_[i].diagonal() += local_[i].diagonal();
      else
        covariance_[i] += local_[i];
      if (p >= 0 && in_dynamics_[p])
        addForceCongruence(nom.R_parent_child[i], nom.p_parent_child[i], local_[i], local_[p]);
    }
  }
}

double Estimator::effortVariance(int segment) const {
  const Matrix6& C = covariance_[static_cast<std::size_t>(segment)];
  const Eigen::Vector3d& u = model_.axis[static_cast<std::size_t>(segment)];
  switch (model_.joint_type[static_cast<std::size_t>(segment)]) {
    case JointType::kRevolute: return u.dot(C.bottomRightCorner<3, 3>() * u);
    case JointType::kPrismatic: return u.dot(C.topLeftCorner<3, 3>() * u);
    default: return 0.0;
  }
}

}  // namespace jle
