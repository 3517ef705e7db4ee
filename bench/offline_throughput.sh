#!/usr/bin/env bash
# Offline throughput (docs/offline_tools.md "Offline: many files at once", docs/studies/offline_throughput.md):
# samples per second of process_bag (the demo's Panda with its wrist sensor, the
# demo's configuration) and of joint_loads (the 7-joint Panda chain with a wrench), one
# file alone and many files through tools/batch.sh, serially (-j 1) and on every core
# (-j nproc); checks that the parallel outputs equal the serial ones byte for byte.
# Usage: bench/offline_throughput.sh [--quick]   (--quick: tiny inputs, for CI)
# JLE_THROUGHPUT_FILES (default 4), JLE_BAG_SECONDS (300), JLE_CSV_SECONDS (60): the
# inputs, recorded at 1 kHz.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws
files=${JLE_THROUGHPUT_FILES:-4}
bag_seconds=${JLE_BAG_SECONDS:-300}
csv_seconds=${JLE_CSV_SECONDS:-60}
if [ "${1:-}" = "--quick" ]; then files=2 bag_seconds=2 csv_seconds=2; fi
jobs=$(nproc)
bin=$ws/devel/lib/joint_load_estimator
tmp=$(mktemp -d /tmp/jle_throughput.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
bag_urdf=$repo/test/data/urdf/panda_demo.urdf
csv_urdf=$repo/test/data/urdf/chains/panda_chain.urdf
mkdir -p "$tmp/bags" "$tmp/csvs"
for i in $(seq "$files"); do
  "$bin/make_example_bag" --urdf "$bag_urdf" --output "$tmp/bags/panda_$i.bag" \
    --duration "$bag_seconds" --seed "$i" --effort >/dev/null
  "$bin/make_trajectory" --urdf "$csv_urdf" --duration "$csv_seconds" --seed "$i" \
    --wrench panda_link8 --output "$tmp/csvs/panda_$i.csv"
done
bag_samples=$((bag_seconds * 1000))
csv_samples=$((csv_seconds * 1000 + 1))
now() { date +%s.%N; }
status=0
echo "machine: $(nproc) cores; $(uptime)"
echo "inputs: $files bags of $bag_samples joint states ($(du -sh "$tmp/bags" | cut -f1) in all)," \
  "$files CSV files of $csv_samples rows ($(du -sh "$tmp/csvs" | cut -f1))"
echo
echo "| tool | files | jobs | samples | wall [s] | samples/s | speed-up | outputs equal to -j 1 |"
echo "|---|---|---|---|---|---|---|---|"
# One tool over every file, first -j 1 then -j $jobs; prints two rows.
measure() {
  local tool=$1 samples=$2 serial_wall=
  shift 2
  local inputs=("$tmp/${tool}_inputs"/*)
  for j in 1 "$jobs"; do
    local start end wall equal=-
    start=$(now)
    bash "$repo/tools/batch.sh" -j "$j" "$tmp/${tool}_j$j" "$tool" "$@" -- "${inputs[@]}" ||
      { echo "batch -j $j of $tool failed" >&2; status=1; }
    end=$(now)
    wall=$(awk -v s="$start" -v e="$end" 'BEGIN { printf "%.3f", e - s }')
    [ -n "$serial_wall" ] || serial_wall=$wall
    if [ "$j" != 1 ]; then
      equal=yes
      for f in "$tmp/${tool}_j1"/*.csv; do
        cmp -s "$f" "$tmp/${tool}_j$j/$(basename "$f")" || { equal=NO; status=1; }
      done
    fi
    awk -v t="$tool" -v n="$files" -v j="$j" -v s="$samples" -v w="$wall" -v w1="$serial_wall" \
      -v e="$equal" 'BEGIN { printf "| %s | %d | %d | %d | %.3f | %.0f | %.2f | %s |\n",
        t, n, j, n * s, w, n * s / w, w1 / w, e }'
  done
}
ln -s "$tmp/bags" "$tmp/process_bag_inputs"
ln -s "$tmp/csvs" "$tmp/joint_loads_inputs"
measure process_bag "$bag_samples" --urdf "$bag_urdf" --config "$repo/config/demo.yaml"
measure joint_loads "$csv_samples" --urdf "$csv_urdf"
echo
echo "process_bag alone on one file (its own closing line: the estimate alone, and with the bag I/O):"
grep -h "samples/s" "$tmp/process_bag_j1/panda_1.log"
echo "after the run: $(uptime)"
exit $status
