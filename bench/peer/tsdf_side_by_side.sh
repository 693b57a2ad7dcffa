#!/usr/bin/env bash
# Kartograf's TSDF on the CPU backend against Open3D 0.20's VoxelBlockGrid on the same 40 frames of
# 7-Scenes, the same voxel sizes (1 and 5 cm), truncation (4 voxels), block side and depth range,
# on the same thread count, in one run (issue 24's CPU speed line). Prints one row per operation
# and voxel size: Kartograf's ms per frame, Open3D's, and Open3D / Kartograf (> 1: Kartograf is
# faster).
#   bash bench/peer/tsdf_side_by_side.sh [BUILD_DIR] [PYTHON] [THREADS]
# PYTHON must import open3d 0.20 (e.g. a venv: pip install open3d==0.20.0); THREADS (default: all
# cores) goes to both (KARTOGRAF_CPU_THREADS, OMP_NUM_THREADS).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
python=${2:-python3}
threads=${3:-$(nproc)}
frames=${KARTOGRAF_DATA_DIR:-$root/../shared/data}/7scenes_redkitchen/frames
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
KARTOGRAF_CPU_THREADS=$threads KARTOGRAF_BENCH_BACKENDS=cpu "$build/bench/kartograf_tsdf_bench" \
  --benchmark_filter='tsdf_(integrate|raycast|mesh)/' --benchmark_format=json > "$out/ours.json"
OMP_NUM_THREADS=$threads "$python" "$root/bench/peer/tsdf_open3d.py" "$frames" --frames 40 \
  2> /dev/null > "$out/open3d.jsonl"
"$python" - "$out/ours.json" "$out/open3d.jsonl" "$threads" <<'PY'
import json, sys
ours = {b["name"].split("/iterations")[0]: b["real_time"] for b in json.load(open(sys.argv[1]))["benchmarks"]}
peers = [json.loads(line) for line in open(sys.argv[2]) if line.startswith("{")]
print(f"threads {sys.argv[3]}; {peers[0]['peer']}; ms per 640x480 frame (meshing: whole 40-frame volume)")
print(f"{'operation':<24}{'kartograf':>11}{'open3d':>10}{'open3d/kartograf':>18}")
for peer in peers:
    size = "1cm" if peer["voxel_m"] == 0.01 else "5cm"
    for op, key in (("integrate", "integrate_ms"), ("raycast", "raycast_ms"), ("mesh", "mesh_ms")):
        mine = ours.get(f"tsdf_{op}/cpu/640x480_{size}")
        theirs = peer[key]
        if mine is None or theirs is None:
            print(f"{op + ' ' + size:<24}{mine or float('nan'):>11.2f}{'-':>10}{'-':>18}")
            continue
        print(f"{op + ' ' + size:<24}{mine:>11.2f}{theirs:>10.2f}{theirs / mine:>18.2f}")
PY
