#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (gtest units, the CLI tests,
# rostest node tests, each benchmark once on a tiny input); exits non-zero on a failure.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws
# Each stage says when it starts, in seconds since this script began (the CI budget).
stage() { echo "[test.sh $SECONDS s] $*"; }
stage install
bash "$repo/tools/install_deps.sh"
stage build
# Warnings are errors in CI (the option JLE_WERROR of CMakeLists.txt, OFF by default).
# This Release workspace builds the system tests (link test, Python bindings, node
# tests, soaks); the unit tests are built and run once, under the sanitizers, by
# tools/sanitize.sh below (their results join these in build/test_results).
bash "$repo/tools/build.sh" -j2 -DJLE_WERROR=ON -DJLE_UNIT_TESTS=OFF -DJLE_SYSTEM_TESTS=ON
bash "$repo/tools/build.sh" -j2 tests
stage style
# House style: no function over 80 lines in src/ and include/, every C++ file formatted
# by the root .clang-format.
style_status=0
/usr/bin/python3 "$repo/tools/function_lengths.py" "$repo/src" "$repo/include" --limit 80 --top 3 ||
  { echo "style: a function is over 80 lines"; style_status=1; }
bash "$repo/tools/format.sh" --check || { echo "style: run bash tools/format.sh"; style_status=1; }
export PATH=/usr/bin:$PATH
cd "$ws"
rm -rf build/test_results
stage run_tests
# run_tests does not fail on a failed test; catkin_test_results does.
if ! catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 run_tests -j1 >"$ws/run_tests.log" 2>&1; then
  tail -80 "$ws/run_tests.log"
  echo "run_tests failed (log: $ws/run_tests.log)"
  exit 1
fi
stage fresh_workspace
# The package as a user builds it: a new catkin workspace, plain catkin_make, then
# catkin_tools' catkin build, every program rosrun finds answering --help, the node run
# from it (README, step 1).
for builder in catkin_make catkin_build; do
  JLE_BUILDER=$builder bash "$repo/test/scripts/fresh_workspace.sh" >"$ws/fresh_workspace_$builder.log" 2>&1 ||
    { tail -30 "$ws/fresh_workspace_$builder.log"; echo "fresh workspace ($builder) failed (log: $ws/fresh_workspace_$builder.log)"; bench_status=1; }
  tail -4 "$ws/fresh_workspace_$builder.log" || true
done
stage benchmarks
# The benchmarks, once each on a tiny input, so that they cannot rot (no timing is
# judged here).
bench_status=0
for b in bench_speed_core bench_speed_messages bench_external_effort; do
  "$ws/devel/lib/joint_load_estimator/$b" --benchmark_min_time=0.0001 >"$ws/$b.log" 2>&1 ||
    { echo "benchmark $b failed (log: $ws/$b.log)"; bench_status=1; }
done
# The external-effort error table on 1.5 s of the scene (about 2 s).
"$ws/devel/lib/joint_load_estimator/bench_external_effort" --table --quick \
  >"$ws/external_effort_table.log" 2>&1 ||
  { tail -20 "$ws/external_effort_table.log"; echo "external effort table failed"; bench_status=1; }
stage accuracy_stability
bash "$repo/tools/accuracy.sh" --quick >"$ws/accuracy_quick.log" 2>&1 ||
  { tail -20 "$ws/accuracy_quick.log"; echo "accuracy --quick failed"; bench_status=1; }
bash "$repo/tools/stability.sh" --quick >"$ws/stability_quick.log" 2>&1 ||
  { tail -20 "$ws/stability_quick.log"; echo "stability --quick failed"; bench_status=1; }
# The node's latency bench (every path, one rate, 0.3 s) and the offline throughput
# bench with its parallel-equals-serial check, on tiny inputs (about 70 s together on
# the loaded 2-core machine, mostly process start-up).
stage latency_throughput
JLE_BENCH_RATES="[1000]" bash "$repo/bench/node_latency.sh" 0.3 >"$ws/node_latency_quick.log" 2>&1 ||
  { tail -20 "$ws/node_latency_quick.log"; echo "node_latency.sh failed"; bench_status=1; }
bash "$repo/bench/offline_throughput.sh" --quick >"$ws/offline_throughput_quick.log" 2>&1 ||
  { tail -20 "$ws/offline_throughput_quick.log"; echo "offline_throughput.sh failed"; bench_status=1; }
# Robustness: the soaks (1e6 samples with bad messages mixed in, in process and
# through the real node over ROS), the fuzzers
# (regressions first, then 30 s each), the unit tests under ASan + UBSan (a second
# workspace: the only run of the unit tests).
stage soak
"$ws/devel/lib/joint_load_estimator/soak" >"$ws/soak.log" 2>&1 ||
  { tail -20 "$ws/soak.log"; echo "soak failed (log: $ws/soak.log)"; bench_status=1; }
tail -12 "$ws/soak.log" || true
stage node_soak
bash "$repo/test/soak/node_soak.sh" >"$ws/node_soak.log" 2>&1 ||
  { tail -30 "$ws/node_soak.log"; echo "node soak failed (log: $ws/node_soak.log)"; bench_status=1; }
tail -20 "$ws/node_soak.log" || true
stage fuzz
bash "$repo/test/fuzz/build_and_run.sh" 30 >"$ws/fuzz.log" 2>&1 ||
  { # without the compilers' warnings; with the failing input's base64 (build_and_run.sh)
    grep -vE "warning:|note:|^In file|^ +[~^]|^ {4}|generated\.$" "$ws/fuzz.log" | tail -400
    echo "fuzzing failed (log: $ws/fuzz.log)"
    bench_status=1
  }
grep -E "^(fuzz|#[0-9]+ +DONE)" "$ws/fuzz.log" | tail -6 || true
stage sanitizers
JLE_SAN_RESULTS="$ws/build/test_results/joint_load_estimator" bash "$repo/tools/sanitize.sh" ||
  { echo "sanitizer suite failed"; bench_status=1; }
grep -E "^\[  (FAILED|PASSED) |^\[ *FAILED *\]|^\[ROSTEST\]|FAILURE" "$ws/run_tests.log" | sort | uniq -c | sort -rn | head -40 || true
stage results
/usr/bin/python3 "$repo/tools/slowest_tests.py" build/test_results || true
status=0
catkin_test_results --verbose build/test_results >"$ws/test_results.txt" 2>&1 || status=$?
grep -vE "^$" "$ws/test_results.txt" | grep -vE "^(Summary|  )" | tail -20 || true
summary=$(grep -E "^Summary:" "$ws/test_results.txt" || echo "Summary: 0 tests, 1 errors, 0 failures, 0 skipped")
echo "$summary"
# The plain closing line: N passed, N failed.
echo "$summary" | awk '{gsub(",", ""); t=$2; e=$4; f=$6; s=$8; printf "tests: %d passed, %d failed, %d skipped\n", t-e-f-s, e+f, s}'
if [ "$(echo "$summary" | awk '{gsub(",", ""); print $2}')" = "0" ]; then
  echo "no test ran"; exit 1
fi
[ "$bench_status" -eq 0 ] || exit 1
[ "$style_status" -eq 0 ] || exit 1
exit $status
