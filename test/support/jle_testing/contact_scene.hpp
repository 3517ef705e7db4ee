// A simulated contact with exact truth, shared by test_external_effort and
// bench/external_effort: a robot moving on sinusoids, a wrench applied TO a link during a
// window, and the joint efforts it would measure (this package's inverse dynamics with
// the wrench applied: the measured efforts are exact, the truth is the applied wrench).
// Header-only, ROS-free.
#pragma once

#include <joint_load_estimator/model/data.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <Eigen/Core>

#include <cmath>
#include <string>
#include <vector>

namespace jle_testing {

struct ContactScene {
  std::string link;                             ///< where the wrench acts (URDF link)
  Eigen::Vector3d force_link{5, -3, 10};        ///< [N] link frame
  Eigen::Vector3d moment_link{0.2, 0.1, -0.3};  ///< [N m] about the link origin
  double t_on = 1.0, t_off = 2.0;               ///< [s] the wrench acts in [t_on, t_off)
  double amplitude = 0.3;                       ///< [rad] of every joint's sinusoid
  double frequency = 0.4;                       ///< [Hz] of the first joint (others faster)
  /// [rad] the pose the sinusoids are about (model.nq values); empty: q0_i = 0.3 + 0.1 i
  /// (i even), -0.6 + 0.1 i (i odd), which on the Panda puts joints 4 and 6 beyond their
  /// limits, near the elbow's singularity (the Jacobian's condition number 220-290).
  Eigen::VectorXd center;

  bool active(double t) const { return t >= t_on && t < t_off; }

  /// q, qd, qdd of coordinate i at t (about `center`).
  void state(const jle::Model<double>& model, double t, jle::VectorX<double>& q,
             jle::VectorX<double>& qd, jle::VectorX<double>& qdd) const {
    const int n = model.nq;
    q.resize(n);
    qd.resize(n);
    qdd.resize(n);
    for (int i = 0; i < n; ++i) {
      const double w = 2.0 * M_PI * frequency * (1.0 + 0.23 * i);
      const double phase = 0.7 * i;
      const double q0 = center.size() == n ? center[i] : (i % 2 == 0 ? 0.3 : -0.6) + 0.1 * i;
      q[i] = q0 + amplitude * std::sin(w * t + phase);
      qd[i] = amplitude * w * std::cos(w * t + phase);
      qdd[i] = -amplitude * w * w * std::sin(w * t + phase);
    }
  }

  /// The measured efforts at t (every moving segment, in segment order of `published`).
  void efforts(const jle::Model<double>& model, jle::Data<double>& data, double t,
               const std::vector<int>& published, const Eigen::Vector3d& gravity,
               std::vector<double>& out) const {
    jle::VectorX<double> q, qd, qdd;
    state(model, t, q, qd, qdd);
    jle::forwardKinematics(model, data, q, qd, qdd, gravity);
    if (active(t))
      jle::addExternalWrench(model, data, model.frameIndex(link), force_link, moment_link,
                             jle::WrenchFrame::kLocal);
    jle::inverseDynamics(model, data);
    out.clear();
    for (int s : published) out.push_back(data.effort[s]);
  }
};

}  // namespace jle_testing
