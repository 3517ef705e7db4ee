#include <joint_load_estimator/estimation/base_channels.hpp>

#include <joint_load_estimator/estimation/estimator.hpp>  // BasePose

namespace jle {
namespace {

// Vector part of a quaternion product a * b, (w, x, y, z) layout.
Eigen::Vector3d productVector(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  const Eigen::Vector3d av = a.tail<3>(), bv = b.tail<3>();
  return a[0] * bv + b[0] * av + av.cross(bv);
}

}  // namespace

void writeBasePose(const BasePose& base, Eigen::Quaterniond& last_orientation, double* channels) {
  Eigen::Quaterniond o = base.orientation.normalized();
  if (o.coeffs().dot(last_orientation.coeffs()) < 0.0) o.coeffs() *= -1.0;
  last_orientation = o;
  double* b = channels;
  b[0] = base.position.x();
  b[1] = base.position.y();
  b[2] = base.position.z();
  b[3] = o.w();
  b[4] = o.x();
  b[5] = o.y();
  b[6] = o.z();
}

BaseState<double> baseStateFromBank(const DifferentiatorBank& bank, int channel) {
  const int b = channel;
  BaseState<double> base_state;
  base_state.p_world_base << bank.value(b), bank.value(b + 1), bank.value(b + 2);
  base_state.v_world << bank.rate(b), bank.rate(b + 1), bank.rate(b + 2);
  base_state.a_world << bank.accel(b), bank.accel(b + 1), bank.accel(b + 2);
  Eigen::Vector4d quat, quat_rate, quat_accel;
  for (int j = 0; j < 4; ++j) {
    quat[j] = bank.value(b + 3 + j);
    quat_rate[j] = bank.rate(b + 3 + j);
    quat_accel[j] = bank.accel(b + 3 + j);
  }
  const double norm = quat.norm();
  quat /= norm;
  quat_rate /= norm;
  quat_accel /= norm;
  const Eigen::Vector4d conj(quat[0], -quat[1], -quat[2], -quat[3]);
  // q' = 1/2 w q  =>  w = 2 vec(q' q*);  alpha = 2 vec(q'' q*) (the rest is scalar).
  base_state.omega_world = 2.0 * productVector(quat_rate, conj);
  base_state.alpha_world = 2.0 * productVector(quat_accel, conj);
  base_state.R_world_base =
      Eigen::Quaterniond(quat[0], quat[1], quat[2], quat[3]).toRotationMatrix();
  return base_state;
}

}  // namespace jle
