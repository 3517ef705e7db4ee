// The gait trial as a CSV file (make_gait_bag --csv) through the offline tool
// (joint_loads --floating-base --plate ...): the path a biomechanist takes with a trial
// of their own (docs/gait_demo.md). The plates explain the motion, so the pelvis residual
// is what the generator's numerical derivatives leave.
#include "tool_test.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace {

using jle_test::Result;

class GaitCsv : public jle_test::ToolTest {
 protected:
  GaitCsv() : ToolTest("jle_gait_csv") {}
};

TEST_F(GaitCsv, JointLoadsExplainsTheTrialWithThePlates) {
  const std::string urdf = std::string(JLE_TEST_DATA) + "/urdf/body_75kg_175cm.urdf";
  const Result make = run(
      JLE_MAKE_GAIT_BAG, {"--urdf", urdf, "--output", path("gait.bag"), "--csv", path("gait.csv")});
  ASSERT_EQ(make.status, 0) << make.err;
  // The generator prints the plate options to give joint_loads.
  std::vector<std::string> loads_args = {"--urdf",         urdf,       "--input",
                                         path("gait.csv"), "--output", path("loads.csv"),
                                         "--floating-base"};
  std::istringstream report(make.out);
  std::string line, plates;
  while (std::getline(report, line))
    if (line.find("joint_loads: ") != std::string::npos)
      plates = line.substr(line.find("joint_loads: ") + 13);
  ASSERT_FALSE(plates.empty());
  std::istringstream words(plates);
  for (std::string word; words >> word;) loads_args.push_back(word);
  loads_args.insert(loads_args.end(), {"--contact-threshold", "1"});
  const Result loads = run(JLE_JOINT_LOADS, loads_args);
  ASSERT_EQ(loads.status, 0) << loads.err;

  const jle_test::Table table = jle_test::parseCsv(jle_test::readFile(path("loads.csv")));
  const std::vector<std::string>& header = table.header;
  std::vector<int> force, moment;
  for (int i = 0; i < static_cast<int>(header.size()); ++i) {
    if (header[i] == "base.fx" || header[i] == "base.fy" || header[i] == "base.fz")
      force.push_back(i);
    if (header[i] == "base.mx" || header[i] == "base.my" || header[i] == "base.mz")
      moment.push_back(i);
  }
  ASSERT_EQ(force.size(), 3u);
  ASSERT_EQ(moment.size(), 3u);
  double max_force = 0.0, max_moment = 0.0;
  int rows = 0;
  for (const std::vector<std::string>& cells : table.rows) {
    double f2 = 0.0, m2 = 0.0;
    for (int i : force) f2 += std::pow(std::atof(cells[static_cast<std::size_t>(i)].c_str()), 2);
    for (int i : moment) m2 += std::pow(std::atof(cells[static_cast<std::size_t>(i)].c_str()), 2);
    max_force = std::max(max_force, std::sqrt(f2));
    max_moment = std::max(max_moment, std::sqrt(m2));
    ++rows;
  }
  EXPECT_EQ(rows, 630);  // 3 strides of 1.05 s at 200 Hz
  // Bound: the CSV's velocities and accelerations are 5-point central differences on a
  // 1 kHz grid, exact to O(h^4) where the motion is smooth; at the junctions of the
  // quintic pieces (a jump J of the third derivative) the second difference errs by
  // J h / 9: the swing (about 1.2 m in 0.42 s, J = 60 x 1.2 / 0.42^3 = 970 m/s^3) 0.11
  // m/s^2 on the 4.6 kg of shank and foot, 0.5 N; the heel rocker (25 deg in 0.105 s,
  // J = 60 x 0.436 / 0.105^3 = 2.3e4 rad/s^3) 2.5 rad/s^2 on the 1.1 kg foot 0.1 m from
  // the ankle, 0.3 N (the pelvis path is a Fourier series, smooth); the legs' angles follow
  // the feet through the inverse kinematics with errors of the same kind: 2 N in all.
  // (A plate pressed by less than the threshold, 1 N, at the ends of each contact acts
  // as measured: nothing more.) 3 N; the moment about the pelvis, the same forces at the
  // feet, about 1 m away: 3 N m.
  // (Without the plates the residual would be the body weight, 735 N.)
  EXPECT_LT(max_force, 3.0);
  EXPECT_LT(max_moment, 3.0);
}

}  // namespace
