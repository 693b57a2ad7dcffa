#!/usr/bin/env bash
# A/B of OpenCL kernel variants on the GPU machine without a build there (docs/benchmarks.md,
# "GPU check"): the bundle's kartograf_gpu_check on OpenCL alone, alternately with the embedded
# kernels and with each variant folder, ROUNDS times. A variant folder holds replacement kernel
# files named as in kernels/ (e.g. icp_sums.cl, includes expanded: cmake/embed_text.cmake writes
# them), read through KARTOGRAF_OPENCL_SOURCE_DIR.
#   here:       bash scripts/gpu-check.sh; put the variants in .cl-variants/<name>/ (git-ignored)
#   device:     run(command="bash scripts/gpu-opencl-variants.sh .cl-variants 2",
#                   carry=[".gpu-check", ".cl-variants"])
set -uo pipefail
cd "$(dirname "$0")/.."
variants_dir="$(cd "${1:?folder of variant folders}" && pwd)" rounds="${2:-2}"
bundle="$PWD/.gpu-check" out="${OUT:-build/gpu-variants-out}" work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
tar xJf "$bundle/data.tar.xz" -C "$work" 2>/dev/null || python3 -m tarfile -e "$bundle/data.tar.xz" "$work"
for deb in "$bundle"/debs/*.deb; do dpkg-deb -x "$deb" "$work/root"; done
export LD_LIBRARY_PATH="$work/root/usr/lib/x86_64-linux-gnu"
library="$( (ldconfig -p | grep -o '/[^ ]*libnvidia-opencl.so.1'; find /usr/local/nvidia -name libnvidia-opencl.so.1 2>/dev/null) | head -1)"
if [ -n "$library" ]; then
  mkdir -p "$work/vendors" && echo "$library" >"$work/vendors/nvidia.icd"
  export OCL_ICD_VENDORS="$work/vendors"
fi
variants=(embedded $(cd "$variants_dir" && ls -d */ | tr -d /))
for ((round = 1; round <= rounds; ++round)); do
  for variant in "${variants[@]}"; do
    source_dir=""
    [ "$variant" != embedded ] && source_dir="$variants_dir/$variant"
    KARTOGRAF_OPENCL_SOURCE_DIR="$source_dir" timeout 120 "$bundle/bin/kartograf_gpu_check" \
      --data "$work/data" --out "$work/$variant" --backends opencl >"$out/$variant.log" 2>&1
    echo "== $variant (round $round)"
    grep -v '^ \|^operation\|^==' "$work/$variant/gpu-check-table.txt"
  done
done
