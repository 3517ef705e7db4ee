#!/usr/bin/env bash
# Builds the package in a catkin workspace beside nothing but this repository.
# JLE_WS (default: ~/.cache/joint_load_estimator/ws) holds the workspace; outside the
# repository, so that no tool crawling the workspace loops back into it.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
mkdir -p "$ws/src"
ln -sfn "$repo" "$ws/src/joint_load_estimator"
# Debian's catkin needs the system python (with catkin_pkg), not a pyenv shim.
export PATH=/usr/bin:$PATH
cd "$ws"
catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release "$@"
