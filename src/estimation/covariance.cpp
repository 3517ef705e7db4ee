// Covariance of the joint wrenches the Estimator publishes (docs/studies/uncertainty.md).
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
#include <joint_load_estimator/estimation/covariance.hpp>

#include <joint_load_estimator/estimation/estimator.hpp>  // UncertaintyConfig, WrenchInputConfig

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jle {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// uncertainty.period: a gap of more than kGapPeriods periods (or a stamp not after the
// last computed one) starts the history again: the quadratic is not trusted that far.
// "A period past" to a millionth of it (kSamePeriod): a stamp difference carries the
// rounding of the double time axis, and 18 samples at 1 kHz should be 18 ms, not
// sometimes 19 samples.
constexpr double kGapPeriods = 3.0, kSamePeriod = 1e-6;

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

// out += J J^T, or only its diagonal.
template <typename Jacobian>
void addOuterProduct(bool diagonal, const Jacobian& J, Matrix6& out) {
  if (diagonal)
    out.diagonal() += J.cwiseAbs2().rowwise().sum();
  else
    out.noalias() += J * J.transpose();
}

// Per segment: the end of its subtree, [i, end). Segments are numbered depth first: each
// subtree is a range of indices.
std::vector<int> subtreeEnds(const Model<double>& model) {
  const int n = model.nsegments();
  std::vector<int> end(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) end[i] = i + 1;
  for (int i = n - 1; i > 0; --i) end[model.parent[i]] = std::max(end[model.parent[i]], end[i]);
  for (int i = 0; i < n; ++i)
    for (int k = i + 1; k < end[i]; ++k)
      if (model.parent[k] < i)
        throw std::logic_error("covariance: segments are not numbered depth first");
  return end;
}

std::vector<char> membership(int n, const std::vector<int>& segments) {
  std::vector<char> in(static_cast<std::size_t>(n), 0);
  for (int i : segments) in[i] = 1;
  return in;
}

// Coordinate j's sweep: the segments it moves (the subtrees of the joints it drives,
// which the loads need), and, when it drives several disjoint subtrees (mimic joints),
// the computed segments above them, which see the sum of their effects. `mark`: scratch.
void setUpSweep(const Model<double>& model, CovarianceModel& cm, int j, std::vector<char>& mark) {
  const int n = model.nsegments();
  mark.assign(mark.size(), 0);
  bool needed = false;
  for (int s : cm.kinematics_segments) {
    if (model.coordinate[s] != j || !isMoving(model.joint_type[s])) continue;
    for (int k = s; k < cm.subtree_end[s]; ++k) {
      mark[k] = cm.in_kinematics[k];
      needed = needed || cm.in_dynamics[k];
    }
  }
  if (!needed) return;  // moves nothing whose loads are computed
  int roots = 0;
  for (int k = 0; k < n; ++k) {
    if (!mark[k]) continue;
    cm.sweep[j].push_back(k);
    if (model.parent[k] < 0 || !mark[model.parent[k]]) ++roots;
  }
  cm.single_root[j] = roots == 1;
  if (roots <= 1) return;
  std::vector<char> above(mark.size(), 0);
  for (int k : cm.sweep[j])
    if (model.parent[k] >= 0 && !mark[model.parent[k]])
      for (int p = model.parent[k]; p >= 0; p = model.parent[p]) above[p] = 1;
  for (int k = n - 1; k >= 0; --k)
    if (above[k] && cm.in_dynamics[k]) cm.sweep_ancestors[j].push_back(k);
}

}  // namespace

