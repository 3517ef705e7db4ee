// Covariance of the joint wrenches the Estimator publishes (docs/uncertainty.md).
//
// The wrench y_i of segment i (force, moment: child frame, about the joint origin)
// depends on
//  - each coordinate's estimate e_j = (q, qd, qdd)_j, whose noise has the covariance
//    Sigma = sigma^2 G (G the filter's noise gain), independent between coordinates;
//  - the filtered wrench inputs (noise sigma^2 G_00 per component, independent);
//  - the inertial parameters of each segment (independent between segments).
// These are independent of each other, so
//    Cov(y_i) = sum_j J_ij Sigma J_ij^T + sum_{k in subtree(i)} X_ik C_k X_ik^T,
// with J_ij = d y_i / d e_j and C_k the covariance of segment k's own terms (its
// inertial wrench and the inputs acting on it) carried to i by the force transform X_ik.
//
// How J is obtained, in O(sum of subtree sizes) instead of O(nq n) passes:
//  - coordinate j moves only the subtree of its joint s: one forward-mode (tangent)
//    sweep of that subtree's kinematics and wrenches gives J_ij for every i in it,
//    exactly (the derivative of the recursion, not a difference);
//  - above s, e_j reaches y_i only through the joint wrench s hands to its parent:
//    J_ij = X_{i p(s)} g_j with g_j (6 x 3) its derivative, so those terms are the rank-3
//    covariance g_j Sigma g_j^T entering p(s), carried up with the C_k above (one
//    congruence per segment for all coordinates together).
// Sigma is factored once (Sigma = F F^T) and the sweep is seeded with the columns of F,
// so each term is an outer product (J F)(J F)^T.
// y is linear in qdd, in the inputs and in the mass and inertia: those parts are exact;
// its dependence on q and qd (and on the centre of mass) is linearised at the estimate.
#include <joint_load_estimator/estimator.hpp>

#include <joint_load_estimator/kinematics.hpp>

#include <Eigen/Cholesky>

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

}  // namespace

