// The core library linked into a client compiled with other flags (-march=native or
// -mavx2: wider vectors, another Eigen alignment if the library did not fix it): the
// client's run of the link scenario must equal this test's, which is built with the
// project's flags. Before the library exported its Eigen alignment (CMakeLists.txt), the
// client crashed in the inline filter code or returned other numbers.
#include "link_scenario.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace {

const std::string kPanda = std::string(JLE_TEST_DATA) + "/urdf/panda.urdf";

TEST(LinkClient, OtherCompilerFlagsGiveTheSameLoads) {
#ifndef JLE_LINK_CLIENT
  GTEST_SKIP() << "the compiler accepts neither -march=native nor -mavx2: no client built";
#else
  // -march=native on a CPU without AVX builds the library's own alignment: nothing to test.
  const bool avx2_flag = std::string(JLE_LINK_CLIENT_FLAGS) == "-mavx2";
  if (!__builtin_cpu_supports("avx") || (avx2_flag && !__builtin_cpu_supports("avx2")))
    GTEST_SKIP() << "this CPU has no AVX (AVX2 for -mavx2): a client built with "
                 << JLE_LINK_CLIENT_FLAGS << " would use the library's alignment or not run";
  const std::vector<double> expected = jle_link::runScenario(kPanda);
  ASSERT_GT(expected.size(), 1000u);
  const std::string command = std::string(JLE_LINK_CLIENT) + " '" + kPanda + "'";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr) << command;
  std::vector<double> got;
  char line[64];
  while (std::fgets(line, sizeof line, pipe)) got.push_back(std::strtod(line, nullptr));
  const int status = pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status)) << JLE_LINK_CLIENT_FLAGS << " client killed by signal "
                                 << WTERMSIG(status);
  ASSERT_EQ(WEXITSTATUS(status), 0) << command;
  ASSERT_EQ(got.size(), expected.size());
  // The client's inline code (the header templates) may contract a * b + c into fused
  // multiply-adds (-march=native has FMA): the last bits of each product, relative 1e-16,
  // which a second derivative from 1 ms samples amplifies by up to 1/h^2 = 1e6 (the
  // Savitzky-Golay fit), hence 1e-9; a wrong layout or alignment gives garbage or a crash.
  double largest = 0.0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_NEAR(got[i], expected[i], 1e-9 * (1.0 + std::abs(expected[i])))
        << "value " << i << " (client flags " << JLE_LINK_CLIENT_FLAGS << ")";
    largest = std::max(largest, std::abs(got[i] - expected[i]) / (1.0 + std::abs(expected[i])));
  }
  std::printf(
      "client built with %s: %zu values, largest deviation %.3g (relative to 1 + |value|)\n",
      JLE_LINK_CLIENT_FLAGS, got.size(), largest);
#endif
}

}  // namespace
