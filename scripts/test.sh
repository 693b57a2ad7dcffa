#!/usr/bin/env bash
# Install what is missing, build everything, run the whole test suite: every operation on cpu,
# vulkan (lavapipe, under the validation layer) and opencl (PoCL). A missing backend fails. Then
# the Python package: pip installs it into a fresh venv (reusing the build: nothing is compiled
# twice) and its pytest suite runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
build_dir="${KARTOGRAF_BUILD_DIR:-build}"
venv="$build_dir/python-venv"
rm -rf "$venv"
mkdir -p "$build_dir"
python="$(bash scripts/python-env.sh "$venv")"
bash scripts/build.sh -DKARTOGRAF_BUILD_TESTS=ON -DKARTOGRAF_BUILD_BENCH=ON \
  -DKARTOGRAF_BUILD_PYTHON=ON -DPython_EXECUTABLE="$python"
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" --timeout 600
bash scripts/python-package.sh "$build_dir" "$python"
