#!/usr/bin/env bash
# Makes docs/external_wrench.png (docs/external_loads.md, "External torques and contact wrenches"): the
# example bag (make_example_bag --effort --sensor-frame panda_hand_tcp) replayed through
# the node with config/external_demo.yaml, whose wrist wrench is NOT an input; rviz
# (config/external_demo.rviz, software GL on Xvfb display :23) draws the estimated
# external wrench (~external_wrench/panda_hand_tcp, red/orange) beside the applied one
# (/ft_sensor/wrench, green/blue), and `import` grabs the screen. Needs the package built
# (tools/build.sh) and rviz, Xvfb, ImageMagick. Usage: external_wrench_screenshot.sh [OUT.png]
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
out=${1:-$repo/docs/external_wrench.png}
export PATH=/usr/bin:$PATH
set +u
# shellcheck disable=SC1091
source "$ws/devel/setup.bash"
set -u
tmp=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
urdf=$repo/test/data/urdf/panda_demo.urdf
bag=$tmp/contact.bag
"$ws/devel/lib/joint_load_estimator/make_example_bag" --urdf "$urdf" --output "$bag" --effort \
  --sensor-frame panda_hand_tcp --duration 8 >/dev/null

export ROS_MASTER_URI=http://127.0.0.1:11523
roscore -p 11523 >"$tmp/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.1; done
Xvfb :23 -screen 0 1280x800x24 >"$tmp/xvfb.log" 2>&1 &
pids+=($!)
export DISPLAY=:23 LIBGL_ALWAYS_SOFTWARE=1
rosparam set use_sim_time true
rosparam set robot_description -t "$urdf"
rosparam load "$repo/config/external_demo.yaml" /joint_load_estimator
rosrun robot_state_publisher robot_state_publisher >"$tmp/rsp.log" 2>&1 &
pids+=($!)
rosrun joint_load_estimator joint_load_estimator __name:=joint_load_estimator \
  >"$tmp/node.log" 2>&1 &
pids+=($!)
rviz -d "$repo/config/external_demo.rviz" >"$tmp/rviz.log" 2>&1 &
pids+=($!)
sleep 10  # rviz on software GL takes a while to come up
rosbag play --clock -q -r 0.5 "$bag" >"$tmp/play.log" 2>&1 &
pids+=($!)
sleep 8  # 4 s of the bag: the observer has settled (its lag is 16 ms)
import -window root "$out"
echo "wrote $out"
