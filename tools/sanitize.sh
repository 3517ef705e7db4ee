#!/usr/bin/env bash
# Builds the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer in a catkin
# workspace of their own and runs every gtest unit-test binary directly. This is where
# tools/test.sh runs the unit tests: once, sanitized (its Release workspace builds the
# system tests only). The unit tests are the ones CMake lists (test/unit_tests.cmake):
# every gtest registered with catkin_add_gtest or jle_add_unit_test, which needs no
# master; the target joint_load_estimator_unit_tests builds them and
# build/joint_load_estimator/unit_tests.txt names their binaries. Built at -O1 with line
# tables only (-g1: a report still names file and line): test_pipeline.cpp compiles in
# 43 s of CPU against 72 s at -O2 -g. Warnings are errors as in the Release build. Fails
# on a failed test or on any sanitizer report.
#   JLE_WS_SAN       workspace (default ~/.cache/joint_load_estimator/ws_asan)
#   JLE_JOBS         parallel build jobs (default 2)
#   JLE_SAN_RESULTS  directory for the tests' JUnit files, gtest-<test>.xml (default
#                    $JLE_WS_SAN/test_results), where catkin_test_results reads them
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS_SAN:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws_asan}
jobs=${JLE_JOBS:-2}
mkdir -p "$ws/src"
ln -sfn "$repo" "$ws/src/joint_load_estimator"
export PATH=/usr/bin:$PATH
cd "$ws"
results=${JLE_SAN_RESULTS:-$ws/test_results}
mkdir -p "$results"
# Build type None: these flags only (no -O2/-O3 of a build type).
flags="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
flags="$flags -O1 -g1 -DNDEBUG"
if ! catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=None \
    -DJLE_UNIT_TESTS=ON -DJLE_SYSTEM_TESTS=OFF -DJLE_WERROR=ON \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
    -j"$jobs" joint_load_estimator_unit_tests >"$ws/build.log" 2>&1; then
  tail -40 "$ws/build.log"
  echo "sanitizer build failed (log: $ws/build.log)"
  exit 1
fi

# halt_on_error: the first report ends the binary with a non-zero status.
# LeakSanitizer cannot run under ptrace (a debugger, strace, some sandboxes): it is kept
# on unless JLE_SAN_LEAKS=0 (it then says "LeakSanitizer does not work under ptrace").
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=${JLE_SAN_LEAKS:-1}:detect_stack_use_after_return=1:strict_string_checks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
list="$ws/build/joint_load_estimator/unit_tests.txt"
[ -s "$list" ] || { echo "no unit-test list at $list"; exit 1; }
status=0
ran=0
while read -r t <&3; do
  name=$(basename "$t")
  [ -x "$t" ] && [ -f "$t" ] || { echo "FAIL  $name: listed but not built ($t)"; status=1; continue; }
  log="$ws/$name.log"
  start=$(date +%s)
  if "$t" --gtest_output="xml:$results/gtest-$name.xml" >"$log" 2>&1 && ! grep -qE "ERROR: (Address|Leak)Sanitizer|runtime error:" "$log"; then
    echo "ok    $name ($(($(date +%s) - start)) s)"
  else
    echo "FAIL  $name (log: $log)"
    grep -E "ERROR: .*Sanitizer|runtime error:|^\[  FAILED  \]|SUMMARY" "$log" | head -20 || true
    status=1
  fi
  ran=$((ran + 1))
done 3<"$list"
[ "$ran" -gt 0 ] || { echo "no unit test binary in $list"; exit 1; }
echo "sanitizers: $ran unit test binaries, $([ $status -eq 0 ] && echo clean || echo FAILED)"
exit $status
