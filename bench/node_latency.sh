#!/usr/bin/env bash
# End-to-end latency of the estimator on one machine (docs/studies/node_latency.md), through
# both paths in one run: a private master, the Panda chain with two wrench inputs
# (bench/node_latency.yaml), and the bench's driver side (bench/node_latency.cpp,
# joint_load_estimator/LatencyBenchNodelet) at each rate:
#   nodelet: the estimator nodelet and the bench nodelet in one nodelet manager (the
#            messages are passed as shared pointers, never serialised);
#   tcp:     the joint_load_estimator node and the bench in a process of its own
#            (`nodelet standalone`; roscpp's TCP transport, tcpNoDelay);
# the nodelet path also with the estimator's inline_callbacks true ("inline"), and with
# the bench's receiver inline too (~inline_receiver).
# Usage: bench/node_latency.sh [seconds per rate] [repeats]   (the package must be built)
#        bench/node_latency.sh --page [seconds per rate] [repeats]   (default 3 s, 3 repeats:
#          about 5 min) builds the node, the nodelets and the bench (tools/build.sh, JLE_WS
#          as there), runs, and writes docs/studies/node_latency.md (bench/node_latency_page.py).
# (JLE_BENCH_RATES="[1000, 5000, 10000]" the rates; JLE_BENCH_PORT the master's port.)
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
page=
if [ "${1:-}" = "--page" ]; then
  page=$repo/docs/studies/node_latency.md
  shift
  mkdir -p "$ws"
  bash "$repo/tools/build.sh" -j"${JLE_JOBS:-2}" joint_load_estimator_node joint_load_estimator_nodelet \
    joint_load_estimator_bench_nodelet >"$ws/node_latency_build.log" 2>&1 ||
    { tail -30 "$ws/node_latency_build.log"; echo "node_latency: build failed" >&2; exit 1; }
  seconds=${1:-3}
  repeats=${2:-3}
else
  seconds=${1:-2.0}
  repeats=${2:-1}
fi
load_before=$(/usr/bin/python3 "$repo/tools/study_page.py" load)
started=$SECONDS
export PATH=/usr/bin:$PATH
set +u; source "$ws/devel/setup.bash"; set -u
export ROS_MASTER_URI=http://127.0.0.1:${JLE_BENCH_PORT:-11517}
export ROS_HOSTNAME=127.0.0.1
log=$(mktemp -d /tmp/jle_node_latency.XXXXXX)
roscore -p "${ROS_MASTER_URI##*:}" >"$log/roscore.log" 2>&1 &
core=$!
pids=()
cleanup() {
  for p in "${pids[@]}" $core; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.1; done
rosparam set -t "$repo/test/data/urdf/chains/panda_chain.urdf" robot_description
rosparam load "$repo/bench/node_latency.yaml" /joint_load_estimator
rates=${JLE_BENCH_RATES:-[1000, 5000, 10000]}
# The nodelet executable (Debian's path, else through rosrun).
nodelet=(/usr/lib/nodelet/nodelet)
[ -x "${nodelet[0]}" ] || nodelet=(rosrun nodelet nodelet)
status=0

# Runs "$@" (the process that holds the bench) until the bench asks it to stop.
run_bench() {
  local out=$1 bench_timeout
  shift
  bench_timeout=$(awk -v s="$seconds" -v r="$rates" \
    'BEGIN { n = gsub(/,/, ",", r) + 1; print int(60 + n * (s + 3)) }')
  timeout "$bench_timeout" "$@" >"$out" 2>&1 || { echo "the bench failed (log: $out)" >&2; status=1; }
  grep -E '^\|' "$out" || { echo "no figures (log: $out)" >&2; status=1; }
  # Every rate must have had its loads (column 5: loads received).
  awk -F'|' '/^\| [a-z]/ && $3 ~ /[0-9]/ && $5 + 0 == 0 { bad = 1 } END { exit bad }' "$out" ||
    { echo "a rate without loads (log: $out)" >&2; status=1; }
}

stop_all() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  pids=()
}

# One configuration: $1 the path's name, $2 the estimator's inline_callbacks, $3 the
# bench receiver's (~inline_receiver), $4 the run's number.
configure() {
  echo "run $4, $1; $(uptime)"
  echo "$4|$1|$(/usr/bin/python3 "$repo/tools/study_page.py" load)" >>"$log/loads.txt"
  printf 'joint_load_estimator: {inline_callbacks: %s}\nnode_latency_bench: {inline_receiver: %s, path: "%s", seconds: %s, rates: %s}\n' \
    "$2" "$3" "$1" "$seconds" "$rates" >"$log/params.yaml"
  rosparam load "$log/params.yaml"  # one process: each costs a second on a loaded machine
}

nodelet_path() {
  configure "$@"
  "${nodelet[@]}" load joint_load_estimator/EstimatorNodelet jle_latency_manager \
    __name:=joint_load_estimator >"$log/load_estimator_$4.log" 2>&1 &
  pids+=($!)
  "${nodelet[@]}" load joint_load_estimator/LatencyBenchNodelet jle_latency_manager \
    __name:=node_latency_bench >"$log/load_bench_$4.log" 2>&1 &
  pids+=($!)
  # The loaders wait for the manager; the bench nodelet shuts the manager down when done.
  run_bench "$log/$4_$1.out" "${nodelet[@]}" manager __name:=jle_latency_manager
  stop_all
}

tcp_path() {
  configure "$@"
  "$ws/devel/lib/joint_load_estimator/joint_load_estimator" >"$log/node_$4.log" 2>&1 &
  pids+=($!)
  run_bench "$log/$4_$1.out" "${nodelet[@]}" standalone joint_load_estimator/LatencyBenchNodelet \
    __name:=node_latency_bench
  stop_all
}

for r in $(seq "$repeats"); do
  nodelet_path nodelet false false "$r"
  nodelet_path "nodelet, inline" true false "$r"
  nodelet_path "nodelet, inline, inline receiver" true true "$r"
  tcp_path tcp false false "$r"
done
echo "logs: $log; after the run: $(uptime)"
if [ -n "$page" ] && [ $status -eq 0 ]; then
  /usr/bin/python3 "$repo/bench/node_latency_page.py" --log "$log" --seconds "$seconds" \
    --repeats "$repeats" --wall $((SECONDS - started)) --rates "$rates" --load-before "$load_before" \
    --load-after "$(/usr/bin/python3 "$repo/tools/study_page.py" load)" --output "$page"
fi
exit $status