CovarianceModel::CovarianceModel(const Model<double>& model, const UncertaintyConfig& uncertainty,
                                 const std::vector<WrenchInputConfig>& wrenches,
                                 const std::vector<int>& input_frames,
                                 const std::vector<int>& kinematics_segments,
                                 const std::vector<int>& dynamics_segments)
    : enabled(uncertainty.enabled),
      diagonal_only(uncertainty.diagonal_only),
      linearize_state(uncertainty.linearize_state),
      var_position(uncertainty.position_noise * uncertainty.position_noise),
      mass_fraction(uncertainty.mass_fraction),
      com_offset(uncertainty.com_offset),
      inertia_fraction(uncertainty.inertia_fraction),
      period(uncertainty.period),
      gain_tolerance(uncertainty.gain_tolerance),
      kinematics_segments(kinematics_segments),
      dynamics_segments(dynamics_segments) {
  // The noises are checked by validate(EstimatorConfig).
  if (!enabled) return;
  for (std::size_t k = 0; k < wrenches.size(); ++k) {
    const WrenchInputConfig& c = wrenches[k];
    if (input_frames[k] < 0 || (c.force_noise == 0.0 && c.moment_noise == 0.0)) continue;
    inputs.push_back(
        {input_frames[k], c.force_noise * c.force_noise, c.moment_noise * c.moment_noise});
  }
  const int n = model.nsegments();
  subtree_end = subtreeEnds(model);
  in_dynamics = membership(n, dynamics_segments);
  in_kinematics = membership(n, kinematics_segments);
  const std::size_t nq = static_cast<std::size_t>(model.nq);
  sweep.assign(nq, {});
  sweep_ancestors.assign(nq, {});
  single_root.assign(nq, 1);
  std::vector<char> mark(static_cast<std::size_t>(n));
  for (int j = 0; j < model.nq; ++j) setUpSweep(model, *this, j, mark);
}

CovarianceWorkspace::CovarianceWorkspace(const CovarianceModel& cm, int segments) {
  const std::size_t ns = static_cast<std::size_t>(segments);
  covariance.assign(ns, Matrix6::Zero());
  if (!cm.enabled) return;
  if (cm.period > 0.0)
    for (auto* c : {&last, &prev, &prev2}) c->assign(ns, Matrix6::Zero());
  local.assign(ns, Matrix6::Zero());
  for (auto* t : {&t_w, &t_al, &t_acc, &t_f, &t_n}) t->assign(ns, Eigen::Matrix3d::Zero());
  jacobian.assign(ns, Eigen::Matrix<double, 6, 3>::Zero());
  sweep_mark.assign(ns, 0);
}

namespace {

// One coordinate's sweep: the derivatives of the kinematics and of the joint wrenches of
// every segment it moves, along the NC noise directions of the columns of F (rows: q,
// qd, qdd; kState false: the q-ddot direction only, one column). Each computed segment
// of the sweep gets its outer product; the wrench handed out of the sweep goes to the
// parent's local (one root) or is carried up explicitly (several roots: mimics).
template <bool kState>
class Sweep {
 public:
  static constexpr int NC = kState ? 3 : 1;
  using M = Eigen::Matrix<double, 3, NC>;
  using Row = Eigen::Matrix<double, 1, NC>;
  using J6 = Eigen::Matrix<double, 6, NC>;

  Sweep(const CovarianceModel& cm, CovarianceWorkspace& ws, const Model<double>& model,
        const Data<double>& nom, int j, const M& F)
      : cm_(cm), ws_(ws), model_(model), nom_(nom), j_(j), tag_(j + 1), F_(F) {}

  void run();

 private:
  void forward(int k);
  void fromParent(int k);
  void jointTerms(int k, bool driven);
  void backward(int k);
  void inertialTangent(int k);
  void handToParent(int k);
  void ancestor(int a);

