#!/usr/bin/env bash
# The gait demo: installs what is missing, builds, makes the body's URDF and a walking
# trial over two force plates (make_gait_bag; once, in the workspace, not in the
# repository), replays it through the estimator (launch/gait_demo.launch) and prints a
# summary: samples, peak joint moments per kg, the largest pelvis residual relative to
# body weight. docs/gait_demo.md.
#   bash tools/gait_demo.sh                       headless, the bundled 75 kg / 1.75 m body
#   bash tools/gait_demo.sh --mass 62 --height 1.68   another body (make_body_urdf)
#   bash tools/gait_demo.sh --rviz                in rviz (the bag loops; Ctrl-C ends it)
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws

rviz=false mass="" height=""
while [ $# -gt 0 ]; do
  case "$1" in
    --rviz) rviz=true ;;
    --mass) mass=${2:?--mass needs a value}; shift ;;
    --height) height=${2:?--height needs a value}; shift ;;
    -h|--help) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "gait_demo: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done
if { [ -n "$mass" ] && [ -z "$height" ]; } || { [ -z "$mass" ] && [ -n "$height" ]; }; then
  echo "gait_demo: --mass and --height go together" >&2
  exit 2
fi

bash "$repo/tools/install_deps.sh"
log_build=${TMPDIR:-/tmp}/joint_load_estimator_gait_demo_build.log
bash "$repo/tools/build.sh" >"$log_build" 2>&1 || {
  tail -40 "$log_build"
  echo "gait_demo: the build failed (log: $log_build)" >&2
  exit 1
}

# Debian's ROS tools need the system python, not a pyenv shim.
export PATH=/usr/bin:$PATH
set +u  # catkin's setup scripts read unset variables
# shellcheck disable=SC1091
source "$ws/devel/setup.bash"
set -u
bin=$ws/devel/lib/joint_load_estimator

demo=$ws/gait_demo
mkdir -p "$demo"
if [ -n "$mass" ]; then
  urdf=$demo/body_${mass}kg_${height}m.urdf
  if [ ! -x "$bin/make_body_urdf" ]; then
    echo "gait_demo: make_body_urdf is not built: --mass and --height need it" >&2
    exit 1
  fi
  "$bin/make_body_urdf" --mass "$mass" --height "$height" --output "$urdf"
  bag=$demo/gait_${mass}kg_${height}m.bag
else
  urdf=$repo/test/data/urdf/body_75kg_175cm.urdf
  bag=$demo/gait.bag
fi
report=${bag%.bag}.txt
if [ ! -s "$bag" ] || [ "$bin/make_gait_bag" -nt "$bag" ] || [ "$urdf" -nt "$bag" ]; then
  echo "gait_demo: making the trial $bag"
  "$bin/make_gait_bag" --urdf "$urdf" --output "$bag" >"$report"
fi
cat "$report"
body_mass=$(awk '/^  body / { print $2; exit }' "$report")

# A master of our own on a free port: the demo sets use_sim_time, which must not reach
# a ROS system that may be running on this machine.
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port
launch_log=$demo/roslaunch.log

if [ "$rviz" = true ]; then
  exec roslaunch -p "$port" joint_load_estimator gait_demo.launch bag:="$bag" model:="$urdf"
fi

roscore -p "$port" >"$demo/roscore.log" 2>&1 &
roscore_pid=$!
echo_pid=""
cleanup() {
  [ -n "$echo_pid" ] && kill -INT "$echo_pid" 2>/dev/null || true
  kill -INT "$roscore_pid" 2>/dev/null || true
  wait 2>/dev/null || true
}
trap cleanup EXIT
for _ in $(seq 100); do
  rostopic list >/dev/null 2>&1 && break
  sleep 0.1
done
rostopic list >/dev/null 2>&1 || { echo "gait_demo: the ROS master did not start" >&2; exit 1; }

# The pelvis residual, as the node publishes it (only while someone listens).
residual=$demo/base_residual.csv
rostopic echo -p /joint_load_estimator/base_residual >"$residual" 2>/dev/null &
echo_pid=$!
summary=$demo/summary.txt
rm -f "$summary"
echo "gait_demo: replaying the trial through the estimator"
roslaunch -p "$port" joint_load_estimator gait_demo.launch rviz:=false bag:="$bag" \
  model:="$urdf" summary:="$summary" >"$launch_log" 2>&1 </dev/null || true
kill -INT "$echo_pid" 2>/dev/null || true
wait "$echo_pid" 2>/dev/null || true
echo_pid=""
if ! grep -q " messages, " "$summary" 2>/dev/null; then
  tail -30 "$launch_log"
  echo "gait_demo: no loads were received (roslaunch's output: $launch_log)" >&2
  exit 1
fi
echo
head -3 "$summary"
echo
# Peak joint moments per kg: max |effort| (column 3 of the table) / body mass.
echo "  peak |moment|: of either sign. Sign convention: positive = flexion, adduction, internal"
echo "  rotation, dorsiflexion, as the moment on the distal segment (Winter plots the opposite"
echo "  sign for hip, knee and ankle); signed peaks and their instants: tools/gait_peaks.py"
awk -v m="$body_mass" 'NR > 3 && NF >= 5 {
    printf "  %-18s peak |moment| %7.1f N m = %5.2f N m/kg\n", $1, $3, $3 / m }' "$summary"
# The residual: what the plates do not explain (filter error only, for this trial).
awk -F, -v m="$body_mass" 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
  { fx = $col["field.wrench.force.x"]; fy = $col["field.wrench.force.y"]; fz = $col["field.wrench.force.z"]
    mx = $col["field.wrench.torque.x"]; my = $col["field.wrench.torque.y"]; mz = $col["field.wrench.torque.z"]
    f = sqrt(fx * fx + fy * fy + fz * fz); t = sqrt(mx * mx + my * my + mz * mz)
    if (f > fmax) fmax = f; if (t > tmax) tmax = t; ++n }
  END { w = m * 9.80665
    if (n == 0) { print "gait_demo: no pelvis residual received"; exit 1 }
    printf "\npelvis residual over %d samples: max |force| %.1f N = %.2f %% of body weight, max |moment| %.1f N m = %.2f %% of body weight x 1 m\n",
      n, fmax, 100 * fmax / w, tmax, 100 * tmax / w }' "$residual"
