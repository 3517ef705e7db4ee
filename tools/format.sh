#!/usr/bin/env bash
# Formats the C++ sources (src/ include/ test/ bench/) with clang-format and the
# repository's .clang-format, in place.
#   format.sh            formats every file
#   format.sh --check    changes nothing; lists the files that are not formatted and
#                        fails if there is one
#   format.sh [--check] FILE...   the same on the given files only
#   CLANG_FORMAT  the binary (default clang-format; the style is tuned on Debian's 14:
#                 other versions may format a few constructs differently)
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
clang_format=${CLANG_FORMAT:-clang-format}
check=0
if [ "${1:-}" = "--check" ]; then
  check=1
  shift
fi
cd "$repo"
if [ $# -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(git ls-files -- 'src/*.cpp' 'src/*.hpp' 'include/*.hpp' \
    'test/*.cpp' 'test/*.hpp' 'bench/*.cpp' 'bench/*.hpp')
fi
[ ${#files[@]} -gt 0 ] || { echo "format.sh: no file"; exit 1; }
if [ $check -eq 0 ]; then
  "$clang_format" -i --style=file "${files[@]}"
  exit 0
fi
bad=0
for f in "${files[@]}"; do
  if ! "$clang_format" --dry-run -Werror --style=file "$f" >/dev/null 2>&1; then
    echo "not formatted: $f"
    bad=$((bad + 1))
  fi
done
if [ $bad -gt 0 ]; then
  echo "format.sh: $bad of ${#files[@]} files are not formatted (bash tools/format.sh fixes them)"
  exit 1
fi
echo "format.sh: ${#files[@]} files formatted"
