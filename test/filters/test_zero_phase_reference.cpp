// joint_loads on positions only against the independently written scipy pipeline and
// closed-form planar inverse dynamics of test/scripts/zero_phase_reference.py (its
// docstring lists the comparisons; every one to 1e-9 relative). The script's exit status
// is this test's verdict.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

TEST(ZeroPhaseReference, JointLoadsReproducesScipyFiltfiltAndClosedFormDynamics) {
  const std::string command = std::string("/usr/bin/python3 ") + JLE_TEST_SCRIPTS +
                              "/zero_phase_reference.py --joint-loads " + JLE_JOINT_LOADS +
                              " --urdf " + JLE_TEST_DATA + "/urdf/planar_arm.urdf";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
}
