# Sourced by the study scripts (tools/accuracy.sh, tools/stability.sh, tools/zero_phase.sh,
# tools/uncertainty.sh, tools/adaptive_filter.sh, bench/external_effort.sh) after they set
# `repo`: sets `ws` (JLE_WS as for tools/build.sh, exported) and defines study_build NAME
# ARG..., which builds the targets ARG... (tools/build.sh, JLE_JOBS jobs, default 2) into
# $ws/NAME_build.log and stops the script with the log's tail where the build fails.
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
export JLE_WS=$ws
mkdir -p "$ws"

study_build() {
  local name=$1 log="$ws/$1_build.log"
  shift
  if ! bash "$repo/tools/build.sh" -j"${JLE_JOBS:-2}" "$@" >"$log" 2>&1; then
    tail -40 "$log"
    echo "$name: build failed (log: $log)" >&2
    exit 1
  fi
}
