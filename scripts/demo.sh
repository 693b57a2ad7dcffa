#!/usr/bin/env bash
# The main job on the built-in default input: install what is missing, build, list the compute
# devices, write the default synthetic building (300 RGB-D frames of a robot's tour, with ground
# truth) and map it: SLAM, planes, occupancy grid, rooms, semantic grid and a report with every
# metric against the building's ground truth. The last line says where the report is.
#   bash scripts/demo.sh [OUT_DIR=out]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DKARTOGRAF_BUILD_TESTS=OFF -DKARTOGRAF_BUILD_BENCH=OFF
build_dir="${KARTOGRAF_BUILD_DIR:-build}"
out="${1:-out}"
kartograf="$build_dir/apps/kartograf/kartograf"
"$kartograf" devices
if [ ! -f "$out/building/world.json" ]; then
  rm -rf "$out/building"
  "$kartograf" synth --out "$out/building"
fi
"$kartograf" map "$out/building" --out "$out/map" --force
