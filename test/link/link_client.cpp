// A client of the core library compiled with other flags than the library
// (-march=native, see test/CMakeLists.txt): runs the link scenario and prints its
// numbers, one a line, for test_link_client to compare with its own run.
#include "link_scenario.hpp"

#include <joint_load_estimator/io/command_line.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  const char* const usage =
      "usage: link_client PANDA_URDF\n"
      "Runs the link scenario (a client compiled with other flags than the core library) and\n"
      "prints its numbers, one a line, for test_link_client.\n";
  if (jle::cli::answerHelpOrVersion(argc, argv, "link_client", usage)) return 0;
  if (argc != 2) {
    std::fputs(usage, stderr);
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
