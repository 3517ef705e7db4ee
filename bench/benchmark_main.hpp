// The main() of a Google Benchmark program of the package: --help prints its usage and
// --version the package's version (jle::cli::answerHelpOrVersion), each exiting 0; then
// Google Benchmark's own options and the benchmarks.
#pragma once

#include <joint_load_estimator/io/command_line.hpp>

#include <benchmark/benchmark.h>

namespace jle_bench {

inline int benchmarkMain(int argc, char** argv, const char* name, const char* usage) {
  if (jle::cli::answerHelpOrVersion(argc, argv, name, usage)) return 0;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}

}  // namespace jle_bench