  const CovarianceModel& cm_;
  CovarianceWorkspace& ws_;
  const Model<double>& model_;
  const Data<double>& nom_;
  const int j_, tag_;
  const M& F_;
};

template <bool kState>
#if defined(__GNUC__)
// Inline every small fixed-size Eigen product (GCC leaves many out of line): 2x faster.
__attribute__((flatten))
#endif
void Sweep<kState>::run() {
  const std::vector<int>& sweep = cm_.sweep[j_];
  for (int k : sweep) ws_.sweep_mark[k] = tag_;
  // Forward: the tangent of omega, alpha and the origin acceleration, segment frame.
  for (int k : sweep) forward(k);
  // Backward: the tangent of each joint wrench, its outer product, handed to the parent.
  const std::vector<int>& ancestors = cm_.sweep_ancestors[j_];
  for (int a : ancestors) ws_.jacobian[a].leftCols<NC>().setZero();
  for (auto it = sweep.rbegin(); it != sweep.rend(); ++it) backward(*it);
  // Several roots (a mimic driving disjoint subtrees): their effects add before the
  // outer product, so the segments above are done here.
  for (int a : ancestors) ancestor(a);
  for (int k : sweep) ws_.sweep_mark[k] = 0;
}

template <bool kState>
void Sweep<kState>::forward(int k) {
  fromParent(k);
  const JointType type = model_.joint_type[k];
  if (type == JointType::kRevolute || type == JointType::kPrismatic)
    jointTerms(k, model_.coordinate[k] == j_ && isMoving(type));
  ws_.t_f[k].leftCols<NC>().setZero();
  ws_.t_n[k].leftCols<NC>().setZero();
}

// The tangents the parent's carry over to segment k (zero at a root of the sweep).
template <bool kState>
void Sweep<kState>::fromParent(int k) {
  const int p = model_.parent[k];
  auto w = ws_.t_w[k].leftCols<NC>();
  auto al = ws_.t_al[k].leftCols<NC>();
  auto acc = ws_.t_acc[k].leftCols<NC>();
  if (!(p >= 0 && ws_.sweep_mark[p] == tag_)) {
    w.setZero();
    al.setZero();
    acc.setZero();
    return;
  }
  const Eigen::Matrix3d& R = nom_.R_parent_child[k];
  const Eigen::Vector3d& r = nom_.p_parent_child[k];
  const auto w_p = ws_.t_w[p].leftCols<NC>();
  const auto al_p = ws_.t_al[p].leftCols<NC>();
  M a_point = ws_.t_acc[p].leftCols<NC>();
  a_point.noalias() -= skew(r) * al_p;  // al_p x r
  if (kState) {
    const Eigen::Vector3d& wn_p = nom_.omega[p];
    // d(w x (w x r)) = dw x (w x r) + w x (dw x r)
    a_point.noalias() -= (skew(wn_p.cross(r)) + skew(wn_p) * skew(r)) * w_p;
    w.noalias() = R.transpose() * w_p;
  } else {
    w.setZero();
  }
  al.noalias() = R.transpose() * al_p;
  acc.noalias() = R.transpose() * a_point;
}

// A revolute or prismatic joint's own terms: its coordinate's (driven) and its rate's.
template <bool kState>
void Sweep<kState>::jointTerms(int k, bool driven) {
  const bool revolute = model_.joint_type[k] == JointType::kRevolute;
  auto w = ws_.t_w[k].leftCols<NC>();
  auto al = ws_.t_al[k].leftCols<NC>();
  auto acc = ws_.t_acc[k].leftCols<NC>();
  const Eigen::Vector3d& u = model_.axis[k];
  const Eigen::Vector3d& wn = nom_.omega[k];
  const double qd_k = nom_.qd[k];
  if (driven) {
    const double mu = model_.multiplier[k];
    const Row a = mu * F_.row(0), b = mu * F_.row(1), c = mu * F_.row(2);
    if (kState && revolute) {
      // The joint rotation R(theta) enters as R^T: d(R^T x)/d theta = -u x R^T x.
      const Eigen::Vector3d Rt_wp = wn - u * qd_k;
      w.noalias() += (-u.cross(Rt_wp)) * a + u * b;
      const Eigen::Vector3d Rt_alp = nom_.alpha[k] - u * nom_.qdd[k] - wn.cross(u * qd_k);
      al.noalias() += (-u.cross(Rt_alp)) * a + wn.cross(u) * b;
      acc.noalias() += (-u.cross(nom_.acc[k])) * a;
    } else if (kState) {
      const Eigen::Vector3d& aln = nom_.alpha[k];
      acc.noalias() += (aln.cross(u) + wn.cross(wn.cross(u))) * a + (2.0 * wn.cross(u)) * b;
    }
    (revolute ? al : acc).noalias() += u * c;
  }
  if (!kState || qd_k == 0.0) return;
  if (revolute)
    al.noalias() -= skew(u * qd_k) * w;  // dw x u qd
  else
    acc.noalias() -= skew(2.0 * qd_k * u) * w;  // 2 dw x u qd
}

template <bool kState>
void Sweep<kState>::backward(int k) {
  if (!cm_.in_dynamics[k]) return;
  if (model_.has_inertia[k]) inertialTangent(k);
  J6 Jk;
  Jk << ws_.t_f[k].leftCols<NC>(), ws_.t_n[k].leftCols<NC>();
  addOuterProduct(cm_.diagonal_only, Jk, ws_.covariance[k]);
  const int p = model_.parent[k];
  if (p >= 0 && cm_.in_dynamics[p]) handToParent(k);
}

// Segment k's own inertial wrench, its tangent added to what its children handed it.
template <bool kState>
void Sweep<kState>::inertialTangent(int k) {
  auto f = ws_.t_f[k].leftCols<NC>();
  auto nmo = ws_.t_n[k].leftCols<NC>();
  const double m = model_.mass[k];
  const Eigen::Vector3d& c = model_.com[k];
  const Eigen::Matrix3d& I = model_.inertia_com[k];
  const Eigen::Matrix3d C = skew(c);
  const auto al = ws_.t_al[k].leftCols<NC>();
  M dacom = ws_.t_acc[k].leftCols<NC>();
  dacom.noalias() -= C * al;
  if (kState) {
    const Eigen::Vector3d& wn = nom_.omega[k];
    const auto w = ws_.t_w[k].leftCols<NC>();
    dacom.noalias() -= (skew(wn.cross(c)) + skew(wn) * C) * w;
    if (model_.gyroscopic[k]) nmo.noalias() += (skew(wn) * I - skew(I * wn)) * w;
  }
  const M df = m * dacom;
  f += df;
  nmo.noalias() += I * al;
  nmo.noalias() += C * df;
}

// The wrench handed to the parent, X (f, n), and its change with the joint's own
// coordinate: d(R f)/d theta = R (u x f) (revolute); d(r x R f)/d d = R (u x f) (prismatic).
template <bool kState>
void Sweep<kState>::handToParent(int k) {
  const int p = model_.parent[k];
  const Eigen::Matrix3d& R = nom_.R_parent_child[k];
  const Eigen::Vector3d& r = nom_.p_parent_child[k];
  M f_p = R * ws_.t_f[k].leftCols<NC>();
  M n_p = R * ws_.t_n[k].leftCols<NC>();
  if (kState && model_.coordinate[k] == j_ && isMoving(model_.joint_type[k])) {
    const Row a = model_.multiplier[k] * F_.row(0);
    const Eigen::Vector3d& u = model_.axis[k];
    if (model_.joint_type[k] == JointType::kRevolute) {
      f_p.noalias() += (R * u.cross(nom_.force[k])) * a;
      n_p.noalias() += (R * u.cross(nom_.moment[k])) * a;
    } else {
      n_p.noalias() += (R * u.cross(nom_.force[k])) * a;
    }
  }
  n_p.noalias() += skew(r) * f_p;
  if (ws_.sweep_mark[p] == tag_) {
    ws_.t_f[p].leftCols<NC>() += f_p;
    ws_.t_n[p].leftCols<NC>() += n_p;
  } else if (cm_.single_root[j_]) {
    J6 g;
    g << f_p, n_p;
    ws_.local[p].noalias() += g * g.transpose();
  } else {
    ws_.jacobian[p].topLeftCorner<3, NC>() += f_p;
    ws_.jacobian[p].bottomLeftCorner<3, NC>() += n_p;
  }
}

// A computed segment above a mimic's disjoint subtrees: the sum of their effects.
template <bool kState>
void Sweep<kState>::ancestor(int a) {
  const J6 Ja = ws_.jacobian[a].leftCols<NC>();
  addOuterProduct(cm_.diagonal_only, Ja, ws_.covariance[a]);
  const int p = model_.parent[a];
  if (p < 0 || !cm_.in_dynamics[p]) return;
  const Eigen::Matrix3d& R = nom_.R_parent_child[a];
  const M f_p = R * Ja.template topRows<3>();
  ws_.jacobian[p].topLeftCorner<3, NC>() += f_p;
  ws_.jacobian[p].bottomLeftCorner<3, NC>().noalias() += R * Ja.template bottomRows<3>();
  ws_.jacobian[p].bottomLeftCorner<3, NC>().noalias() += skew(nom_.p_parent_child[a]) * f_p;
}

// The state part, coordinate by coordinate (false: no position noise).
bool addStateTerms(const CovarianceModel& cm, CovarianceWorkspace& ws, const Model<double>& model,
                   const Data<double>& nom, const Eigen::Matrix3d& G) {
  const double var_q = cm.var_position;
  if (!(var_q > 0.0)) return false;
  if (cm.linearize_state) {
    // Sigma = var_q G = F F^T (G may be singular: the Kalman filter's first sample).
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(G);
    Eigen::Matrix3d F = ldlt.transpositionsP().transpose() * Eigen::Matrix3d(ldlt.matrixL());
    for (int c = 0; c < 3; ++c) F.col(c) *= std::sqrt(var_q * std::max(ldlt.vectorD()[c], 0.0));
    for (int j = 0; j < model.nq; ++j)
      if (!cm.sweep[j].empty()) Sweep<true>(cm, ws, model, nom, j, F).run();
  } else {
    const Eigen::Vector3d F(0.0, 0.0, std::sqrt(var_q * G(2, 2)));
    for (int j = 0; j < model.nq; ++j)
      if (!cm.sweep[j].empty()) Sweep<false>(cm, ws, model, nom, j, F).run();
  }
  return true;
}

// The wrench inputs acting on each segment, filtered like the positions (value output:
// g00 the noise gain of the value). False: no input with noise.
bool addInputTerms(const CovarianceModel& cm, CovarianceWorkspace& ws, const Model<double>& model,
                   double g00) {
  for (const CovarianceModel::InputNoise& in : cm.inputs) {
    const Frame<double>& fr = model.frames[in.frame];
    Matrix6 D = Matrix6::Zero();
    D.diagonal() << Eigen::Vector3d::Constant(in.var_force * g00),
        Eigen::Vector3d::Constant(in.var_moment * g00);
    addForceCongruence(fr.R_segment_frame, fr.p_segment_frame, D, ws.local[fr.segment]);
  }
  return !cm.inputs.empty();
}

// Segment i's inertial parameters: mass (exact: the loads are linear in m), centre of
// mass (linearised: the moment is quadratic in c) and inertia (exact: linear in the
// tensor's scale).
void addInertialTerms(const CovarianceModel& cm, const Model<double>& model,
                      const Data<double>& nom, int i, Matrix6& local) {
  const double m = model.mass[i];
  const Eigen::Vector3d& c = model.com[i];
  const Eigen::Vector3d& w = nom.omega[i];
  const Eigen::Vector3d& al = nom.alpha[i];
  const Eigen::Vector3d a_com = nom.acc[i] + al.cross(c) + w.cross(w.cross(c));
  Vector6 d;
  if (cm.mass_fraction > 0.0 && m > 0.0) {
    d << a_com, c.cross(a_com);
    local.noalias() += (cm.mass_fraction * cm.mass_fraction * m * m) * d * d.transpose();
  }
  if (cm.com_offset > 0.0 && m > 0.0) {
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
      const Eigen::Vector3d df = m * (al.cross(e) + w.cross(w.cross(e)));
      d << df, e.cross(m * a_com) + c.cross(df);
      local.noalias() += (cm.com_offset * cm.com_offset) * d * d.transpose();
    }
  }
  if (cm.inertia_fraction > 0.0) {
    const Eigen::Matrix3d& I = model.inertia_com[i];
    Eigen::Vector3d dn = I * al;
    if (model.gyroscopic[i]) dn += w.cross(I * w);
    d << Eigen::Vector3d::Zero(), dn;
    local.noalias() += (cm.inertia_fraction * cm.inertia_fraction) * d * d.transpose();
  }
}

