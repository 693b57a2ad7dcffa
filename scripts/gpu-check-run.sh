#!/usr/bin/env bash
# The device side of the GPU check (copied into the bundle as run.sh by scripts/gpu-check-bundle.sh).
# Usage: run.sh BUNDLE_DIR OUT_DIR device|local
#   device: a machine where nothing is installed: the carried loaders and layer are unpacked under a
#           temporary folder (never into /), NVIDIA's Vulkan and OpenCL drivers are looked for.
#   local:  this machine's loaders and drivers (lavapipe, PoCL); every backend must be there.
# Writes OUT_DIR/gpu-check.log, devices.txt, conformance.xml, gpu-check.json, gpu-check-table.txt
# (device: clocks.csv, the GPU's clocks through the benchmark);
# prints the table last. Exit status 0 only if the conformance tests and the benchmark passed.
set -uo pipefail
bundle="$(cd "$1" && pwd)" out="$2" mode="$3"
mkdir -p "$out" && out="$(cd "$out" && pwd)"
exec > >(tee "$out/gpu-check.log") 2>&1
work="$(mktemp -d /tmp/kartograf-gpu-check.XXXXXX)"
trap 'rm -rf "$work"' EXIT
started=$SECONDS
echo "== kartograf gpu-check ($mode) $(date -u +%Y-%m-%dT%H:%M:%SZ) on $(hostname)"
head -2 "$bundle/MANIFEST"
# tar needs the xz program for .xz; Python's tarfile reads it where xz is not installed.
{ tar xJf "$bundle/data.tar.xz" -C "$work" 2>/dev/null || python3 -m tarfile -e "$bundle/data.tar.xz" "$work"; } || { echo "FAIL: cannot unpack the data"; exit 1; }
export POCL_CACHE_DIR="$work/pocl-cache" MESA_SHADER_CACHE_DIR="$work/mesa-cache" OMP_WAIT_POLICY=passive

first_file() { for f in "$@"; do [ -f "$f" ] && { echo "$f"; return; }; done; }

if [ "$mode" = device ]; then
  for deb in "$bundle"/debs/*.deb; do dpkg-deb -x "$deb" "$work/root" || echo "WARN: cannot unpack $deb"; done
  export LD_LIBRARY_PATH="$work/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  export VK_LAYER_PATH="$work/root/usr/share/vulkan/explicit_layer.d"
  icd="$(first_file /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json \
          /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json \
          $(find /usr/local/nvidia /usr/share/vulkan /etc/vulkan -name 'nvidia_icd*.json' 2>/dev/null))"
  [ -n "$icd" ] && export VK_DRIVER_FILES="$icd"
  [ -n "$icd" ] && echo "nvidia_icd.json: $(tr -d '\n ' <"$icd")"
  echo "vulkan ICD: ${VK_DRIVER_FILES:-the search path of the loader} ($(ls /usr/share/vulkan/icd.d /etc/vulkan/icd.d 2>/dev/null | tr '\n' ' '))"
  echo "OpenCL vendors in /etc/OpenCL/vendors: $(ls /etc/OpenCL/vendors 2>/dev/null | tr '\n' ' ')"
  if ! grep -qs nvidia /etc/OpenCL/vendors/*.icd; then
    library="$( (ldconfig -p | grep -o '/[^ ]*libnvidia-opencl.so.1' ; find /usr/local/nvidia /usr/lib /usr/lib64 -name 'libnvidia-opencl.so.1' 2>/dev/null) | head -1)"
    if [ -n "$library" ]; then
      mkdir -p "$work/vendors" && echo "$library" >"$work/vendors/nvidia.icd"
      export OCL_ICD_VENDORS="$work/vendors"
      echo "OpenCL: NVIDIA's library $library (ICD file written)"
    else
      echo "OpenCL: NVIDIA's OpenCL library (libnvidia-opencl.so.1) is absent on this machine"
    fi
  fi
  command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm,clocks.max.memory --format=csv
fi

"$bundle/bin/kartograf_gpu_check" --list | tee "$out/devices.txt"
available="$(sed -n 's/^available: //p' "$out/devices.txt")"
if [ "$mode" = device ] && [ "${available#*vulkan}" = "$available" ]; then
  echo "vulkan is unavailable: the loader's own report (VK_LOADER_DEBUG=error,warn,driver):"
  VK_LOADER_DEBUG=error,warn,driver "$bundle/bin/kartograf_gpu_check" --list 2>&1 | grep -v '^ ' | head -40
fi
if [ "$mode" = local ] && [ "$available" != "cpu,vulkan,opencl" ]; then
  echo "FAIL: --local needs every backend here (cpu, vulkan on lavapipe, opencl on PoCL); available: $available"
  exit 1
fi
if [ -f "${VK_LAYER_PATH:-}/VkLayer_khronos_validation.json" ] || [ "$mode" = local ]; then
  echo "vulkan validation: the layer is there; the conformance tests run under it with synchronization validation"
else
  echo "vulkan validation: the layer did not travel; the conformance tests run without it"
fi

[ -n "${KARTOGRAF_VULKAN_STAGING:-}" ] && echo "KARTOGRAF_VULKAN_STAGING=$KARTOGRAF_VULKAN_STAGING: Vulkan takes the discrete-GPU path (staging copies)"
# Here (local) the per-layer ctest binaries already run every test on cpu, lavapipe and PoCL; what
# only this run checks is the bundle itself and, with KARTOGRAF_VULKAN_STAGING, Vulkan's
# discrete-GPU path: so its backend tests on Vulkan. On the device, everything.
tested="$available" filter=()
[ "$mode" = local ] && tested=vulkan filter=(--gtest_filter='Backends/*')
echo "== conformance tests on $tested ($((SECONDS - started)) s so far)"
KARTOGRAF_DATA_DIR="$work/data" KARTOGRAF_TEST_BACKENDS="$tested" timeout 300 \
  "$bundle/bin/kartograf_device_tests" --gtest_brief=1 --gtest_output="xml:$out/conformance.xml" \
  "${filter[@]}"
conformance=$?
echo "== benchmark ($((SECONDS - started)) s so far)"
quick=(); [ "$mode" = local ] && quick=(--quick)
# The GPU's clocks and power state through the benchmark: device times that change between runs
# of the same code (an idle GPU clocks down) show here.
clocks_pid=
if [ "$mode" = device ] && command -v nvidia-smi >/dev/null; then
  nvidia-smi --query-gpu=timestamp,pstate,clocks.sm,clocks.mem,power.draw,temperature.gpu \
    --format=csv -lms 250 >"$out/clocks.csv" 2>&1 &
  clocks_pid=$!
fi
# The odometry sequence is as long as the frames the bundle carries (its MANIFEST says how many).
frames=(); sequence_frames="$(sed -n 's/^odometry frames: //p' "$bundle/MANIFEST" 2>/dev/null)"
[ -n "$sequence_frames" ] && [ "$mode" = device ] && frames=(--frames "$sequence_frames")
timeout 360 "$bundle/bin/kartograf_gpu_check" --data "$work/data" --out "$out" --backends "$available" \
  "${quick[@]}" "${frames[@]}"
benchmark=$?
[ -n "$clocks_pid" ] && kill "$clocks_pid" 2>/dev/null
echo "== done in $((SECONDS - started)) s: conformance tests $([ $conformance = 0 ] && echo passed || echo "FAILED ($conformance)") on $tested; benchmark $([ $benchmark = 0 ] && echo passed || echo "FAILED ($benchmark)")"
cat "$out/gpu-check-table.txt" 2>/dev/null
[ $conformance = 0 ] && [ $benchmark = 0 ]
