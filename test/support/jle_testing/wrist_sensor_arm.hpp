// The arm of test/data/urdf/wrist_sensor_arm.urdf with its tool, in closed form: what its
// wrist sensor reads at rest, and j2's effort at rest with a push on the tool tip. Shared
// by test/algorithms/test_sensor_joint.cpp (the core) and test/rostest/test_consistency.cpp
// (the node), which check the sensor substitution against the same numbers.
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <string>

namespace jle_test {
namespace wrist_sensor_arm {

inline const std::string& urdf() {
  static const std::string path = std::string(JLE_TEST_DATA) + "/urdf/wrist_sensor_arm.urdf";
  return path;
}
constexpr double kG = 9.80665;             // [m/s^2]
constexpr double kToolMass = 0.8;          // [kg]
inline const Eigen::Vector3d& toolCom() {  // sensor frame [m]
  static const Eigen::Vector3d c(0.0, 0.02, 0.11);
  return c;
}
inline const Eigen::Vector3d& tip() {  // sensor frame [m]
  static const Eigen::Vector3d p(0.0, 0.0, 0.2);
  return p;
}

inline Eigen::Matrix3d Ry(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

/// What the sensor reads at rest with the tool alone (sensor frame, about its origin):
/// the proximal side holds the tool's weight, m g upward; the sensor frame is turned by
/// q1 about z and q2 + pi/2 about y from the world, so "up" is (-cos q2, 0, -sin q2).
inline void staticReading(double q2, Eigen::Vector3d& f, Eigen::Vector3d& m) {
  f = kToolMass * kG * Eigen::Vector3d(-std::cos(q2), 0.0, -std::sin(q2));
  m = toolCom().cross(f);
}

/// j2's effort at rest [N m]: minus the moment about its axis (y, unchanged by q1) of the
/// weights of link2 (1.5 kg, centre of mass (0.15, 0, 0.01) in link2) and of the tool,
/// and of the push c [N] at the tool tip (sensor axes).
inline double j2EffortAtRest(double q2, const Eigen::Vector3d& c) {
  const Eigen::Matrix3d R2 = Ry(q2), Rs = R2 * Ry(M_PI / 2);
  const Eigen::Vector3d weight(0.0, 0.0, -kG);
  const Eigen::Vector3d r_link2 = R2 * Eigen::Vector3d(0.15, 0.0, 0.01);
  const Eigen::Vector3d r_tool = R2 * Eigen::Vector3d(0.3, 0.0, 0.0) + Rs * toolCom();
  const Eigen::Vector3d r_tip = R2 * Eigen::Vector3d(0.3, 0.0, 0.0) + Rs * tip();
  return -(r_link2.cross(1.5 * weight) + r_tool.cross(kToolMass * weight) + r_tip.cross(Rs * c))
              .y();
}

}  // namespace wrist_sensor_arm
}  // namespace jle_test
