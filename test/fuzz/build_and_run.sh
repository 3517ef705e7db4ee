#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz_urdf, fuzz_csv, fuzz_messages) with clang++
# -fsanitize=fuzzer,address,undefined straight from the sources (no catkin), replays
# the regression inputs of each (test/fuzz/regressions/<target>/), then fuzzes each
# for a bounded time starting from its seed corpus (test/fuzz/corpus/<target>/).
# Fails on a crash, a sanitizer report, a leak or a timeout; a crashing input is left
# as crash-* in the work directory: copy it into regressions/<target>/.
#   build_and_run.sh [SECONDS_PER_TARGET (default 30)] [TARGET...]
#   JLE_FUZZ_DIR  work directory (default ~/.cache/joint_load_estimator/fuzz)
#   CXX           compiler (default clang++; Debian 12: packages clang, libclang-rt-14-dev)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
seconds=${1:-30}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_urdf fuzz_csv fuzz_messages)
work=${JLE_FUZZ_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/fuzz}
cxx=${CXX:-clang++}
mkdir -p "$work/obj"

san="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
common=(-std=c++17 -O1 -g $san -I"$repo/include" -I/usr/include/eigen3
        -DJLE_FUZZ_DATA="\"$repo/test/data\"" -Wall -Wextra)
# Every target links the whole ROS-free core (compiled once, shared; without the fuzzer
# runtime so that it holds no main): no list to keep up to date. The objects compile
# JLE_JOBS at a time (default 2), each rebuilt when its source or a header is newer.
core_sources=$(cd "$repo" && ls src/{model,filters,estimation,pipeline,settings,io}/*.cpp)
jobs=${JLE_JOBS:-2}
objs=()
build_failed=0
for src in $core_sources; do
  obj="$work/obj/$(echo "$src" | tr / _).o"
  objs+=("$obj")
  if [ ! -f "$obj" ] || [ -n "$(find "$repo/$src" "$repo/include" -newer "$obj" -print -quit)" ]; then
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || build_failed=1; done
    # Into a scratch file first: a failed compile leaves no object that looks current.
    ("$cxx" "${common[@]}" -fsanitize=fuzzer-no-link -c "$repo/$src" -o "$obj.tmp" &&
      mv "$obj.tmp" "$obj") &
  fi
done
for pid in $(jobs -p); do wait "$pid" || build_failed=1; done
[ "$build_failed" -eq 0 ] || { echo "FAIL  the core did not compile for the fuzzers"; exit 1; }
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=${JLE_FUZZ_LEAKS:-1}:allocator_may_return_null=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
status=0
for t in "${targets[@]}"; do
  "$cxx" "${common[@]}" -fsanitize=fuzzer "$here/$t.cpp" "${objs[@]}" -ltinyxml2 -lyaml-cpp -o "$work/$t"
  # Regressions first: each must now run clean.
  reg="$here/regressions/$t"
  if [ -d "$reg" ] && [ -n "$(ls -A "$reg")" ]; then
    if ! "$work/$t" -runs=0 "$reg"/* >"$work/$t.regressions.log" 2>&1; then
      tail -30 "$work/$t.regressions.log"
      echo "FAIL  $t: a regression input fails again (log: $work/$t.regressions.log)"
      status=1
      continue
    fi
  fi
  # Fuzz: a scratch corpus seeded from the repository's (which stays untouched).
  mkdir -p "$work/corpus/$t"
  start=$(date +%s)
  if (cd "$work" && "$work/$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
        -max_len=16384 -print_final_stats=1 "$work/corpus/$t" "$here/corpus/$t" \
        >"$work/$t.log" 2>&1); then
    echo "ok    $t: $(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$work/$t.log" |
      grep -oE '[0-9]+$') runs in $(($(date +%s) - start)) s"
  else
    grep -E "ERROR: |runtime error:|check failed:|terminate called|what\(\):|SUMMARY|Test unit written" \
      "$work/$t.log" | head -20 || true
    grep -E "^ *#[0-9]+ 0x" "$work/$t.log" | head -16 | sed 's/^ */  /' || true
    # The input itself, so that a CI machine gone afterwards still hands it over:
    # base64 -d > regressions/<target>/NAME restores it.
    for crash in $(find "$work" -maxdepth 1 -newermt "@$start" \
                     \( -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' \)); do
      echo "input $(basename "$crash") ($(stat -c %s "$crash") bytes), base64:"
      base64 -w 100 "$crash" | head -c 24000
      echo
    done
    echo "FAIL  $t (log: $work/$t.log; copy the crash-* input into $reg/)"
    status=1
  fi
done
exit $status
