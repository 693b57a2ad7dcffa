#!/usr/bin/env bash
# Assembles the GPU check's bundle (scripts/gpu-check.sh): BUILD_DIR's OpenCV-free binaries, the
# loaders and validation layer as .deb files, the exported real frames, and the device-side runner.
# Usage: scripts/gpu-check-bundle.sh BUILD_DIR BUNDLE_DIR FRAMES
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="$1" bundle="$2" frames="$3"
limit_mib=64  # the device tool's limit on what travels
binaries=("$build_dir/tests/kartograf_device_tests" "$build_dir/bench/kartograf_gpu_check")
for binary in "${binaries[@]}" "$build_dir/tests/kartograf_export_device_data"; do
  [ -x "$binary" ] || { echo "gpu-check: $binary is missing: build it (scripts/gpu-check.sh without --no-build)" >&2; exit 1; }
done
# What travels may need only what every Linux has: no OpenCV, and the loaders are opened at run time.
for binary in "${binaries[@]}"; do
  if readelf -d "$binary" | grep -E "NEEDED.*(opencv|vulkan|OpenCL|gtest|benchmark)"; then
    echo "gpu-check: $binary links a library that does not travel (above)" >&2; exit 1
  fi
done

rm -rf "$bundle"
mkdir -p "$bundle/bin" "$bundle/debs"
cp "${binaries[@]}" "$bundle/bin/"
strip "$bundle"/bin/*
cp scripts/gpu-check-run.sh "$bundle/run.sh"

# The loaders and the layer, from apt's cache when it holds them, else downloaded. NVIDIA's Vulkan
# driver (libGLX_nvidia.so.0) needs glvnd's libGLdispatch: the device tool's README list of GL
# libraries travels with the Vulkan loader.
packages=(libvulkan1 ocl-icd-libopencl1 vulkan-validationlayers libglvnd0 libglx0 libegl1 libgl1
          libopengl0 libgles2)
for package in "${packages[@]}"; do
  version="$(dpkg-query -W -f='${Version}' "$package" 2>/dev/null || true)"
  cached="/var/cache/apt/archives/${package}_${version//:/%3a}_amd64.deb"
  if [ -n "$version" ] && [ -f "$cached" ]; then
    cp "$cached" "$bundle/debs/"
  else
    (cd "$bundle/debs" && apt-get download "$package" >/dev/null) ||
      { echo "gpu-check: cannot download $package (apt-get download)" >&2; exit 1; }
  fi
done

data="$(mktemp -d)"
trap 'rm -rf "$data"' EXIT
"$build_dir/tests/kartograf_export_device_data" "$data/data" --sequence "$frames" >/dev/null
# xz, not gzip: the frames are a third smaller (34 vs 45 MiB at 60 frames), which keeps the bundle and
# the tracked tree under the device tool's 64 MiB.
XZ_OPT="-6 -T0" tar cJf "$bundle/data.tar.xz" -C "$data" data
{
  echo "kartograf gpu-check bundle: git $(git rev-parse --short HEAD 2>/dev/null || echo unknown)$(git diff --quiet 2>/dev/null || echo ' + local changes'), built $(date -u +%Y-%m-%dT%H:%MZ) on $(uname -m)"
  echo "odometry frames: $frames"
  (cd "$bundle" && find . -type f -printf '%s %p\n' | sort -k2)
} >"$bundle/MANIFEST"
# The device tool sends the tracked tree with the bundle: both count towards its limit.
size_kib="$(du -sk "$bundle" | cut -f1)"
tree_kib="$(git ls-files -z 2>/dev/null | du -ck --files0-from=- 2>/dev/null | tail -1 | cut -f1)"
tree_kib="${tree_kib:-0}"
echo "gpu-check: bundle $bundle: $((size_kib / 1024)) MiB + tracked tree $((tree_kib / 1024)) MiB (limit $limit_mib MiB)"
[ $((size_kib + tree_kib)) -lt $((limit_mib * 1024)) ] || { echo "gpu-check: the bundle and the tree are over $limit_mib MiB" >&2; exit 1; }