// Up the tree: each segment's wrench carries the covariance of its whole subtree.
void addSubtrees(const CovarianceModel& cm, CovarianceWorkspace& ws, const Model<double>& model,
                 const Data<double>& nom) {
  for (auto it = cm.dynamics_segments.rbegin(); it != cm.dynamics_segments.rend(); ++it) {
    const int i = *it, p = model.parent[i];
    if (cm.diagonal_only)
      ws.covariance[i].diagonal() += ws.local[i].diagonal();
    else
      ws.covariance[i] += ws.local[i];
    if (p >= 0 && cm.in_dynamics[p])
      addForceCongruence(nom.R_parent_child[i], nom.p_parent_child[i], ws.local[i], ws.local[p]);
  }
}

// Whether the noise gain G is within `tolerance` of G0, entry by entry relative to the
// standard deviations of G0 (an entry of G0 with a zero diagonal must stay exact).
bool sameNoiseGain(const Eigen::Matrix3d& G, const Eigen::Matrix3d& G0, double tolerance) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (!(std::abs(G(a, b) - G0(a, b)) <= tolerance * std::sqrt(G0(a, a) * G0(b, b))))
        return false;
  return true;
}

// The three the extrapolation starts from, a period apart: while the history fills
// (after a start, a gap or a change of the noise gain), the samples in between are
// computed but not kept, so that the quadratic never reaches far beyond its nodes. The
// nodes whose gain is not within tolerance of the new one's are dropped: a settling
// filter's earlier gains would bend the quadratic (8.8x the exact sigma 40 ms after a
// start on a 1 kHz Panda with the default period when only the newest node was compared).
void keepForExtrapolation(const CovarianceModel& cm, CovarianceWorkspace& ws,
                          const Eigen::Matrix3d& G, double t) {
  if (!(cm.period > 0.0 && (ws.history == 0 || t - ws.time[0] >= (1.0 - kSamePeriod) * cm.period)))
    return;
  int agreeing = 0;
  while (agreeing < ws.history && sameNoiseGain(G, ws.gain[agreeing], cm.gain_tolerance))
    ++agreeing;
  ws.prev2.swap(ws.prev);
  ws.prev.swap(ws.last);
  for (int i : cm.dynamics_segments) ws.last[i] = ws.covariance[i];
  for (int k = 2; k > 0; --k) {
    ws.time[k] = ws.time[k - 1];
    ws.gain[k] = ws.gain[k - 1];
  }
  ws.time[0] = t;
  ws.gain[0] = G;
  ws.history = std::min(agreeing + 1, 3);
}

