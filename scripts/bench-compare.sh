#!/usr/bin/env bash
# Before/after speed of the CPU backend's hot operations: runs the same benchmarks from two builds'
# bench/ folders alternately (ROUNDS times, default 2) and prints each benchmark's median per run.
# Usage: scripts/bench-compare.sh OLD_BENCH_DIR NEW_BENCH_DIR [ROUNDS]
# (docs/benchmarks.md, "One source per kernel ...": the table there comes from this script.)
set -euo pipefail
old=${1:?old bench folder}
new=${2:?new bench folder}
rounds=${3:-2}

run() {  # folder binary filter label
  "$1/$2" --benchmark_filter="$3" --benchmark_report_aggregates_only=true 2>/dev/null |
    awk -v label="$4" '/_median/ {print label, $1, $2, $3}'
}

for ((round = 1; round <= rounds; ++round)); do
  for side in old new; do
    dir=$old
    [ "$side" = new ] && dir=$new
    run "$dir" kartograf_bench '^(backproject|normals|icp_point_to_plane_sums|icp_point_to_point_sums)/cpu/640x480/steady' "$side"
    # The ICP sums on the CPU-hosted drivers too (lavapipe, PoCL): their kernels changed with the CPU's.
    run "$dir" kartograf_bench '^(icp_point_to_plane_sums|icp_point_to_point_sums)/(vulkan|opencl)/640x480/steady' "$side"
    run "$dir" kartograf_cloud_bench '^nn_kdtree/cpu/300000/query' "$side"
    run "$dir" kartograf_segmentation_bench '^plane_extraction/cpu/' "$side"
    run "$dir" kartograf_odometry_bench '^odometry/cpu/640x480/iterations' "$side"
    run "$dir" kartograf_rooms_bench '^rooms/(morphological|voronoi|feature|vrf)/Freiburg52_scan_plain' "$side"
  done
done
