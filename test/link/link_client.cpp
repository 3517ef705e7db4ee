// A client of the core library compiled with other flags than the library
// (-march=native, see test/CMakeLists.txt): runs the link scenario and prints its
// numbers, one a line, for test_link_client to compare with its own run.
#include "link_scenario.hpp"

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s PANDA_URDF\n", argv[0]);
    return 2;
  }
  try {
    for (double v : jle_link::runScenario(argv[1])) std::printf("%.17g\n", v);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "link_client: %s\n", e.what());
    return 1;
  }
  return 0;
}
