#!/usr/bin/env bash
# The KDL rows of docs/studies/correctness.md: builds and runs test_kdl (ours against
# KDL's inverse dynamics and forward kinematics on random states of the bundled robots)
# and writes its largest disagreements into the page (tools/correctness_page.py).
# About a minute after the build. JLE_WS as for tools/build.sh.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
mkdir -p "$ws"
before=$(/usr/bin/python3 "$repo/tools/study_page.py" load)
log="$ws/correctness_build.log"
if ! bash "$repo/tools/build.sh" -j"${JLE_JOBS:-2}" -DJLE_UNIT_TESTS=ON test_kdl >"$log" 2>&1; then
  tail -40 "$log"
  echo "correctness: build failed (log: $log)" >&2
  exit 1
fi
"$ws/devel/lib/joint_load_estimator/test_kdl" >"$ws/correctness_kdl.txt" 2>/dev/null || {
  grep -E "FAILED|Failure" "$ws/correctness_kdl.txt" | head -20
  echo "correctness: test_kdl failed (output: $ws/correctness_kdl.txt)" >&2
  exit 1
}
/usr/bin/python3 "$repo/tools/correctness_page.py" "$ws/correctness_kdl.txt" "$before" \
  "$(/usr/bin/python3 "$repo/tools/study_page.py" load)"
