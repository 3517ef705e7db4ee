#!/usr/bin/env bash
# Soak of the real node over ROS: a private roscore on a free port, the Panda chain in
# robot_description, the joint_load_estimator executable with test/soak/node_soak.yaml,
# then the driver (test/soak/node_soak.cpp) feeding it 1e6 joint states with bad
# messages mixed in and checking its loads, diagnostics and memory. Exit status: the
# verdict (0 ok, 1 a failed check or the node died, 2 usage).
# Usage: node_soak.sh [--page] [--samples N] [other node_soak options]; needs the `tests`
# build (JLE_WS as for tools/build.sh). --page: a passing run also writes its figures into
# docs/studies/node_soak.md (test/soak/node_soak_page.py).
set -euo pipefail
page=0
if [ "${1:-}" = "--page" ]; then page=1; shift; fi
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
repo=$(cd "$(dirname "$0")/../.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
bin=$ws/devel/lib/joint_load_estimator
config=$repo/test/soak/node_soak.yaml
urdf=$repo/test/data/urdf/chains/panda_chain.urdf
for exe in joint_load_estimator node_soak; do
  [ -x "$bin/$exe" ] || { echo "node_soak.sh: $bin/$exe is not built (tools/build.sh tests)" >&2; exit 1; }
done
export PATH=/usr/bin:$PATH
set +u
# shellcheck disable=SC1091
source "$ws/devel/setup.bash"
set -u

port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port
export ROS_HOME=$(mktemp -d /tmp/node_soak.XXXXXX)
export ROS_LOG_DIR=$ROS_HOME/log
core_pid="" node_pid=""
cleanup() {
  for p in $node_pid $core_pid; do kill -INT "$p" 2>/dev/null || true; done
  for p in $node_pid $core_pid; do wait "$p" 2>/dev/null || true; done
  rm -rf "$ROS_HOME"
}
trap cleanup EXIT

roscore -p "$port" >"$ROS_HOME/roscore.log" 2>&1 &
core_pid=$!
for _ in $(seq 100); do  # up to 10 s for the master
  rosparam list >/dev/null 2>&1 && break
  kill -0 "$core_pid" 2>/dev/null || { cat "$ROS_HOME/roscore.log"; echo "roscore died"; exit 1; }
  sleep 0.1
done
rosparam list >/dev/null 2>&1 || { echo "FAILED: no ROS master on $ROS_MASTER_URI"; exit 1; }
rosparam set -t "$urdf" /robot_description
rosparam load "$config" /joint_load_estimator

"$bin/joint_load_estimator" >"$ROS_HOME/node.log" 2>&1 &
node_pid=$!
echo "node_soak.sh: master $ROS_MASTER_URI, node pid $node_pid"
status=0
"$bin/node_soak" --pid "$node_pid" --config "$config" "$@" >"$ROS_HOME/soak.txt" || status=$?
cat "$ROS_HOME/soak.txt"
if kill -0 "$node_pid" 2>/dev/null; then
  kill -INT "$node_pid"
  node_status=0
  wait "$node_pid" || node_status=$?
  node_pid=""
  if [ "$node_status" -ne 0 ]; then
    echo "FAILED: the node exited with status $node_status on SIGINT"
    [ "$status" -ne 0 ] || status=1
  fi
else
  echo "FAILED: the node is not running at the end"
  [ "$status" -ne 0 ] || status=1
fi
if [ "$status" -ne 0 ]; then
  echo "node log (last 20 lines):"
  tail -20 "$ROS_HOME/node.log"
fi
if [ "$status" -eq 0 ] && [ "$page" -eq 1 ]; then
  /usr/bin/python3 "$repo/test/soak/node_soak_page.py" "$ROS_HOME/soak.txt" "$load_before" \
    "$(cut -d' ' -f1-3 /proc/loadavg)" "bash test/soak/node_soak.sh --page${*:+ $*}" || status=1
fi
echo "node_soak.sh: exit status $status"
exit "$status"
