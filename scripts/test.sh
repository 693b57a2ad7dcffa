#!/usr/bin/env bash
# Install what is missing, build everything, run the whole test suite: every operation on cpu,
# vulkan (lavapipe, under the validation layer) and opencl (PoCL). A missing backend fails.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DKARTOGRAF_BUILD_TESTS=ON -DKARTOGRAF_BUILD_BENCH=ON
build_dir="${KARTOGRAF_BUILD_DIR:-build}"
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" --timeout 600
