#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test; exits non-zero on a failure.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
bash "$repo/tools/install_deps.sh"
bash "$repo/tools/build.sh" -j2
bash "$repo/tools/build.sh" -j2 tests
export PATH=/usr/bin:$PATH
cd "$ws"
# run_tests does not fail on a failed test; catkin_test_results does.
catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 run_tests -j1 >"$ws/run_tests.log" 2>&1 ||
  { tail -50 "$ws/run_tests.log"; exit 1; }
grep -E "^\[ *(OK|FAILED|PASSED) |^\[==========\]|FAILURE|Error" "$ws/run_tests.log" | tail -60 || true
catkin_test_results --verbose build/test_results | tail -40
catkin_test_results build/test_results
