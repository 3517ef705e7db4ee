// What the message-path tests (jle::Pipeline fed as the node feeds it) share: the test
// data folder, a stamp to start from, a millisecond in stamps, the empty input, the
// UR5 chain they drive, and its wrist force/torque input.
#pragma once

#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/timeline.hpp>
#include <joint_load_estimator/settings/config.hpp>

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
