#!/usr/bin/env bash
# Checks that every source and header includes only its own layer and the layers below it, as
# docs/architecture.md draws them: a lower layer cannot include an upper one. Exits 1 and names each
# offending include. Usage: scripts/check-layers.sh [SOURCE_ROOT]
# With --tests LIST (lines "LAYER tests/FILE", written by tests/CMakeLists.txt), checks instead that
# each test file, with the test headers it includes, includes only LAYER and the layers below it:
# the per-layer test binaries (kartograf_<layer>_tests) link only their layer.
set -euo pipefail
test_list=""
if [ "${1:-}" = "--tests" ]; then
  test_list=$2
  shift 2
fi
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root"

# layer: the layers it may include (besides itself). Keep in step with docs/architecture.md.
declare -A allowed=(
  [core]=""
  [compute]="core"
  [geometry]="core compute"
  [eval]="core"
  [segmentation]="core compute geometry"
  [registration]="core compute geometry segmentation"
  [mapping]="core compute geometry segmentation registration"
  [synth]="core"
  [rooms]="core compute geometry"
  [semantic]="core compute geometry segmentation"
  [features]="core compute geometry segmentation registration"
  [formats]="core"
  [pipeline]="core compute geometry eval segmentation registration mapping rooms semantic features formats"
  [outputs]="core compute geometry eval segmentation registration mapping rooms semantic features formats pipeline synth"
  [training]="core compute geometry segmentation semantic synth"
)

# check_include FILE LINE INCLUDE LAYER: counts and names an include of a layer LAYER may not use.
failures=0
check_include() {
  local used
  # Public headers (kartograf/<layer>/...) and src/'s private ones (<layer>/...).
  used=$(printf '%s' "$3" | sed -E 's|.*"(kartograf/)?([a-z_]+)/.*|\2|')
  [ -n "${allowed[$used]+known}" ] || return 0  # not a layer (kernels/, shaders/, ...)
  [ "$used" = "$4" ] && return 0
  case " ${allowed[$4]} " in
    *" $used "*) ;;
    *)
      echo "$1:$2: layer '$4' includes '$used' ($3); allowed: ${allowed[$4]:-nothing}"
      failures=$((failures + 1))
      ;;
  esac
}

# The test files: each file and the test headers (tests/*.hpp) it includes, transitively.
check_test_file() {
  local layer=$1 file=$2 line include header
  while IFS=: read -r line include; do
    header=$(printf '%s' "$include" | sed -E 's|#include "([^"]+)"|\1|')
    if [ -f "tests/$header" ] && [ -z "${seen[$header]+yes}" ]; then
      seen[$header]=1
      check_test_file "$layer" "tests/$header"
    fi
    check_include "$file" "$line" "$include" "$layer"
  done < <(grep -noE '#include "[^"]+"' "$file" || true)
}
if [ -n "$test_list" ]; then
  while read -r layer file; do
    [ -n "$layer" ] || continue
    [ "$layer" = rooms_scan ] && layer=rooms  # kartograf_rooms_scan: the rooms layer without OpenCV
    [ -n "${allowed[$layer]+known}" ] || { echo "$test_list: unknown layer '$layer'"; exit 1; }
    declare -A seen=()
    check_test_file "$layer" "$file"
    unset seen
  done < "$test_list"
  if [ "$failures" -gt 0 ]; then
    echo "$failures include(s) of test files cross the layers upward"
    exit 1
  fi
  echo "layers: every test binary's files include only its layer and those below"
  exit 0
fi

for layer in "${!allowed[@]}"; do
  for dir in "include/kartograf/$layer" "src/$layer"; do
    [ -d "$dir" ] || continue
    while IFS=: read -r file line include; do
      check_include "$file" "$line" "$include" "$layer"
    done < <(grep -rnoE '#include "(kartograf/)?[a-z_]+/[^"]+"' "$dir" || true)
  done
done
# The compute layer's rule headers and wrappers, and the shading-language preludes.
while IFS=: read -r file line include; do
  echo "$file:$line: kernels and shaders include only shaders/ and kernels/ ($include)"
  failures=$((failures + 1))
done < <(grep -rnoE '#include "kartograf/(geometry|segmentation|registration|mapping|eval|synth|rooms|semantic|formats|io|pipeline|outputs)/[^"]+"' kernels shaders || true)

if [ "$failures" -gt 0 ]; then
  echo "$failures include(s) cross the layers upward"
  exit 1
fi
echo "layers: every include follows docs/architecture.md"