// The quadratic through the last three computed covariances C_0, C_1, C_2 at their stamps
// t_0 > t_1 > t_2 (Lagrange, at any spacing), at the stamp t: with x = t - t_0,
// a = t_1 - t_0, b = t_2 - t_0,
//    C = (x-a)(x-b)/(a b) C_0 + x(x-b)/(a (a-b)) C_1 + x(x-a)/(b (b-a)) C_2
// (equal spacing h, s = x/h: (1+s)(2+s)/2 C_0 - s(2+s) C_1 + s(1+s)/2 C_2).
// The covariance is a smooth function of the state, so this is exact to third order in
// the time since t_0 (holding C_0: first order; the straight line through the last two:
// second order, which overshoots where a variance turns round near its minimum;
// docs/studies/uncertainty.md measures the three). Elementwise, so as symmetric as the computed
// ones. A variance extrapolated below 0 is set to 0, and its row and column with it (no
// covariance without variance).
void quadraticThroughLastThree(const CovarianceModel& cm, CovarianceWorkspace& ws, double t) {
  const double x = t - ws.time[0], a = ws.time[1] - ws.time[0], b = ws.time[2] - ws.time[0];
  const double w0 = (x - a) * (x - b) / (a * b), w1 = x * (x - b) / (a * (a - b)),
               w2 = x * (x - a) / (b * (b - a));
  for (int i : cm.dynamics_segments) {
    Matrix6& out = ws.covariance[i];
    if (cm.diagonal_only)
      out.diagonal() =
          w0 * ws.last[i].diagonal() + w1 * ws.prev[i].diagonal() + w2 * ws.prev2[i].diagonal();
    else
      out = w0 * ws.last[i] + w1 * ws.prev[i] + w2 * ws.prev2[i];
    for (int r = 0; r < 6; ++r) {
      if (out(r, r) >= 0.0) continue;
      out.row(r).setZero();
      out.col(r).setZero();
    }
  }
}

}  // namespace

