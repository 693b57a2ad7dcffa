#!/usr/bin/python3
"""Cross-checks the loop closures of a `kartograf slam` run on 7-Scenes against Open3D.

For every verified loop closure in DIR/stats.json, registers the same two depth frames with
Open3D's point-to-plane ICP (full clouds, 1 cm voxels, 5 cm gate), started from the ground truth
and from Kartograf's result, and prints how far each lands from the ground truth and from
Kartograf (translation, metres). Used for docs/slam.md ("Loop closure").

    /usr/bin/python3 scripts/loop-closures-vs-open3d.py ../shared/data/7scenes_redkitchen DIR

Needs Debian's python3-open3d and python3-numpy (/usr/bin/python3, not a virtual environment).
"""
import json
import sys

import numpy as np
import open3d as o3d


def quaternion_to_matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def main(sequence, run):
    frames = f"{sequence}/frames/"
    camera = o3d.camera.PinholeCameraIntrinsic(640, 480, 585, 585, 320, 240)

    def cloud(i):
        depth = o3d.io.read_image(frames + f"frame-{i:06d}.depth.png")
        points = o3d.geometry.PointCloud.create_from_depth_image(depth, camera, depth_scale=1000,
                                                                 depth_trunc=4.0)
        points = points.voxel_down_sample(0.01)
        points.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=0.05, max_nn=30))
        return points

    def pose(i):
        matrix = np.loadtxt(frames + f"frame-{i:06d}.pose.txt")
        u, _, vt = np.linalg.svd(matrix[:3, :3])  # the files' rotations are not quite orthonormal
        matrix[:3, :3] = u @ vt
        return matrix

    stats = json.load(open(f"{run}/stats.json"))
    for closure in stats["loop_closure"]["closures"]:
        i, j = closure["match_frame"], closure["query_frame"]
        truth = np.linalg.inv(pose(i)) @ pose(j)
        ours = np.eye(4)
        ours[:3, :3] = quaternion_to_matrix(closure["motion"][3:])
        ours[:3, 3] = closure["motion"][:3]
        source, target = cloud(j), cloud(i)
        landed = []
        def distance(a, b):
            return np.linalg.norm(a[:3, 3] - b[:3, 3])
        for start in (truth, ours):
            result = o3d.pipelines.registration.registration_icp(
                source, target, 0.05, start,
                o3d.pipelines.registration.TransformationEstimationPointToPlane(),
                o3d.pipelines.registration.ICPConvergenceCriteria(1e-8, 1e-8, 100))
            landed.append(result.transformation)
        print(f"{i:4d} -> {j:4d}  kartograf vs truth {distance(ours, truth):.3f}  "
              f"open3d from truth: vs truth {distance(landed[0], truth):.3f} "
              f"vs kartograf {distance(landed[0], ours):.3f}  "
              f"open3d from kartograf: vs truth {distance(landed[1], truth):.3f}", flush=True)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
