#!/usr/bin/env bash
# A Python virtual environment for building and testing the Python package: the build tools
# (scikit-build-core, nanobind), the test tools (numpy, pytest), rosbags (ROS bags) and Ray
# (kartograf batch) from PyPI. Prints the venv's
# python. Usage: python="$(bash scripts/python-env.sh DIR)". Safe to run again.
set -euo pipefail
venv="${1:?usage: python-env.sh VENV_DIR}"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv" >&2
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
  "scikit-build-core>=0.10" "nanobind>=2.0" "numpy>=1.21" "pytest>=7" "rosbags>=0.10" "ray>=2.9" >&2
echo "$(cd "$venv" && pwd)/bin/python"  # absolute: CMake takes it from any folder
