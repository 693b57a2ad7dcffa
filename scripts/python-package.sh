#!/usr/bin/env bash
# pip install . into the venv of PYTHON, reusing the CMake build folder BUILD_DIR (configured with
# the same options, so only the package's install step runs), then the package's pytest suite.
# Usage: scripts/python-package.sh BUILD_DIR PYTHON
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="$(realpath "${1:?usage: python-package.sh BUILD_DIR PYTHON}")"
python="${2:?usage: python-package.sh BUILD_DIR PYTHON}"
"$python" -m pip install --quiet --disable-pip-version-check --no-build-isolation --no-deps \
  -C build-dir="$build_dir" \
  -C cmake.define.KARTOGRAF_BUILD_TESTS=ON -C cmake.define.KARTOGRAF_BUILD_BENCH=ON .
# From elsewhere than the source tree, so that the installed package is the one imported.
(cd "$build_dir" && "$python" -c "import kartograf; print('python package:', kartograf.__file__)")
"$python" -m pytest -q -p no:cacheprovider --rootdir="$PWD" python/tests
