#!/usr/bin/env bash
# The accuracy study in one command: builds bench/accuracy, runs every scene through
# jle::Pipeline and the offline zero-phase smoother, and writes docs/studies/accuracy.csv, docs/studies/accuracy.md,
# docs/studies/accuracy_error_vs_time.png and docs/studies/accuracy_error_vs_delay.png, then the
# Kalman smoother's tables of docs/studies/differentiators.md (bench/differentiator_tables.py),
# the tables of docs/studies/accuracy_overview.md (bench/accuracy_overview.py) and
# docs/studies/causal_limit.md (bench/causal_limit.py).
#   tools/accuracy.sh           the full study (about 2 min of CPU after the build)
#   tools/accuracy.sh --quick   a tiny input, into $JLE_WS/accuracy_quick instead of docs/
#                               (for CI: it fails if the study or the report no longer run,
#                               or if exact inputs are not reproduced)
# JLE_WS as for tools/build.sh; JLE_JOBS build jobs (default 2).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
source "$repo/tools/study_build.sh"
quick=()
case "${1:-}" in
  "") out="$repo/docs/studies" ;;
  --quick) quick=(--quick); out="$ws/accuracy_quick" ;;
  *) echo "usage: tools/accuracy.sh [--quick]" >&2; exit 2 ;;
esac
mkdir -p "$out"
study_build accuracy accuracy
"$ws/devel/lib/joint_load_estimator/accuracy" "${quick[@]}" --csv "$out/accuracy.csv"
/usr/bin/python3 "$repo/bench/plot_accuracy.py" "$out/accuracy.csv" --md "$out/accuracy.md" \
  --png-prefix "$out/accuracy" --command "tools/accuracy.sh${quick:+ --quick}"
/usr/bin/python3 "$repo/bench/causal_limit.py" "$out/causal_limit.md" "$out/accuracy.csv" >/dev/null
if [ ${#quick[@]} -eq 0 ]; then
  /usr/bin/python3 "$repo/bench/differentiator_tables.py" "$out/accuracy.csv" "$out/differentiators.md"
  /usr/bin/python3 "$repo/bench/accuracy_overview.py" "$out/accuracy.csv" "$out/accuracy_overview.md"
fi
echo "accuracy: wrote $out/accuracy.csv, accuracy.md, accuracy_error_vs_time.png, accuracy_error_vs_delay.png, causal_limit.md, accuracy_overview.md"
