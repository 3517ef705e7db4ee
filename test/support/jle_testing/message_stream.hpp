// What the message-path tests (jle::Pipeline fed as the node feeds it) share: the test
// data folder, a stamp to start from, a millisecond in stamps, the empty input, and the
// UR5 chain they drive.
#pragma once

#include <joint_load_estimator/model/urdf_reader.hpp>
#include <joint_load_estimator/pipeline/timeline.hpp>

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

}  // namespace jle_test
