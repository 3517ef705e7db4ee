#!/usr/bin/env bash
# The docs/any_robot.md "Any robot" commands on the UR5 (test/data/urdf/ur5_robot.urdf), run under
# a virtual display, with a screenshot of rviz into docs/ur5_rviz.png, 5 s of
# ~joint_efforts plotted by plot_efforts into docs/ur5_efforts.png, and what
# `rostopic echo` shows of ~joint_efforts into docs/ur5_joint_efforts.txt.
#   bash tools/ur5_rviz.sh     (JLE_WS: the workspace; ROS_PORT: the roscore it starts)
# Needs rviz, xvfb and imagemagick (installed here if missing: not CI dependencies).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws
port=${ROS_PORT:-11324}
missing=()
for p in rviz xvfb imagemagick; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
bash "$repo/tools/install_deps.sh"
bash "$repo/tools/build.sh" -j1 joint_load_estimator_node make_example_bag >/dev/null
export PATH=/usr/bin:$PATH
set +u
# shellcheck disable=SC1091
source "$ws/devel/setup.bash"
set -u
export ROS_MASTER_URI=http://localhost:$port
out=$ws/any_robot
mkdir -p "$out"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
}
trap cleanup EXIT
roscore -p "$port" >"$out/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.2; done
Xvfb :24 -screen 0 1200x800x24 >"$out/xvfb.log" 2>&1 &
pids+=($!)
export DISPLAY=:24 LIBGL_ALWAYS_SOFTWARE=1

# --- the docs/any_robot.md commands---------------------------------------------------------
urdf=$(rospack find joint_load_estimator)/test/data/urdf/ur5_robot.urdf
rosrun joint_load_estimator make_example_bag --urdf "$urdf" --output "$out/ur5.bag" \
  --sensor-frame tool0 --tcp-frame tool0
rosrun joint_load_estimator rviz_config --urdf "$urdf" --output "$out/ur5.rviz"
roslaunch joint_load_estimator any_robot.launch model:="$urdf" bag:="$out/ur5.bag" \
  rviz_config:="$out/ur5.rviz" >"$out/launch.log" 2>&1 &
pids=("$!" "${pids[@]}")
timeout 60 rostopic echo -n 1 /joint_load_estimator/joint_efforts >/dev/null
rosrun joint_load_estimator plot_efforts /joint_load_estimator/joint_efforts --seconds 5 \
  --output "$repo/docs/ur5_efforts.png"
# ---------------------------------------------------------------------------------------

sleep 10  # rviz: the window, the model and a few seconds of wrenches
import -window root "$repo/docs/ur5_rviz.png"
{
  echo "\$ rostopic echo -n 1 /joint_load_estimator/joint_efforts"
  rostopic echo -n 1 /joint_load_estimator/joint_efforts
  echo "\$ rostopic hz /joint_load_estimator/joint_efforts   (5 s)"
  timeout 5 rostopic hz /joint_load_estimator/joint_efforts 2>&1 | tail -2 || true
} >"$repo/docs/ur5_joint_efforts.txt"
echo "wrote $repo/docs/ur5_rviz.png, $repo/docs/ur5_efforts.png and $repo/docs/ur5_joint_efforts.txt"
