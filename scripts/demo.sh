#!/usr/bin/env bash
# The main job on the built-in default input: install what is missing, build, list the compute
# devices, and run the demo into out/demo (pictures, PLY).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DKARTOGRAF_BUILD_TESTS=OFF -DKARTOGRAF_BUILD_BENCH=OFF
build_dir="${KARTOGRAF_BUILD_DIR:-build}"
"$build_dir/apps/kartograf/kartograf" devices
"$build_dir/apps/kartograf/kartograf" demo --out "${1:-out/demo}"
