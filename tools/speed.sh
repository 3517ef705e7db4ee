#!/usr/bin/env bash
# The speed benchmarks in one command: builds them, runs the core against KDL on the
# same states in the same run and prints the ratios, the cost split, the scaling fit
# and the savings rows. Extra arguments go to Google Benchmark (e.g. --benchmark_filter).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws
bash "$repo/tools/build.sh" -j"${JLE_JOBS:-2}" bench_speed_core bench_speed_messages >"$ws/speed_build.log" 2>&1 ||
  { tail -30 "$ws/speed_build.log"; exit 1; }
bin=$ws/devel/lib/joint_load_estimator
json=$ws/speed_core.json
"$bin/bench_speed_core" --benchmark_min_time=0.5 --benchmark_out="$json" \
  --benchmark_out_format=json "$@" 2> >(grep -v "KDL does not support" >&2)
"$bin/bench_speed_messages" --benchmark_min_time=0.5
/usr/bin/python3 - "$json" <<'PY'
import json, sys
runs = {b["name"]: b for b in json.load(open(sys.argv[1]))["benchmarks"] if "cpu_time" in b}
pairs = [("panda_chain", "kdlChain"), ("ur5_chain", "kdlChain"), ("kinova_chain", "kdlChain"),
         ("panda_chain", "kdlTree"), ("panda", "kdlTree"), ("talos", "kdlTree")]
print("\nAll 6-D joint wrenches + kinematics (ours) against KDL's efforts, CPU time per sample:")
for model, peer in pairs:
    ours, theirs = runs.get("coreDouble/" + model), runs.get(peer + "/" + model)
    if ours and theirs:
        print(f"  {model:13s} ours {ours['cpu_time']:9.0f} ns   {peer:9s} {theirs['cpu_time']:9.0f} ns"
              f"   ratio {ours['cpu_time'] / theirs['cpu_time']:.3f}")
PY
