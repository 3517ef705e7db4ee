// What the message-path tests (jle::Pipeline fed as the node feeds it) share: the test
// data folder, a stamp to start from, a millisecond in stamps, the empty input, the
// UR5 chain they drive, a motion of its joints, and its wrist force/torque input.
#pragma once

#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/timeline.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace jle_test {

inline const std::string kData = JLE_TEST_DATA;
constexpr jle::Stamp kStart = 1700000000123456789;  // [ns]
constexpr jle::Stamp kMs = 1000000;                 // [ns]
inline const std::vector<double> kNone;             // no velocities, no efforts

inline jle::Model<double> ur5() {
  return jle::modelFromUrdfFile(kData + "/urdf/chains/ur5_chain.urdf");
}

/// Joint i's position [rad] at t [s]: 0.5 sin(w_i t + i), 0.3-1.0 Hz, within the UR5's
/// limits and speeds.
inline double ur5Sine(int i, double t) {
  return 0.5 * std::sin(2.0 * M_PI * (0.3 + 0.14 * i) * t + i);
}

/// The default settings with one wrench input, "ft" on the UR5's tool0, on topic "ft".
inline jle::Settings withToolSensor() {
  jle::Settings settings;
  jle::WrenchInputConfig ft;
  ft.name = "ft";
  ft.link = "tool0";
  settings.estimator.wrenches.push_back(ft);
  jle::WrenchTopicSettings topic;
  topic.topic = "ft";
  settings.wrenches.push_back(topic);
  return settings;
}

}  // namespace jle_test
