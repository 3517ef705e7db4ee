#!/usr/bin/env bash
# End-to-end latency of the node on loopback (docs/node_latency.md): starts a private
# master, the node on the Panda chain with two wrench inputs, and the publisher/
# receiver bench at increasing rates. Usage: bench/node_latency.sh [seconds per rate]
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
seconds=${1:-2.0}
export PATH=/usr/bin:$PATH
set +u; source "$ws/devel/setup.bash"; set -u
export ROS_MASTER_URI=http://127.0.0.1:${JLE_BENCH_PORT:-11517}
export ROS_HOSTNAME=127.0.0.1
roscore -p "${ROS_MASTER_URI##*:}" >/tmp/jle_bench_roscore.log 2>&1 &
core=$!
trap 'kill $node $core 2>/dev/null || true; wait 2>/dev/null || true' EXIT
node=
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.1; done
rosparam set -t "$repo/test/data/urdf/chains/panda_chain.urdf" robot_description
rosparam load "$repo/bench/node_latency.yaml" /joint_load_estimator
"$ws/devel/lib/joint_load_estimator/joint_load_estimator" >/tmp/jle_bench_node.log 2>&1 &
node=$!
"$ws/devel/lib/joint_load_estimator/bench_node_latency" _seconds:="$seconds" ${JLE_BENCH_RATES:+_rates:="$JLE_BENCH_RATES"}
