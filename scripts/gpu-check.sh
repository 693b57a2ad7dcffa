#!/usr/bin/env bash
# The one prepared GPU run (issue 21; docs/benchmarks.md, "GPU check"). Builds a bundle that needs
# nothing installed where it runs: the device conformance tests and the device benchmark (built
# without OpenCV), the Vulkan and OpenCL ICD loaders and the Vulkan validation layer as Debian
# .deb files, and raw copies of the real frames they read.
#   scripts/gpu-check.sh            build the bundle in .gpu-check/ (here; no GPU needed)
#   scripts/gpu-check.sh --local    build it, then run it here on lavapipe and PoCL (CI does)
#   scripts/gpu-check.sh --run      on the GPU machine: run the carried bundle; the device tool's
#                                   call: carry [".gpu-check"], command
#                                   "bash scripts/gpu-check.sh --run", results under $OUT
# Options: --build-dir DIR (default build), --bundle DIR (default .gpu-check), --out DIR (results;
# default $OUT, else build-dir/gpu-check-out), --frames N (odometry frames, default 60),
# --no-build (take the binaries as they are in the build folder).
set -euo pipefail
cd "$(dirname "$0")/.."
mode=bundle build_dir=build bundle=.gpu-check out="${OUT:-}" frames=60 build=1
while [ $# -gt 0 ]; do
  case "$1" in
    --local) mode=local ;;
    --run) mode=run ;;
    --build-dir) build_dir="$2"; shift ;;
    --bundle) bundle="$2"; shift ;;
    --out) out="$2"; shift ;;
    --frames) frames="$2"; shift ;;
    --no-build) build=0 ;;
    *) echo "gpu-check.sh: unknown argument '$1' (see the comment at the top)" >&2; exit 2 ;;
  esac
  shift
done
out="${out:-$build_dir/gpu-check-out}"

if [ "$mode" = run ]; then
  [ -x "$bundle/run.sh" ] || { echo "gpu-check.sh: no bundle in $bundle (build it here first: bash scripts/gpu-check.sh)" >&2; exit 2; }
  exec bash "$bundle/run.sh" "$bundle" "$out" device
fi

targets=(kartograf_device_tests kartograf_gpu_check kartograf_export_device_data)
if [ "$build" = 1 ]; then
  if [ ! -f "$build_dir/CMakeCache.txt" ]; then
    bash scripts/build.sh -DKARTOGRAF_BUILD_TESTS=ON -DKARTOGRAF_BUILD_BENCH=ON
  fi
  cmake --build "$build_dir" --target "${targets[@]}"
fi
bash scripts/gpu-check-bundle.sh "$build_dir" "$bundle" "$frames"
if [ "$mode" = local ]; then
  bash "$bundle/run.sh" "$bundle" "$out" local
fi
