#!/usr/bin/env bash
# rviz for robots the package has no demo for, under a virtual display (docs/rviz.md,
# docs/any_robot.md):
#   the UR5 (test/data/urdf/ur5_robot.urdf) through any_robot.launch: a screenshot of rviz
#   into docs/ur5_rviz.png, 5 s of ~joint_efforts plotted by plot_efforts into
#   docs/ur5_efforts.png, and what `rostopic echo` shows of ~joint_efforts into
#   docs/ur5_joint_efforts.txt;
#   the upright arm (test/data/urdf/upright_arm.urdf, meshes that do not resolve) through
#   the one command `estimator.launch model:=... rviz:=true`, its joint states from a bag:
#   a screenshot into docs/rviz_any_robot.png.
#   bash tools/ur5_rviz.sh     (JLE_WS: the workspace; ROS_PORT: the roscore it starts)
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws
port=${ROS_PORT:-11324}
bash "$repo/tools/install_deps.sh"  # rviz, xvfb and imagemagick among them
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
roslaunch joint_load_estimator any_robot.launch model:="$urdf" bag:="$out/ur5.bag" \
  >"$out/launch.log" 2>&1 &
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
kill -INT "${pids[0]}"
wait "${pids[0]}" || true
pids=("${pids[@]:1}")

# --- rviz for any robot, one command (docs/rviz.md) -------------------------------------
urdf=$(rospack find joint_load_estimator)/test/data/urdf/upright_arm.urdf
rosrun joint_load_estimator make_example_bag --urdf "$urdf" --output "$out/arm.bag" \
  --duration 20 --sensor-frame tool --tcp-frame tool
roslaunch joint_load_estimator estimator.launch model:="$urdf" rviz:=true use_sim_time:=true \
  >"$out/arm_launch.log" 2>&1 &
pids=("$!" "${pids[@]}")
rosbag play --clock --loop --quiet "$out/arm.bag" >/dev/null 2>&1 &
pids=("$!" "${pids[@]}")
timeout 60 rostopic echo -n 1 /joint_load_estimator/smoothed/wrench/wrist_roll >/dev/null
sleep 10  # rviz: the window, the model and a few seconds of wrenches
import -window root "$repo/docs/rviz_any_robot.png"
echo "wrote $repo/docs/ur5_rviz.png, $repo/docs/ur5_efforts.png, $repo/docs/ur5_joint_efforts.txt" \
  "and $repo/docs/rviz_any_robot.png"
