// A link whose centre of mass lies D out along its own joint axis, and its effort in
// closed form: the case where a parallel-axis round trip of the inertia (m D^2 added
// to Ixx and taken away again) costs the effort its digits. Shared by
// test/algorithms/test_stability.cpp and bench/stability.cpp (docs/studies/stability.md).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace jle_test {

/// Two revolute joints: j1 about x at the base; j2 about z, its origin at (0, 0.1, 0.2)
/// rpy (0.3, 0, 0) on link1. link2: 2 kg, centre of mass at (0, 0, D) [m], inertia
/// diag(0.01, 0.02, 0.03) kg m^2 about it.
inline std::string farComUrdf(double D) {
  char com[32];
  std::snprintf(com, sizeof com, "%.17g", D);
  return std::string(R"(<robot name="far_com"><link name="base"/>
  <link name="link1"><inertial><mass value="1"/><origin xyz="0 0.05 0"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="link2"><inertial><mass value="2"/><origin xyz="0 0 )") +
         com + R"("/>
    <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/>
    <axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/>
    <origin xyz="0 0.1 0.2" rpy="0.3 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint></robot>)";
}

/// The state of the case: q = (0.4, 0.7), qd = (1.3, -0.8), qdd = (0.5, 2.0).
struct FarComState {
  double q[2] = {0.4, 0.7};
  double qd[2] = {1.3, -0.8};
  double qdd[2] = {0.5, 2.0};
};

/// The effort of j2 [N m], in long double from the URDF's numbers, independent of D and
/// of gravity (the weight and the inertial force act on the axis): in the link2 frame,
/// tau = Izz alpha_z + (Iyy - Ixx) omega_x omega_y with omega = R^T qd1 e_x + qd2 e_z and
/// alpha = R^T qdd1 e_x + (R^T qd1 e_x) x (qd2 e_z) + qdd2 e_z, R = Rx(0.3) Rz(q2)
/// (Rx(0.3)^T keeps e_x, so R^T e_x = (cos q2, -sin q2, 0)).
inline long double farComEffort(const FarComState& s = {}) {
  using L = long double;
  const L q2 = s.q[1], qd1 = s.qd[0], qdd2 = s.qdd[1];
  const L omega_x = std::cos(q2) * qd1, omega_y = -std::sin(q2) * qd1;
  const L alpha_z = qdd2;  // neither R^T qdd1 e_x nor (R^T qd1 e_x) x qd2 e_z has a z part
  return 0.03L * alpha_z + (0.02L - 0.01L) * omega_x * omega_y;
}

}  // namespace jle_test
