#!/usr/bin/env bash
# The speed benchmarks in one command: builds them, runs the core against KDL on the
# same states in the same run, and prints the ratios against the targets (pass/fail),
# the before/after rows, the cost split, the scaling fit and the savings rows. Extra
# arguments go to Google Benchmark (e.g. --benchmark_filter, --benchmark_repetitions=5
# --benchmark_enable_random_interleaving=true: then the medians are compared).
#
# The ratios are fair: ours and KDL's run the same 256 random states (same seed, mimics
# expanded for KDL), in one process, built with the same compiler and flags (Release);
# "ours" is every joint's full 6-D wrench over the segment-frame kinematics
# (localKinematics + inverseDynamics), KDL's solvers compute the joint torques over the
# same kinematics (no world poses either). KDL is Debian's (liborocos-kdl), as shipped.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws
bash "$repo/tools/build.sh" -j"${JLE_JOBS:-2}" bench_speed_core bench_speed_messages >"$ws/speed_build.log" 2>&1 ||
  { tail -30 "$ws/speed_build.log"; exit 1; }
bin=$ws/devel/lib/joint_load_estimator
json=$ws/speed_core.json
if [ "${1:-}" = "--page" ]; then
  filter='^(coreDouble|coreDoubleWorld|fullStep|fullStepSmoother|kdlChain|kdlTree|filterBank|smootherBank|adaptiveSmootherBank|scaling)/|^estimatorStep/.*(_defaults|_none|_off|_on|_float|_auto)$'
  args=(--benchmark_filter="$filter" --benchmark_min_time=0.2 --benchmark_repetitions=5
    --benchmark_enable_random_interleaving=true)
  before=$(/usr/bin/python3 "$repo/tools/study_page.py" load)
  "$bin/bench_speed_core" "${args[@]}" --benchmark_out="$json" --benchmark_out_format=json \
    >"$ws/speed_core.txt" 2> >(grep -v "KDL does not support" >&2)
  "$bin/bench_speed_messages" --benchmark_min_time=0.2 --benchmark_repetitions=3 \
    --benchmark_enable_random_interleaving=true --benchmark_out="$ws/speed_messages.json" \
    --benchmark_out_format=json >"$ws/speed_messages.txt"
  /usr/bin/python3 "$repo/tools/speed_page.py" "$json" "$ws/speed_messages.json" \
    --load-before "$before" --load-after "$(/usr/bin/python3 "$repo/tools/study_page.py" load)" \
    --command "bash tools/speed.sh --page" --output "$repo/docs/studies/speed.md"
  exit 0
fi
"$bin/bench_speed_core" --benchmark_min_time=0.5 --benchmark_out="$json" \
  --benchmark_out_format=json "$@" 2> >(grep -v "KDL does not support" >&2)
[ -n "${JLE_SPEED_CORE_ONLY:-}" ] || "$bin/bench_speed_messages" --benchmark_min_time=0.5
/usr/bin/python3 "$repo/tools/speed_summary.py" "$json"
