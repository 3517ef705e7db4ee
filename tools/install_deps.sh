#!/usr/bin/env bash
# Installs what the package needs to build, run and test, from Debian 12's own
# packages (ROS 1 Noetic-era in /usr). Safe to run again: apt skips what is there.
set -euo pipefail
packages=(
  build-essential cmake catkin python3-catkin-pkg
  ros-base-dev libroscpp-dev ros-message-generation libstd-msgs-dev
  libsensor-msgs-dev libgeometry-msgs-dev libtf2-ros-dev libtf2-eigen-dev libtf2-msgs-dev
  libdiagnostic-updater-dev librosbag-dev libnodelet-dev pluginlib-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure  # ~reconfigure (.cfg: python at build time)
  python3-diagnostic-msgs python3-rostopic python3-rosnode python3-rosservice python3-rosparam python3-yaml rospack-tools  # README's rostopic/rosservice commands
  libeigen3-dev libtinyxml2-dev libyaml-cpp-dev
  libgtest-dev libbenchmark-dev librostest-dev python3-rostest python3-roslaunch
  python3-rosbag python3-sensor-msgs python3-geometry-msgs python3-std-msgs
  liborocos-kdl-dev libkdl-parser-dev liburdf-dev
  ros-robot-state-publisher rosbash
  python3-matplotlib        # tools/examples/plot_loads.py, bench/plot_*.py
  pybind11-dev python3-pybind11 python3-numpy   # the Python bindings (docs/python.md)
  python3-pytest            # test/python (the bindings' tests)
  catkin-tools              # test/scripts/fresh_workspace.sh: `catkin build` as a user runs it
  rviz python3-visualization-msgs  # estimator.launch rviz:=true (joint_labels: MarkerArray)
  xvfb imagemagick          # test/python/test_rviz.py: rviz on a virtual display, screenshots
  python3-scipy             # test/scripts/zero_phase_reference.py (the independent reference)
  clang libclang-rt-14-dev  # libFuzzer for test/fuzz/build_and_run.sh
  clang-format              # tools/format.sh (the style is tuned on Debian's 14)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -q
  apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
