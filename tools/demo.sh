#!/usr/bin/env bash
# The demo, headless: installs what is missing, builds, makes the example bag (once, in
# the workspace, not in the repository), replays it through the estimator with
# roslaunch (launch/demo.launch rviz:=false) and prints the table of the joint loads.
# About 15 s once built. With rviz, and what the numbers mean: docs/demo.md.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws

bash "$repo/tools/install_deps.sh"
bash "$repo/tools/build.sh" >"${TMPDIR:-/tmp}/joint_load_estimator_demo_build.log" 2>&1 || {
  tail -40 "${TMPDIR:-/tmp}/joint_load_estimator_demo_build.log"
  echo "demo: the build failed (log: ${TMPDIR:-/tmp}/joint_load_estimator_demo_build.log)" >&2
  exit 1
}

# Debian's ROS tools need the system python, not a pyenv shim.
export PATH=/usr/bin:$PATH
set +u  # catkin's setup scripts read unset variables
# shellcheck disable=SC1091
source "$ws/devel/setup.bash"
set -u

demo=$ws/demo
mkdir -p "$demo"
bag=$demo/panda_example.bag
urdf=$repo/test/data/urdf/panda_demo.urdf
maker=$ws/devel/lib/joint_load_estimator/make_example_bag
if [ ! -s "$bag" ] || [ "$maker" -nt "$bag" ] || [ "$urdf" -nt "$bag" ]; then
  echo "demo: making the example bag $bag"
  "$maker" --urdf "$urdf" --output "$bag" --effort
fi

# A master of our own on a free port: the demo sets use_sim_time, which must not reach
# a ROS system that may be running on this machine.
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port
summary=$demo/summary.txt
log=$demo/roslaunch.log
rm -f "$summary"
echo "demo: replaying 10 s of a Panda with a wrist force/torque sensor through the estimator"
start=$(date +%s.%N)
roslaunch -p "$port" joint_load_estimator demo.launch rviz:=false bag:="$bag" \
  summary:="$summary" >"$log" 2>&1 </dev/null || true
end=$(date +%s.%N)
if ! grep -q " messages, " "$summary" 2>/dev/null; then
  tail -30 "$log"
  echo "demo: no loads were received (roslaunch's output: $log)" >&2
  exit 1
fi
echo
cat "$summary"
echo
awk -v s="$start" -v e="$end" -v f="$log" 'BEGIN { printf "demo: roslaunch ran %.1f s (log: %s)\n", e - s, f }'
