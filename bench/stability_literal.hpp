// The "before" of bench/stability.cpp: the paper's formulation taken literally (Federico &
// Alhasadi 2022, section 5). Every quantity in world coordinates, moments about the
// centre of mass x_G, lever arms xi = x - x_G computed from world positions:
//   F = m a_G - F_0
//   M = J_G alpha + omega x J_G omega - xi_n x F - M_0,
//   F_0 = m g + sum F_i,  M_0 = sum (xi_i x F_i + M_i),
// with the children's joint wrenches among the F_i, M_i (reversed, about their joint
// origins). Kinematics come from the core's forward pass (rotated to the world), so
// that the two formulations differ only in where the backward pass works.
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <jle_testing/random_models.hpp>

#include <Eigen/Core>

#include <vector>

namespace jle_bench {

/// Joint wrenches by the literal world-frame formulation, returned like Data's
/// (child frame, moment about the joint origin) so that they compare with the core's.
template <typename S>
struct LiteralLoads {
  std::vector<Eigen::Matrix<S, 3, 1>> force, moment;
};

template <typename S>
LiteralLoads<S> literalWorldFrameLoads(const jle::Model<S>& model, jle::Data<S>& data,
                                       const jle_test::Scene& scene) {
  using V3 = Eigen::Matrix<S, 3, 1>;
  using M3 = Eigen::Matrix<S, 3, 3>;
  const jle::VectorX<S> q = scene.state.q.cast<S>(), qd = scene.state.qd.cast<S>(),
                        qdd = scene.state.qdd.cast<S>();
  const V3 g = scene.gravity.cast<S>();
  jle::forwardKinematics(model, data, q, qd, qdd, g, jle_test::castBase<S>(scene.base));
  const int n = model.nsegments();
  // Applied loads per segment, world frame, each with its point of application.
  std::vector<std::vector<V3>> ext_x(n), ext_f(n), ext_m(n);
  for (const jle_test::AppliedWrench& w : scene.wrenches) {
    const jle::Frame<S>& fr = model.frames[w.frame];
    const M3& R = data.R_world[fr.segment];
    const V3 x = data.p_world[fr.segment] + R * fr.p_segment_frame;
    V3 f = w.force.cast<S>(), m = w.moment.cast<S>();
    if (w.expressed_in == jle::WrenchFrame::kLocal) {
      f = (R * fr.R_segment_frame * f).eval();
      m = (R * fr.R_segment_frame * m).eval();
    }
    ext_x[fr.segment].push_back(x);
    ext_f[fr.segment].push_back(f);
    ext_m[fr.segment].push_back(m);
  }
  std::vector<V3> F(n, V3::Zero()), M(n, V3::Zero());    // world, M about the joint origin
  std::vector<V3> F0(n, V3::Zero()), M0(n, V3::Zero());  // M0 about x_G
  std::vector<V3> xG(n);
  for (int i = 0; i < n; ++i) xG[i] = jle::comWorld(model, data, i);
  for (int i = n - 1; i >= 0; --i) {
    const M3& R = data.R_world[i];
    const S m = model.mass[i];
    const V3 w = jle::omegaWorld(data, i), al = jle::alphaWorld(data, i);
    const V3 aG = jle::comAccelerationWorld(model, data, i, g);
    const M3 JG = R * model.inertia_com[i] * R.transpose();
    F0[i] += m * g;
    for (std::size_t k = 0; k < ext_x[i].size(); ++k) {
      F0[i] += ext_f[i][k];
      M0[i] += (ext_x[i][k] - xG[i]).cross(ext_f[i][k]) + ext_m[i][k];
    }
    const V3 xi_n = data.p_world[i] - xG[i];
    F[i] = m * aG - F0[i];
    M[i] = JG * al + w.cross(JG * w) - xi_n.cross(F[i]) - M0[i];
    const int p = model.parent[i];
    if (p >= 0) {  // the parent feels the reversed joint wrench, at this joint origin
      F0[p] -= F[i];
      M0[p] += (data.p_world[i] - xG[p]).cross(-F[i]) - M[i];
    }
  }
  LiteralLoads<S> out;
  for (int i = 0; i < n; ++i) {
    out.force.push_back(data.R_world[i].transpose() * F[i]);
    out.moment.push_back(data.R_world[i].transpose() * M[i]);
  }
  return out;
}

}  // namespace jle_bench
