#!/usr/bin/env bash
# The package built as a user builds it (README, "Your own robot in five minutes", step
# 1): a new catkin workspace with the repository's tracked files in src/, plain
# catkin_make (or, with JLE_BUILDER=catkin_build, catkin_tools' `catkin build`), then,
# from that workspace: every program rosrun finds answers --help (exit 0, at once), and
# the node started with estimator.launch on a URDF publishes ~joint_efforts for a bag of
# joint states. Exits non-zero naming what failed.
#   bash test/scripts/fresh_workspace.sh [WORKDIR]   (default: a new temporary directory,
#                                                     removed at the end)
# ROS_PORT: the roscore it starts (default 11397). Part of tools/test.sh (both builders).
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
work=${1:-}
temporary=""
[ -n "$work" ] || { work=$(mktemp -d); temporary=$work; }
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  [ -z "$temporary" ] || rm -rf "$temporary"
}
trap cleanup EXIT
ws=$work/catkin_ws
pkg=$ws/src/joint_load_estimator
rm -rf "$ws" && mkdir -p "$pkg"
# What a clone holds: the tracked files (a copy of the tree where git is not there).
if git -C "$repo" rev-parse --git-dir >/dev/null 2>&1; then
  (cd "$repo" && git ls-files -z | xargs -0 cp --parents -t "$pkg")
else
  (cd "$repo" && tar --exclude=.git -cf - .) | (cd "$pkg" && tar -xf -)
fi
export PATH=/usr/bin:$PATH  # Debian's catkin needs the system python
cd "$ws"
builder=${JLE_BUILDER:-catkin_make}
log=$work/$builder.log
echo "fresh_workspace: $builder in $ws"
case "$builder" in
  catkin_make)
    build() {
      catkin_make -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 \
        -j"${JLE_JOBS:-2}"
    } ;;
  catkin_build)
    build() {
      catkin init &&
        catkin config --cmake-args -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 &&
        catkin build --no-status --no-notify -j"${JLE_JOBS:-2}"
    } ;;
  *) echo "fresh_workspace: JLE_BUILDER is catkin_make or catkin_build" >&2; exit 2 ;;
esac
if ! build >"$log" 2>&1; then
  tail -40 "$log"
  echo "fresh_workspace: $builder failed (log: $log)" >&2
  exit 1
fi
set +u
# shellcheck disable=SC1091
source devel/setup.bash
set -u
status=0
# Every program under rosrun's eyes answers --help at once, exit 0.
programs=$(find -L devel/lib/joint_load_estimator -maxdepth 1 -type f -perm -u+x -printf '%f\n' | sort)
for p in $programs; do
  if ! timeout 10 rosrun joint_load_estimator "$p" --help >"$work/help_$p.log" 2>&1; then
    echo "fresh_workspace: rosrun joint_load_estimator $p --help failed:" >&2
    tail -5 "$work/help_$p.log" >&2
    status=1
  fi
done
echo "fresh_workspace: --help of $(echo "$programs" | wc -w) programs: $programs" | tr '\n' ' '
echo
# The node from this workspace, on a URDF and a bag of joint states.
port=${ROS_PORT:-11397}
export ROS_MASTER_URI=http://localhost:$port
roscore -p "$port" >"$work/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.2; done
urdf=$(rospack find joint_load_estimator)/test/data/urdf/ur5_robot.urdf
rosrun joint_load_estimator make_example_bag --urdf "$urdf" --output "$work/ur5.bag" \
  --sensor-frame tool0 --tcp-frame tool0 --duration 3 >"$work/make_example_bag.log" 2>&1 ||
  { cat "$work/make_example_bag.log" >&2; exit 1; }
roslaunch joint_load_estimator estimator.launch model:="$urdf" >"$work/launch.log" 2>&1 &
pids=("$!" "${pids[@]}")
rosbag play --quiet --delay 2 "$work/ur5.bag" >"$work/play.log" 2>&1 &
pids=("$!" "${pids[@]}")
if timeout 30 rostopic echo -n 1 /joint_load_estimator/joint_efforts >"$work/efforts.txt" 2>&1 &&
  grep -q "shoulder_pan_joint" "$work/efforts.txt"; then
  echo "fresh_workspace: the node ran from the workspace; one ~joint_efforts message:"
  grep -A1 "^effort" "$work/efforts.txt" | head -3
else
  echo "fresh_workspace: no ~joint_efforts from the node in 30 s" >&2
  tail -20 "$work/launch.log" >&2
  status=1
fi
exit $status
