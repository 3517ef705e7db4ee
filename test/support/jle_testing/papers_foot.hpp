// The paper's section 6 foot (S. Federico, M. F. Alhasadi 2022): a foot turning in the
// plane about a fixed ankle, a force plate's reaction at a centre of pressure fixed in
// the foot, and the ankle wrench by the paper's planar equations, worked here (not by
// the library). Shared by test_closed_form.cpp (the 6x6 path) and test_planar.cpp (the
// planar path).
//
// Geometry, in the foot frame (origin at the ankle, turning with theta): the ankle lies
// at distance l from G in the direction (-cos beta, sin beta) (behind and above G); the
// centre of pressure lies b ahead of G and d below it.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <string>

namespace jle_test {

/// The z component of the cross product of two plane vectors.
inline double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

struct PapersFoot {
  double m = 1.2, J_G = 0.0065;             ///< [kg], [kg m^2]
  double l = 0.09, beta = 0.6;              ///< ankle from G [m], [rad]
  double b = 0.11, d = 0.04;                ///< centre of pressure from G [m]
  Eigen::Vector2d ankle_world{0.05, 0.08};  ///< the fixed ankle [m]
  Eigen::Vector2d g{0.0, -9.80665};         ///< [m/s^2]
  // Foot-frame positions from the ankle.
  Eigen::Vector2d xi_A_foot = l * Eigen::Vector2d(-std::cos(beta), std::sin(beta));
  Eigen::Vector2d G_foot = -xi_A_foot;
  Eigen::Vector2d xi_P_foot{b, -d};
  Eigen::Vector2d P_foot = G_foot + xi_P_foot;

  /// The equivalent URDF: a massless world, the ankle about z, the foot with its inertia
  /// axes turned in the plane (J_G stays I_zz), the centre of pressure a fixed child
  /// frame "cop" of the foot.
  std::string urdf() const {
    const auto num = [](double x) {
      char buffer[40];
      std::snprintf(buffer, sizeof buffer, "%.17g", x);
      return std::string(buffer);
    };
    const auto xy = [&](const Eigen::Vector2d& p) { return num(p.x()) + " " + num(p.y()) + " 0"; };
    return "<robot name=\"foot\"><link name=\"world\"/><link name=\"foot\"><inertial>"
           "<origin xyz=\"" +
           xy(G_foot) + "\" rpy=\"0 0 0.3\"/><mass value=\"" + num(m) +
           "\"/><inertia ixx=\"0.0012\" ixy=\"0\" ixz=\"0\" iyy=\"0.0058\" iyz=\"0\" izz=\"" +
           num(J_G) +
           "\"/></inertial></link><link name=\"cop\"/>"
           "<joint name=\"ankle\" type=\"revolute\"><parent link=\"world\"/><child link=\"foot\"/>"
           "<origin xyz=\"" +
           xy(ankle_world) +
           "\"/><axis xyz=\"0 0 1\"/>"
           "<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>"
           "<joint name=\"cop_joint\" type=\"fixed\"><parent link=\"foot\"/><child link=\"cop\"/>"
           "<origin xyz=\"" +
           xy(P_foot) + "\"/></joint></robot>";
  }

  /// One instant of a stance-like motion, theta(t) = theta0 + A sin(omega t) at
  /// t = 0.025 k (k = 0 .. 40: one second), under a plate reaction F_P(t) that rises and
  /// falls; and the ankle wrench (F_A, M_A: on the foot, world frame) by the paper's
  /// equations, with the scales the tests' tolerances are relative to.
  struct Instant {
    double t, theta, theta_d, theta_dd;
    Eigen::Matrix2d Q;  ///< the foot's rotation
    Eigen::Vector2d F_P, a_G, xi_A, xi_P, F_A;
    double M_A, force_scale, moment_scale;
  };

  Instant at(int k) const {
    const double theta0 = -0.1, A = 0.35, omega = 5.0;
    Instant i;
    i.t = 0.025 * k;
    i.theta = theta0 + A * std::sin(omega * i.t);
    i.theta_d = A * omega * std::cos(omega * i.t);
    i.theta_dd = -A * omega * omega * std::sin(omega * i.t);
    i.F_P = Eigen::Vector2d(60.0 * std::sin(2 * omega * i.t), 700.0 * std::sin(M_PI * i.t) + 5.0);
    // Kinematics of G turning about the fixed ankle: tangential + centripetal.
    i.Q = Eigen::Rotation2Dd(i.theta).toRotationMatrix();
    const Eigen::Vector2d r = i.Q * G_foot;  // ankle -> G, world
    i.a_G = Eigen::Vector2d(-i.theta_dd * r.y() - i.theta_d * i.theta_d * r.x(),
                            i.theta_dd * r.x() - i.theta_d * i.theta_d * r.y());
    i.xi_A = i.Q * xi_A_foot;
    i.xi_P = i.Q * xi_P_foot;
    i.F_A = m * i.a_G - i.F_P - m * g;
    i.M_A = J_G * i.theta_dd - cross2(i.xi_A, i.F_A) - cross2(i.xi_P, i.F_P);
    i.force_scale = m * (i.a_G.norm() + 9.80665) + i.F_P.norm();
    i.moment_scale = J_G * std::abs(i.theta_dd) + l * i.F_A.norm() + i.xi_P.norm() * i.F_P.norm();
    return i;
  }
};

}  // namespace jle_test
