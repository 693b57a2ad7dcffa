#!/usr/bin/env python3
"""Which relative poses the images themselves support: a trajectory's or the ground truth's.

For every step (frame i, frame i + GAP) of a `kartograf slam` run on a 7-Scenes / 3DMatch / SUN3D
folder, moves frame i + GAP's depth points (every 8th pixel, 0.1-4 m) into frame i by each
trajectory's relative pose and measures
  - depth: the median distance to their nearest neighbours among frame i's points (every 2nd
    pixel; neighbours beyond 5 cm left out) and the share within 1 cm;
  - colour: the median absolute grey-level difference between each point's pixel in frame i + GAP
    and where it lands in frame i (bilinear).
Prints a line per step and a summary: how many steps each trajectory fits better, and the steps
where the ground truth fits worse by both measures (by more than 1 mm and 0.5 grey levels), or the
trajectory does. Used for docs/slam.md ("The ground truth's own error").

    python3 scripts/pose-consistency.py SEQUENCE RUN [--gap 1] [--first I] [--last J]

SEQUENCE: frames/frame-N.depth.png (millimetres) with frame-N.color.{png,jpg}, and
camera-intrinsics.txt (3x3). RUN: groundtruth.txt and trajectory.txt (TUM, one row per frame, in
the folder's frame order), as `kartograf slam SEQUENCE --out RUN` writes them.
Needs numpy, scipy and Pillow (Debian: python3-numpy python3-scipy python3-pil).
"""
import argparse
import glob
import os

import numpy as np
from PIL import Image
from scipy.ndimage import map_coordinates
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation


def load_tum(path):
    rows = [line.split() for line in open(path) if line.strip() and not line.startswith("#")]
    poses = []
    for r in rows:
        pose = np.eye(4)
        pose[:3, :3] = Rotation.from_quat([float(x) for x in r[4:8]]).as_matrix()
        pose[:3, 3] = [float(x) for x in r[1:4]]
        poses.append(pose)
    return poses


class Frames:
    def __init__(self, folder):
        self.depths = sorted(glob.glob(os.path.join(folder, "frames", "frame-*.depth.png")))
        if not self.depths:
            raise SystemExit(f"pose-consistency: no frames/frame-*.depth.png in '{folder}'")
        k = np.loadtxt(os.path.join(folder, "camera-intrinsics.txt"))
        self.fx, self.fy, self.cx, self.cy = k[0, 0], k[1, 1], k[0, 2], k[1, 2]

    def points(self, i, step):
        """Frame i's points (every step-th pixel, 0.1-4 m) and their pixels."""
        depth = np.asarray(Image.open(self.depths[i]), dtype=np.float64) / 1000.0
        v, u = np.mgrid[0 : depth.shape[0] : step, 0 : depth.shape[1] : step]
        z = depth[::step, ::step]
        keep = (z > 0.1) & (z < 4.0)
        z, u, v = z[keep], u[keep], v[keep]
        xyz = np.stack([(u - self.cx) * z / self.fx, (v - self.cy) * z / self.fy, z], 1)
        return xyz, u, v

    def grey(self, i):
        stem = self.depths[i][: -len(".depth.png")]
        for ext in (".color.png", ".color.jpg"):
            if os.path.exists(stem + ext):
                return np.asarray(Image.open(stem + ext).convert("L"), dtype=np.float64)
        raise SystemExit(f"pose-consistency: no colour image beside '{self.depths[i]}'")


def depth_fit(tree, moved):
    distance, _ = tree.query(moved, distance_upper_bound=0.05)
    near = np.isfinite(distance)
    if not near.any():
        return np.nan, 0.0
    return np.median(distance[near]) * 1000, float((distance < 0.01).mean())


def colour_fit(frames, grey_i, grey_j, moved, u, v):
    x = frames.fx * moved[:, 0] / moved[:, 2] + frames.cx
    y = frames.fy * moved[:, 1] / moved[:, 2] + frames.cy
    inside = (x >= 1) & (y >= 1) & (x < grey_i.shape[1] - 2) & (y < grey_i.shape[0] - 2)
    inside &= moved[:, 2] > 0.1
    landed = map_coordinates(grey_i, [y[inside], x[inside]], order=1)
    return float(np.median(np.abs(landed - grey_j[v[inside], u[inside]])))


def step_fits(frames, i, j, trajectories):
    """Per trajectory: (median NN mm, share within 1 cm, median grey difference)."""
    tree = cKDTree(frames.points(i, 2)[0])
    xyz, u, v = frames.points(j, 8)
    grey_i, grey_j = frames.grey(i), frames.grey(j)
    fits = []
    for poses in trajectories:
        relative = np.linalg.inv(poses[i]) @ poses[j]
        moved = xyz @ relative[:3, :3].T + relative[:3, 3]
        fits.append((*depth_fit(tree, moved), colour_fit(frames, grey_i, grey_j, moved, u, v)))
    return fits


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("run")
    parser.add_argument("--gap", type=int, default=1)
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--last", type=int, default=None)
    args = parser.parse_args()
    frames = Frames(args.sequence)
    truth = load_tum(os.path.join(args.run, "groundtruth.txt"))
    estimate = load_tum(os.path.join(args.run, "trajectory.txt"))
    if not len(truth) == len(estimate) == len(frames.depths):
        raise SystemExit(f"pose-consistency: {len(truth)} ground-truth poses, {len(estimate)} "
                         f"estimated, {len(frames.depths)} frames: they must match")
    last = min(args.last if args.last is not None else len(truth), len(truth)) - args.gap
    rows = []
    for i in range(args.first, last):
        (gt_mm, gt_in, gt_grey), (es_mm, es_in, es_grey) = step_fits(
            frames, i, i + args.gap, (truth, estimate))
        rows.append((i, gt_mm, es_mm, gt_grey, es_grey))
        print(f"{i:5d} -> {i + args.gap:5d}  depth truth {gt_mm:5.1f} mm {gt_in:4.0%} trajectory "
              f"{es_mm:5.1f} mm {es_in:4.0%} | grey truth {gt_grey:5.2f} trajectory {es_grey:5.2f}")
    a = np.array(rows)
    print(f"steps {len(a)}: trajectory fits the depth better in {(a[:, 2] < a[:, 1]).sum()} "
          f"(median {np.nanmedian(a[:, 2]):.2f} mm against {np.nanmedian(a[:, 1]):.2f}), the colour in "
          f"{(a[:, 4] < a[:, 3]).sum()} ({np.median(a[:, 4]):.2f} against {np.median(a[:, 3]):.2f})")
    truth_worse = a[(a[:, 1] > a[:, 2] + 1.0) & (a[:, 3] > a[:, 4] + 0.5), 0].astype(int)
    estimate_worse = a[(a[:, 2] > a[:, 1] + 1.0) & (a[:, 4] > a[:, 3] + 0.5), 0].astype(int)
    print(f"ground truth worse by both: {len(truth_worse)} steps {truth_worse.tolist()}")
    print(f"trajectory worse by both: {len(estimate_worse)} steps {estimate_worse.tolist()}")


if __name__ == "__main__":
    main()
