#!/usr/bin/env bash
# Many bags or CSV files at once, one process per file, as many at a time as there are
# cores (docs/offline_tools.md "Offline: many files at once"):
#   tools/batch.sh [-j N] OUT_DIR process_bag [process_bag options] -- IN.bag...
#   tools/batch.sh [-j N] OUT_DIR joint_loads [joint_loads options] -- IN.csv...
# Each input IN gives OUT_DIR/<IN's name without .bag/.csv>.csv (process_bag --csv,
# joint_loads --output) and its messages in OUT_DIR/<name>.log. Every file is
# processed as if alone, so the outputs equal a serial run's byte for byte. Exit status:
# 0 when every file succeeded; otherwise 1 with the failed inputs named (2: usage).
set -euo pipefail
usage() { sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
jobs=$(nproc)
if [ "${1:-}" = "-j" ]; then
  [ $# -ge 2 ] || usage
  jobs=$2; shift 2
fi
[[ "$jobs" =~ ^[1-9][0-9]*$ ]] || { echo "batch: -j: '$jobs' is not a positive integer" >&2; exit 2; }
[ $# -ge 3 ] || usage
out=$1 tool=$2
shift 2
case $tool in
  process_bag) input_flag=--bag output_flag=--csv ;;
  joint_loads) input_flag=--input output_flag=--output ;;
  *) echo "batch: tool '$tool' is not process_bag or joint_loads" >&2; exit 2 ;;
esac
options=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do options+=("$1"); shift; done
[ "${1:-}" = "--" ] || { echo "batch: no '--' before the input files" >&2; exit 2; }
shift
[ $# -ge 1 ] || { echo "batch: no input files after '--'" >&2; exit 2; }
declare -A seen
for f in "$@"; do
  name=$(basename "$f"); name=${name%.bag}; name=${name%.csv}
  [ -z "${seen[$name]:-}" ] || { echo "batch: '$f' and '${seen[$name]}' would both write $out/$name.csv" >&2; exit 2; }
  seen[$name]=$f
done
# The tool: beside this script in a catkin workspace, or on PATH (rosrun's directory).
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
exe=$ws/devel/lib/joint_load_estimator/$tool
[ -x "$exe" ] || exe=$(command -v "$tool" || true)
[ -n "$exe" ] && [ -x "$exe" ] || { echo "batch: $tool not found (build first, or set JLE_WS)" >&2; exit 1; }
mkdir -p "$out"
# One file: its output and log under OUT_DIR; its status in OUT_DIR/<name>.status.
one() {
  local f=$1 name
  name=$(basename "$f"); name=${name%.bag}; name=${name%.csv}
  local status=0
  "$exe" "${options[@]}" "$input_flag" "$f" "$output_flag" "$out/$name.csv" >"$out/$name.log" 2>&1 || status=$?
  echo "$status" >"$out/$name.status"
}
export -f one
export exe input_flag output_flag out
# Bash cannot export arrays: the options travel as arguments, the file (which xargs
# appends) last.
printf '%s\0' "$@" | xargs -0 -n 1 -P "$jobs" bash -c 'options=("${@:1:$#-1}"); one "${!#}"' _ \
  "${options[@]+"${options[@]}"}"
failed=0
for f in "$@"; do
  name=$(basename "$f"); name=${name%.bag}; name=${name%.csv}
  s=$(cat "$out/$name.status" 2>/dev/null || echo "?")
  rm -f "$out/$name.status"
  if [ "$s" != 0 ]; then
    echo "batch: $f failed (exit $s): $(tail -1 "$out/$name.log" 2>/dev/null)" >&2
    failed=1
  fi
done
exit $failed