void Estimator::setUpCovariance() {
  const UncertaintyConfig& u = config_.uncertainty;
  const int n = model_.nsegments();
  const std::size_t ns = static_cast<std::size_t>(n);
  covariance_.assign(ns, Matrix6::Zero());
  cov_history_ = 0;
  if (!u.enabled) return;
  if (u.period > 0.0) {
    for (auto* c : {&cov_last_, &cov_prev_, &cov_prev2_}) c->assign(ns, Matrix6::Zero());
  }
  local_.assign(ns, Matrix6::Zero());
  for (auto* t : {&t_w_, &t_al_, &t_acc_, &t_f_, &t_n_}) t->assign(ns, Eigen::Matrix3d::Zero());
  jacobian_.assign(ns, Eigen::Matrix<double, 6, 3>::Zero());
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
  in_kinematics_.assign(ns, 0);
  for (int i : kinematics_segments_) in_kinematics_[i] = 1;
  sweep_mark_.assign(ns, 0);
  // Per coordinate: the segments it moves (the subtrees of the joints it drives, which
  // the loads need), and, when it drives several disjoint subtrees (mimic joints), the
  // computed segments above them, which see the sum of their effects.
  const std::size_t nq = static_cast<std::size_t>(model_.nq);
  sweep_.assign(nq, {});
  sweep_ancestors_.assign(nq, {});
  single_root_.assign(nq, 1);
  std::vector<char> mark(ns);
  for (int j = 0; j < model_.nq; ++j) {
    mark.assign(ns, 0);
    bool needed = false;
    for (int s : kinematics_segments_) {
      if (model_.coordinate[s] != j || !isMoving(model_.joint_type[s])) continue;
      for (int k = s; k < subtree_end_[s]; ++k) {
        mark[k] = in_kinematics_[k];
        needed = needed || in_dynamics_[k];
      }
    }
    if (!needed) continue;  // moves nothing whose loads are computed
    int roots = 0;
    for (int k = 0; k < n; ++k) {
      if (!mark[k]) continue;
      sweep_[j].push_back(k);
      if (model_.parent[k] < 0 || !mark[model_.parent[k]]) ++roots;
    }
    single_root_[j] = roots == 1;
    if (roots > 1) {
      std::vector<char> above(ns, 0);
      for (int k : sweep_[j])
        if (model_.parent[k] >= 0 && !mark[model_.parent[k]])
          for (int p = model_.parent[k]; p >= 0; p = model_.parent[p]) above[p] = 1;
      for (int k = n - 1; k >= 0; --k)
        if (above[k] && in_dynamics_[k]) sweep_ancestors_[j].push_back(k);
    }
  }
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

// One coordinate's sweep: the derivatives of the kinematics and of the joint wrenches of
// every segment it moves, along the NC noise directions of the columns of F (rows: q,
// qd, qdd; kState false: the q-ddot direction only, one column). Each computed segment
// of the sweep gets its outer product; the wrench handed out of the sweep goes to the
// parent's local_ (one root) or is carried up explicitly (several roots: mimics).
template <bool kState>
#if defined(__GNUC__)
// Inline every small fixed-size Eigen product (GCC leaves many out of line): 2x faster.
__attribute__((flatten))
#endif
void Estimator::sweepCoordinate(int j, const Data<double>& nom,
                                const Eigen::Matrix<double, 3, kState ? 3 : 1>& F) {
  constexpr int NC = kState ? 3 : 1;
  using M = Eigen::Matrix<double, 3, NC>;
  using Row = Eigen::Matrix<double, 1, NC>;
  using J6 = Eigen::Matrix<double, 6, NC>;
  const bool diagonal = config_.uncertainty.diagonal_only;
  const std::vector<int>& sweep = sweep_[j];
  const int tag = j + 1;
  for (int k : sweep) sweep_mark_[k] = tag;

  // Forward: the tangent of omega, alpha and the origin acceleration, segment frame.
  for (int k : sweep) {
    const int p = model_.parent[k];
    const Eigen::Matrix3d& R = nom.R_parent_child[k];
    const Eigen::Vector3d& r = nom.p_parent_child[k];
    const Eigen::Vector3d& u = model_.axis[k];
    const double qd_k = nom.qd[k];
    auto w = t_w_[k].leftCols<NC>();
    auto al = t_al_[k].leftCols<NC>();
    auto acc = t_acc_[k].leftCols<NC>();
    if (p >= 0 && sweep_mark_[p] == tag) {
      const auto w_p = t_w_[p].leftCols<NC>();
      const auto al_p = t_al_[p].leftCols<NC>();
      M a_point = t_acc_[p].leftCols<NC>();
      a_point.noalias() -= skew(r) * al_p;  // al_p x r
      if (kState) {
        const Eigen::Vector3d& wn_p = nom.omega[p];
        // d(w x (w x r)) = dw x (w x r) + w x (dw x r)
        a_point.noalias() -= (skew(wn_p.cross(r)) + skew(wn_p) * skew(r)) * w_p;
        w.noalias() = R.transpose() * w_p;
      } else {
        w.setZero();
      }
      al.noalias() = R.transpose() * al_p;
      acc.noalias() = R.transpose() * a_point;
    } else {
      w.setZero();
      al.setZero();
      acc.setZero();
    }
    const bool driven = model_.coordinate[k] == j && isMoving(model_.joint_type[k]);
    const double mu = model_.multiplier[k];
    const Eigen::Vector3d& wn = nom.omega[k];
    if (model_.joint_type[k] == JointType::kRevolute) {
      if (driven) {
        // The joint rotation R(theta) enters as R^T: d(R^T x)/d theta = -u x R^T x.
        const Row a = mu * F.row(0), b = mu * F.row(1), c = mu * F.row(2);
        if (kState) {
          const Eigen::Vector3d Rt_wp = wn - u * qd_k;
          w.noalias() += (-u.cross(Rt_wp)) * a + u * b;
          const Eigen::Vector3d Rt_alp = nom.alpha[k] - u * nom.qdd[k] - wn.cross(u * qd_k);
          al.noalias() += (-u.cross(Rt_alp)) * a + wn.cross(u) * b;
          acc.noalias() += (-u.cross(nom.acc[k])) * a;
        }
        al.noalias() += u * c;
      }
      if (kState && qd_k != 0.0) al.noalias() -= skew(u * qd_k) * w;  // dw x u qd
    } else if (model_.joint_type[k] == JointType::kPrismatic) {
      if (driven) {
        const Row a = mu * F.row(0), b = mu * F.row(1), c = mu * F.row(2);
        if (kState) {
          const Eigen::Vector3d& aln = nom.alpha[k];
          acc.noalias() += (aln.cross(u) + wn.cross(wn.cross(u))) * a + (2.0 * wn.cross(u)) * b;
        }
        acc.noalias() += u * c;
      }
      if (kState && qd_k != 0.0) acc.noalias() -= skew(2.0 * qd_k * u) * w;  // 2 dw x u qd
    }
    t_f_[k].leftCols<NC>().setZero();
    t_n_[k].leftCols<NC>().setZero();
  }

  // Backward: the tangent of each joint wrench, its outer product, handed to the parent.
  const std::vector<int>& ancestors = sweep_ancestors_[j];
  for (int a : ancestors) jacobian_[a].leftCols<NC>().setZero();
  for (auto it = sweep.rbegin(); it != sweep.rend(); ++it) {
    const int k = *it;
    if (!in_dynamics_[k]) continue;
    auto f = t_f_[k].leftCols<NC>();
    auto nmo = t_n_[k].leftCols<NC>();
    if (model_.has_inertia[k]) {
      const double m = model_.mass[k];
      const Eigen::Vector3d& c = model_.com[k];
      const Eigen::Matrix3d& I = model_.inertia_com[k];
      const Eigen::Matrix3d C = skew(c);
      const auto al = t_al_[k].leftCols<NC>();
      M dacom = t_acc_[k].leftCols<NC>();
      dacom.noalias() -= C * al;
      if (kState) {
        const Eigen::Vector3d& wn = nom.omega[k];
        const auto w = t_w_[k].leftCols<NC>();
        dacom.noalias() -= (skew(wn.cross(c)) + skew(wn) * C) * w;
        if (model_.gyroscopic[k]) nmo.noalias() += (skew(wn) * I - skew(I * wn)) * w;
      }
      const M df = m * dacom;
      f += df;
      nmo.noalias() += I * al;
      nmo.noalias() += C * df;
    }
    J6 Jk;
    Jk << f, nmo;
    if (diagonal)
      covariance_[k].diagonal() += Jk.cwiseAbs2().rowwise().sum();
    else
      covariance_[k].noalias() += Jk * Jk.transpose();
    const int p = model_.parent[k];
    if (p < 0 || !in_dynamics_[p]) continue;
    // The wrench handed to the parent, X (f, n), and its change with the joint's own
    // coordinate: d(R f)/d theta = R (u x f) (revolute); d(r x R f)/d d = R (u x f) (prismatic).
    const Eigen::Matrix3d& R = nom.R_parent_child[k];
    const Eigen::Vector3d& r = nom.p_parent_child[k];
    M f_p = R * f;
    M n_p = R * nmo;
    if (kState && model_.coordinate[k] == j && isMoving(model_.joint_type[k])) {
      const Row a = model_.multiplier[k] * F.row(0);
      const Eigen::Vector3d& u = model_.axis[k];
      if (model_.joint_type[k] == JointType::kRevolute) {
        f_p.noalias() += (R * u.cross(nom.force[k])) * a;
        n_p.noalias() += (R * u.cross(nom.moment[k])) * a;
      } else {
        n_p.noalias() += (R * u.cross(nom.force[k])) * a;
      }
    }
    n_p.noalias() += skew(r) * f_p;
    if (sweep_mark_[p] == tag) {
      t_f_[p].leftCols<NC>() += f_p;
      t_n_[p].leftCols<NC>() += n_p;
    } else if (single_root_[j]) {
      J6 g;
      g << f_p, n_p;
      local_[p].noalias() += g * g.transpose();
    } else {
      jacobian_[p].topLeftCorner<3, NC>() += f_p;
      jacobian_[p].bottomLeftCorner<3, NC>() += n_p;
    }
  }
  // Several roots (a mimic driving disjoint subtrees): their effects add before the
  // outer product, so the segments above are done here.
  for (int a : ancestors) {
    const J6 Ja = jacobian_[a].leftCols<NC>();
    if (diagonal)
      covariance_[a].diagonal() += Ja.cwiseAbs2().rowwise().sum();
    else
      covariance_[a].noalias() += Ja * Ja.transpose();
    const int p = model_.parent[a];
    if (p < 0 || !in_dynamics_[p]) continue;
    const Eigen::Matrix3d& R = nom.R_parent_child[a];
    const M f_p = R * Ja.template topRows<3>();
    jacobian_[p].topLeftCorner<3, NC>() += f_p;
    jacobian_[p].bottomLeftCorner<3, NC>().noalias() += R * Ja.template bottomRows<3>();
    jacobian_[p].bottomLeftCorner<3, NC>().noalias() += skew(nom.p_parent_child[a]) * f_p;
  }
  for (int k : sweep) sweep_mark_[k] = 0;
}

// uncertainty.period, between two computations: the quadratic through the last three
// computed covariances C_0, C_1, C_2 at their stamps t_0 > t_1 > t_2 (Lagrange, at any
// spacing), at the stamp t: with x = t - t_0, a = t_1 - t_0, b = t_2 - t_0,
//    C = (x-a)(x-b)/(a b) C_0 + x(x-b)/(a (a-b)) C_1 + x(x-a)/(b (b-a)) C_2
// (equal spacing h, s = x/h: (1+s)(2+s)/2 C_0 - s(2+s) C_1 + s(1+s)/2 C_2).
// The covariance is a smooth function of the state, so this is exact to third order in
// the time since t_0 (holding C_0: first order; the straight line through the last two:
// second order, which overshoots where a variance turns round near its minimum;
// docs/uncertainty.md measures the three). Elementwise, so as symmetric as the computed
// ones. A variance extrapolated below 0 is set to 0, and its row and column with it (no
// covariance without variance).
void Estimator::extrapolateCovariance(double t) {
  const double x = t - cov_time_[0], a = cov_time_[1] - cov_time_[0],
               b = cov_time_[2] - cov_time_[0];
  const double w0 = (x - a) * (x - b) / (a * b), w1 = x * (x - b) / (a * (a - b)),
               w2 = x * (x - a) / (b * (b - a));
  const bool diagonal = config_.uncertainty.diagonal_only;
  for (int i : dynamics_segments_) {
    Matrix6& out = covariance_[i];
    if (diagonal)
      out.diagonal() = w0 * cov_last_[i].diagonal() + w1 * cov_prev_[i].diagonal() +
                       w2 * cov_prev2_[i].diagonal();
    else
      out = w0 * cov_last_[i] + w1 * cov_prev_[i] + w2 * cov_prev2_[i];
    for (int r = 0; r < 6; ++r) {
      if (out(r, r) >= 0.0) continue;
      out.row(r).setZero();
      out.col(r).setZero();
    }
  }
}

namespace {

// Whether the noise gain G is within `tolerance` of G0, entry by entry relative to the
// standard deviations of G0 (an entry of G0 with a zero diagonal must stay exact).
bool sameNoiseGain(const Eigen::Matrix3d& G, const Eigen::Matrix3d& G0, double tolerance) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (!(std::abs(G(a, b) - G0(a, b)) <= tolerance * std::sqrt(G0(a, a) * G0(b, b))))
        return false;
  return true;
}

}  // namespace

