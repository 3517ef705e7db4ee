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
source "$repo/tools/study_build.sh"
quick=()
case "${1:-}" in
  "") out="$repo/docs/studies/stability.md" ;;
  --quick) quick=(--quick); out="$ws/stability_quick.md" ;;
  *) echo "usage: tools/stability.sh [--quick]" >&2; exit 2 ;;
esac
# The full study also runs the unit test that asserts its bounds, so it switches the
# unit tests on in its workspace. --quick (CI) does not: there the CI workspace builds
# the system tests only, and test_stability runs in tools/sanitize.sh.
targets=(stability)
if [ ${#quick[@]} -eq 0 ]; then targets=(-DJLE_UNIT_TESTS=ON stability test_stability); fi
study_build stability "${targets[@]}"
if [ ${#quick[@]} -eq 0 ]; then "$ws/devel/lib/joint_load_estimator/test_stability"; fi
"$ws/devel/lib/joint_load_estimator/stability" "${quick[@]}" --output "$out"
echo "stability: wrote $out"