bool extrapolateCovariance(const CovarianceModel& cm, CovarianceWorkspace& ws,
                           const Eigen::Matrix3d& gain, double t) {
  if (!(cm.period > 0.0)) return false;
  const double since = t - ws.time[0];
  if (ws.history > 0 && !(since > 0.0 && since <= kGapPeriods * cm.period)) ws.history = 0;
  if (!(ws.history == 3 && since < (1.0 - kSamePeriod) * cm.period)) return false;
  if (!sameNoiseGain(gain, ws.gain[0], cm.gain_tolerance)) {
    ws.history = 0;  // the past covariances belong to another noise gain
    return false;
  }
  // An older node of another gain (kept while the filter settled): computed, and the
  // history rebuilds itself from this sample on (keepForExtrapolation).
  if (!sameNoiseGain(gain, ws.gain[1], cm.gain_tolerance) ||
      !sameNoiseGain(gain, ws.gain[2], cm.gain_tolerance))
    return false;
  quadraticThroughLastThree(cm, ws, t);
  return true;
}

void computeCovariance(const CovarianceModel& cm, CovarianceWorkspace& ws,
                       const Model<double>& model, const Data<double>& nominal,
                       const Eigen::Matrix3d& gain, double t) {
  for (int i : cm.dynamics_segments) {
    ws.covariance[i].setZero();
    ws.local[i].setZero();
  }
  bool any_local = addStateTerms(cm, ws, model, nominal, gain);
  // Each segment's own terms: the wrench inputs acting on it and its inertial parameters.
  if (addInputTerms(cm, ws, model, gain(0, 0))) any_local = true;
  if (cm.mass_fraction > 0.0 || cm.com_offset > 0.0 || cm.inertia_fraction > 0.0) {
    any_local = true;
    for (int i : cm.dynamics_segments) addInertialTerms(cm, model, nominal, i, ws.local[i]);
  }
  if (any_local) addSubtrees(cm, ws, model, nominal);
  keepForExtrapolation(cm, ws, gain, t);
}

double effortVariance(const Model<double>& model, const Eigen::Matrix<double, 6, 6>& C,
                      int segment) {
  const Eigen::Vector3d& u = model.axis[static_cast<std::size_t>(segment)];
  switch (model.joint_type[static_cast<std::size_t>(segment)]) {
    case JointType::kRevolute: return std::max(0.0, u.dot(C.bottomRightCorner<3, 3>() * u));
    case JointType::kPrismatic: return std::max(0.0, u.dot(C.topLeftCorner<3, 3>() * u));
    default: return 0.0;
  }
}

}  // namespace jle