void Estimator::computeCovariance(const BaseState<double>& base_state) {
  const UncertaintyConfig& u = config_.uncertainty;
  // uncertainty.period: computed once the stamp is a period past the last computed one;
  // in between, extrapolated from the last three (once there are three). A gap of more
  // than kGapPeriods periods (or a stamp not after the last) starts the history again:
  // the quadratic is not trusted that far.
  // "A period past" to a millionth of it: a stamp difference carries the rounding of the
  // double time axis, and 18 samples at 1 kHz should be 18 ms, not sometimes 19 samples.
  constexpr double kGapPeriods = 3.0, kSamePeriod = 1e-6;
  const double period = u.period;
  const double t = stamp_;
  if (period > 0.0) {
    const double since = t - cov_time_[0];
    if (cov_history_ > 0 && !(since > 0.0 && since <= kGapPeriods * period)) cov_history_ = 0;
    if (cov_history_ == 3 && since < (1.0 - kSamePeriod) * period) {
      if (sameNoiseGain(bank_.noiseGain(), cov_gain_, u.gain_tolerance)) {
        extrapolateCovariance(t);
        return;
      }
      cov_history_ = 0;  // the past covariances belong to another noise gain
    }
  }
  // The kinematics in double: data_ itself, or a double pass beside the float one.
  if (config_.precision == Precision::kFloat) loadsPass(cov_nominal_, q_, qd_, base_state);
  const Data<double>& nom = config_.precision == Precision::kFloat ? cov_nominal_ : data_;
  const Eigen::Matrix3d G = bank_.noiseGain();
  for (int i : dynamics_segments_) {
    covariance_[i].setZero();
    local_[i].setZero();
  }
  bool any_local = false;

  // The state part, coordinate by coordinate.
  const double var_q = u.position_noise * u.position_noise;
  if (var_q > 0.0) {
    any_local = true;
    if (u.linearize_state) {
      // Sigma = var_q G = F F^T (G may be singular: the Kalman filter's first sample).
      const Eigen::LDLT<Eigen::Matrix3d> ldlt(G);
      Eigen::Matrix3d F = ldlt.transpositionsP().transpose() * Eigen::Matrix3d(ldlt.matrixL());
      for (int c = 0; c < 3; ++c) F.col(c) *= std::sqrt(var_q * std::max(ldlt.vectorD()[c], 0.0));
      for (int j = 0; j < model_.nq; ++j)
        if (!sweep_[j].empty()) sweepCoordinate<true>(j, nom, F);
    } else {
      const Eigen::Vector3d F(0.0, 0.0, std::sqrt(var_q * G(2, 2)));
      for (int j = 0; j < model_.nq; ++j)
        if (!sweep_[j].empty()) sweepCoordinate<false>(j, nom, F);
    }
  }

  // Each segment's own terms: the wrench inputs acting on it and its inertial parameters.
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
  // The three the extrapolation starts from, a period apart: while the history fills
  // (after a start, a gap or a change of the noise gain), the samples in between are
  // computed but not kept, so that the quadratic never reaches far beyond its nodes.
  if (period > 0.0 && (cov_history_ == 0 || t - cov_time_[0] >= (1.0 - kSamePeriod) * period)) {
    cov_prev2_.swap(cov_prev_);
    cov_prev_.swap(cov_last_);
    for (int i : dynamics_segments_) cov_last_[i] = covariance_[i];
    cov_time_[2] = cov_time_[1];
    cov_time_[1] = cov_time_[0];
    cov_time_[0] = t;
    cov_gain_ = G;
    cov_history_ = std::min(cov_history_ + 1, 3);
  }
}

double Estimator::effortVariance(int segment) const {
  const Matrix6& C = covariance_[static_cast<std::size_t>(segment)];
  const Eigen::Vector3d& u = model_.axis[static_cast<std::size_t>(segment)];
  switch (model_.joint_type[static_cast<std::size_t>(segment)]) {
    case JointType::kRevolute: return std::max(0.0, u.dot(C.bottomRightCorner<3, 3>() * u));
    case JointType::kPrismatic: return std::max(0.0, u.dot(C.topLeftCorner<3, 3>() * u));
    default: return 0.0;
  }
}

}  // namespace jle
