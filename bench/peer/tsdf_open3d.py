#!/usr/bin/env python3
"""Open3D's VoxelBlockGrid on the frames kartograf_tsdf_bench fuses (issue 24's CPU speed line):
the same 640x480 depth + colour frames at their ground-truth poses, the same voxel size, truncation
(4 voxels), block side (8) and depth range, on the CPU. Prints one JSON line per voxel size with
the mean milliseconds per frame of integration (block allocation included) and ray casting of depth
and colour (after 5 warm-up frames), of meshing (marching cubes) and the block count at the end.

Usage: tsdf_open3d.py FRAMES_DIR [--frames N] [--voxels 0.01,0.05] [--max-depth 4]
FRAMES_DIR holds frame-XXXXXX.{depth.png,color.jpg,pose.txt} and ../camera-intrinsics.txt
(7-Scenes as ../shared/data/7scenes_redkitchen has them). Thread count: OMP_NUM_THREADS.
"""
import argparse
import json
import os
import time

import numpy as np
import open3d as o3d
import open3d.core as o3c


def frames(folder, count):
    names = sorted(n[:-len(".depth.png")] for n in os.listdir(folder) if n.endswith(".depth.png"))
    for name in names[:count]:
        depth = o3d.t.io.read_image(os.path.join(folder, name + ".depth.png"))
        color = o3d.t.io.read_image(os.path.join(folder, name + ".color.jpg"))
        pose = np.loadtxt(os.path.join(folder, name + ".pose.txt"))
        yield depth, color, np.linalg.inv(pose)  # Open3D takes world-to-camera extrinsics


def run(folder, count, voxel, max_depth, raycast):
    intrinsic = np.loadtxt(os.path.join(folder, "..", "camera-intrinsics.txt"))
    device = o3c.Device("CPU:0")
    grid = o3d.t.geometry.VoxelBlockGrid(
        attr_names=("tsdf", "weight", "color"), attr_dtypes=(o3c.float32, o3c.float32, o3c.float32),
        attr_channels=((1), (1), (3)), voxel_size=voxel, block_resolution=8,
        block_count=100000, device=device)
    k = o3c.Tensor(intrinsic, o3c.Dtype.Float64)
    integrate, cast = [], []
    loaded = list(frames(folder, count))
    for i, (depth, color, extrinsic) in enumerate(loaded):
        e = o3c.Tensor(extrinsic, o3c.Dtype.Float64)
        start = time.perf_counter()
        blocks = grid.compute_unique_block_coordinates(depth, k, e, 1000.0, max_depth,
                                                       trunc_voxel_multiplier=4.0)
        grid.integrate(blocks, depth, color, k, e, 1000.0, max_depth,
                       trunc_voxel_multiplier=4.0)
        middle = time.perf_counter()
        if raycast:
            grid.ray_cast(blocks, k, e, 640, 480, ["depth", "color"], 1000.0, 0.1,
                          max_depth, 1.0, trunc_voxel_multiplier=4.0)
        end = time.perf_counter()
        if i >= 5:
            integrate.append(middle - start)
            cast.append(end - middle)
    start = time.perf_counter()
    mesh = grid.extract_triangle_mesh()
    meshing = time.perf_counter() - start
    return {"peer": "open3d " + o3d.__version__, "voxel_m": voxel, "frames": len(loaded),
            "threads": os.environ.get("OMP_NUM_THREADS", "all"),
            "integrate_ms": 1000 * float(np.mean(integrate)),
            "raycast_ms": 1000 * float(np.mean(cast)) if raycast else None,
            "mesh_ms": 1000 * meshing, "blocks": int(grid.hashmap().size()),
            "triangles": int(mesh.triangle.indices.shape[0])}


def main():
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)  # stdout is the JSON lines
    parser = argparse.ArgumentParser()
    parser.add_argument("folder")
    parser.add_argument("--frames", type=int, default=50)
    parser.add_argument("--voxels", default="0.01,0.05")
    parser.add_argument("--max-depth", type=float, default=4.0)
    # Open3D 0.20's ray_cast dies (SIGSEGV) at 5 cm voxels on these frames after some ten frames.
    parser.add_argument("--raycast-voxels", default="0.01")
    a = parser.parse_args()
    cast = {float(v) for v in a.raycast_voxels.split(",") if v}
    for voxel in (float(v) for v in a.voxels.split(",")):
        print(json.dumps(run(a.folder, a.frames, voxel, a.max_depth, voxel in cast)), flush=True)


if __name__ == "__main__":
    main()
