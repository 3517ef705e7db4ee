#include <joint_load_estimator/model/joint_space.hpp>

#include <Eigen/Geometry>

namespace jle {

namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

// Motion cross product a x b of two twists (omega; v_O).
Vector6d crossMotion(const Vector6d& a, const Vector6d& b) {
  Vector6d out;
  out.head<3>() = a.head<3>().cross(b.head<3>());
  out.tail<3>() = a.head<3>().cross(b.tail<3>()) + a.tail<3>().cross(b.head<3>());
  return out;
}

// Spatial inertia about the world origin, world frame, of mass m with its centre of
// mass at c and inertia I_com about it (world axes): (moment; force) = I (omega; v_O).
Matrix6d spatialInertia(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& I_com) {
  const Eigen::Matrix3d C = skew(c);
  Matrix6d I;
  I.topLeftCorner<3, 3>() = I_com - m * C * C;
  I.topRightCorner<3, 3>() = m * C;
  I.bottomLeftCorner<3, 3>() = -m * C;
  I.bottomRightCorner<3, 3>() = m * Eigen::Matrix3d::Identity();
  return I;
}

}  // namespace

JointSpace::JointSpace(const Model<double>& model) {
  const int n = model.nsegments();
  index.assign(static_cast<std::size_t>(n), -1);
  moving_parent.assign(static_cast<std::size_t>(n), -1);
  for (int i = 0; i < n; ++i) {
    if (i > 0) {
      const int p = model.parent[i];
      moving_parent[i] = index[p] >= 0 ? p : moving_parent[p];
    }
    if (isMoving(model.joint_type[i])) {
      index[i] = static_cast<int>(segments.size());
      segments.push_back(i);
    }
  }
  S.assign(static_cast<std::size_t>(n), Vector6d::Zero());
  v.assign(static_cast<std::size_t>(n), Vector6d::Zero());
  Ic.assign(static_cast<std::size_t>(n), Matrix6d::Zero());
  H.assign(static_cast<std::size_t>(n), Vector6d::Zero());
  const int nj = size();
  M = Eigen::MatrixXd::Zero(nj, nj);
  gravity = Eigen::VectorXd::Zero(nj);
  coriolis_transpose = Eigen::VectorXd::Zero(nj);
  momentum = Eigen::VectorXd::Zero(nj);
}

namespace {

// Forward: each segment's axis, twist, own spatial inertia and momentum (world frame).
void forwardTwists(const Model<double>& model, const Data<double>& data, JointSpace& js) {
  const int n = model.nsegments();
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d& R = data.R_world[i];
    const Eigen::Vector3d& p = data.p_world[i];
    js.S[i].setZero();
    if (model.joint_type[i] == JointType::kRevolute) {
      const Eigen::Vector3d a = R * model.axis[i];
      js.S[i] << a, p.cross(a);
    } else if (model.joint_type[i] == JointType::kPrismatic) {
      js.S[i].tail<3>() = R * model.axis[i];
    }
    js.v[i] = i == 0 ? Vector6d::Zero() : Vector6d(js.v[model.parent[i]]);
    js.v[i] += js.S[i] * data.qd[i];
    js.Ic[i] = spatialInertia(model.mass[i], p + R * model.com[i],
                              R * model.inertia_com[i] * R.transpose());
    js.H[i] = js.Ic[i] * js.v[i];
  }
}

}  // namespace

void updateJointSpace(const Model<double>& model, const Data<double>& data,
                      const Eigen::Vector3d& gravity_world, JointSpace& js) {
  forwardTwists(model, data, js);
  const int n = model.nsegments();
  // Backward: composite inertias and subtree momenta (children have larger indices).
  for (int i = n - 1; i > 0; --i) {
    js.Ic[model.parent[i]] += js.Ic[i];
    js.H[model.parent[i]] += js.H[i];
  }
  Vector6d a_gravity = Vector6d::Zero();  // gravity as an upward acceleration of the base
  a_gravity.tail<3>() = -gravity_world;
  js.M.setZero();
  for (int j = 0; j < js.size(); ++j) {
    const int k = js.segments[j];
    const Vector6d F = js.Ic[k] * js.S[k];
    js.M(j, j) = js.S[k].dot(F);
    for (int a = js.moving_parent[k]; a >= 0; a = js.moving_parent[a]) {
      const int ja = js.index[a];
      js.M(ja, j) = js.S[a].dot(F);
      js.M(j, ja) = js.M(ja, j);
    }
    js.gravity[j] = js.S[k].dot(js.Ic[k] * a_gravity);
    js.coriolis_transpose[j] = crossMotion(js.v[k], js.S[k]).dot(js.H[k]);
    js.momentum[j] = js.S[k].dot(js.H[k]);  // (M qd)_j: the axis's share of the momentum
  }
}

void pointJacobian(const Model<double>& /*model*/, const Data<double>& data, const JointSpace& js,
                   int segment, const Eigen::Vector3d& point_segment, Eigen::MatrixXd& J) {
  J.setZero(6, js.size());
  const Eigen::Vector3d x = data.p_world[segment] + data.R_world[segment] * point_segment;
  int k = js.index[segment] >= 0 ? segment : js.moving_parent[segment];
  for (; k >= 0; k = js.moving_parent[k]) {
    const int j = js.index[k];
    const Eigen::Vector3d w = js.S[k].head<3>();
    // Velocity of the point x for a unit rate: v_O + omega x x.
    J.block<3, 1>(0, j) = js.S[k].tail<3>() + w.cross(x);
    J.block<3, 1>(3, j) = w;
  }
}

}  // namespace jle
