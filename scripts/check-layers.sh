#!/usr/bin/env bash
# Checks that every source and header includes only its own layer and the layers below it, as
# docs/architecture.md draws them: a lower layer cannot include an upper one. Exits 1 and names each
# offending include. Usage: scripts/check-layers.sh [SOURCE_ROOT]
set -euo pipefail
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
  [formats]="core"
  [pipeline]="core compute geometry eval segmentation registration mapping rooms semantic formats"
  [outputs]="core compute geometry eval segmentation registration mapping rooms semantic formats pipeline synth"
  [training]="core compute geometry segmentation semantic synth"
)

failures=0
for layer in "${!allowed[@]}"; do
  for dir in "include/kartograf/$layer" "src/$layer"; do
    [ -d "$dir" ] || continue
    while IFS=: read -r file line include; do
      # Public headers (kartograf/<layer>/...) and src/'s private ones (<layer>/...).
      used=$(printf '%s' "$include" | sed -E 's|.*"(kartograf/)?([a-z_]+)/.*|\2|')
      [ -n "${allowed[$used]+known}" ] || continue  # not a layer (kernels/, shaders/, ...)
      [ "$used" = "$layer" ] && continue
      case " ${allowed[$layer]} " in
        *" $used "*) ;;
        *)
          echo "$file:$line: layer '$layer' includes '$used' ($include); allowed: ${allowed[$layer]:-nothing}"
          failures=$((failures + 1))
          ;;
      esac
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
