#!/usr/bin/env bash
# Installs the Debian (bookworm) packages Kartograf needs to build, test and run, and only those
# that are missing; prints what it installs. Safe to run again.
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config
  libeigen3-dev                                    # core and compute
  libnanoflann-dev                                 # compute: k-d tree correspondences (header-only)
  libvulkan-dev glslang-tools                      # Vulkan headers + loader, GLSL -> SPIR-V
  mesa-vulkan-drivers vulkan-validationlayers      # lavapipe + the validation layer for tests
  ocl-icd-opencl-dev ocl-icd-libopencl1 pocl-opencl-icd  # OpenCL headers, ICD loader, PoCL
  libopencv-dev                                    # io: PNG/JPEG
  liblzf-dev                                       # io: PCD binary_compressed
  libyaml-cpp-dev                                  # io: ROS map_server YAML
  nlohmann-json3-dev                               # io and CLI: JSON files
  libcli11-dev                                     # the kartograf CLI
  libgtest-dev libbenchmark-dev                    # tests and benchmarks
  libjs-three                                      # io: three.js, inlined into report.html
  chromium                                         # tests: report.html in headless Chromium
  python3-dev python3-venv                         # the Python package (pip from PyPI in a venv)
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
