#!/usr/bin/env bash
# The main job on the built-in default input: install what is missing, build, list the compute
# devices, write the default synthetic building (a robot's survey of it: ~1300 RGB-D frames with
# one full turn in every room and corridor pass, ground truth included) and map it: SLAM, planes,
# occupancy grid, rooms, semantic grid and a report with every metric against the building's
# ground truth. The last line says where the report is.
#   bash scripts/demo.sh [OUT_DIR=out]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DKARTOGRAF_BUILD_TESTS=OFF -DKARTOGRAF_BUILD_BENCH=OFF
build_dir="${KARTOGRAF_BUILD_DIR:-build}"
out="${1:-out}"
kartograf="$build_dir/apps/kartograf/kartograf"
"$kartograf" devices
if [ ! -f "$out/survey/world.json" ]; then
  rm -rf "$out/survey"
  "$kartograf" synth --out "$out/survey" --survey --pitch 20
fi
"$kartograf" map "$out/survey" --out "$out/map" --force
