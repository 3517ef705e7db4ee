#!/usr/bin/env bash
# The numerical-stability study in one command: builds bench/stability.cpp and runs its
# sweeps, which write docs/studies/stability.md (one table per sweep) and fail if a measured
# error exceeds the bound that test/algorithms/test_stability.cpp asserts.
#   tools/stability.sh           the full study (about a minute and a half after the build)
#   tools/stability.sh --quick   fewer samples, 2e5 instead of 1e7 filter steps, into
#                                $JLE_WS/stability_quick.md instead of docs/ (for CI)
# JLE_WS as for tools/build.sh; JLE_JOBS build jobs (default 2).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws
quick=()
case "${1:-}" in
  "") out="$repo/docs/studies/stability.md" ;;
  --quick) quick=(--quick); out="$ws/stability_quick.md" ;;
  *) echo "usage: tools/stability.sh [--quick]" >&2; exit 2 ;;
esac
mkdir -p "$ws"
log="$ws/stability_build.log"
# The full study also runs the unit test that asserts its bounds, so it switches the
# unit tests on in its workspace. --quick (CI) does not: there the CI workspace builds
# the system tests only, and test_stability runs in tools/sanitize.sh.
targets=(stability)
if [ ${#quick[@]} -eq 0 ]; then targets=(-DJLE_UNIT_TESTS=ON stability test_stability); fi
if ! bash "$repo/tools/build.sh" -j"${JLE_JOBS:-2}" "${targets[@]}" >"$log" 2>&1; then
  tail -40 "$log"
  echo "stability: build failed (log: $log)" >&2
  exit 1
fi
if [ ${#quick[@]} -eq 0 ]; then "$ws/devel/lib/joint_load_estimator/test_stability"; fi
"$ws/devel/lib/joint_load_estimator/stability" "${quick[@]}" --output "$out"
echo "stability: wrote $out"
