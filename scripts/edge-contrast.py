#!/usr/bin/env python3
"""Colour-to-depth edge contrast over windows of consecutive frames (a development tool, not a test).

Usage: edge-contrast.py [--window 3] [--every 5] [--min-steps 10000] FOLDER...

FOLDER holds an RGB-D sequence as `kartograf synth` writes it (rgb/, depth/) or as 7-Scenes / SUN3D
do (frame-N.color.*, frame-N.depth.png, in FOLDER or FOLDER/frames). For each window of --window
consecutive frames, starting at every --every-th frame, it computes the figure that
`registration::ColourEdgeProfile` computes (src/registration/colour_registration.cpp): across every
step in depth between two neighbouring pixels (over 5 % of the nearer depth) the grey gradient's
magnitude (channel mean, central differences) is summed at offsets -8..8 along the step's axis;
the contrast is the sum at 0 over the mean at offsets 4..8. Registered colour peaks at 0. Windows
with fewer than --min-steps depth steps (the check's own minimum) are left out. Prints, per folder,
the number of windows and the range of their contrasts, so the thresholds of
`ColourRegistrationParams` can be checked against many sequences.
"""
import argparse
import glob
import os

import numpy as np
from PIL import Image

REACH = 8


def gradient_magnitude(colour_path):
    grey = np.asarray(Image.open(colour_path).convert("RGB"), dtype=np.float32).mean(axis=2)
    gx = np.zeros_like(grey)
    gy = np.zeros_like(grey)
    gx[1:-1, 1:-1] = 0.5 * (grey[1:-1, 2:] - grey[1:-1, :-2])
    gy[1:-1, 1:-1] = 0.5 * (grey[2:, 1:-1] - grey[:-2, 1:-1])
    return np.hypot(gx, gy)


def profile(colour_path, depth_path):
    """Summed gradient at offsets -REACH..REACH across the frame's depth steps."""
    magnitude = gradient_magnitude(colour_path)
    depth = np.asarray(Image.open(depth_path), dtype=np.float32)
    sums = np.zeros(2 * REACH + 1)
    count = 0
    for axis in (1, 0):
        a = depth[:, :-1] if axis == 1 else depth[:-1, :]
        b = depth[:, 1:] if axis == 1 else depth[1:, :]
        steps = (a > 0) & (b > 0) & (np.abs(a - b) > 0.05 * np.minimum(a, b))
        ys, xs = np.nonzero(steps)
        along = xs if axis == 1 else ys
        keep = (along >= REACH) & (along < depth.shape[axis] - REACH - 1)
        ys, xs = ys[keep], xs[keep]
        count += len(ys)
        for s in range(-REACH, REACH + 1):
            if axis == 1:
                sums[s + REACH] += magnitude[ys, xs + s].sum() + magnitude[ys, xs + 1 + s].sum()
            else:
                sums[s + REACH] += magnitude[ys + s, xs].sum() + magnitude[ys + 1 + s, xs].sum()
    return sums, count


def contrast(sums):
    far = np.r_[sums[: REACH - 3], sums[REACH + 4 :]].mean()
    return sums[REACH] / far if far > 0 else 0.0


def frames_of(folder):
    if os.path.isdir(os.path.join(folder, "rgb")):
        colours = sorted(glob.glob(os.path.join(folder, "rgb", "*.png")))
        depths = sorted(glob.glob(os.path.join(folder, "depth", "*.png")))
        return list(zip(colours, depths))
    if os.path.isdir(os.path.join(folder, "frames")):
        folder = os.path.join(folder, "frames")
    colours = sorted(glob.glob(os.path.join(folder, "frame-*.color.*")))
    return [(c, c[: c.index(".color.")] + ".depth.png") for c in colours]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--window", type=int, default=3)
    parser.add_argument("--every", type=int, default=5)
    parser.add_argument("--min-steps", type=int, default=10000)
    parser.add_argument("folders", nargs="+")
    args = parser.parse_args()
    for folder in args.folders:
        frames = frames_of(folder)
        if len(frames) < args.window:
            raise SystemExit(f"{folder}: {len(frames)} frames, fewer than the window ({args.window})")
        cache = {}
        values = []
        for start in range(0, len(frames) - args.window + 1, args.every):
            sums, count = np.zeros(2 * REACH + 1), 0
            for i in range(start, start + args.window):
                if i not in cache:
                    cache[i] = profile(*frames[i])
                sums, count = sums + cache[i][0], count + cache[i][1]
            if count >= args.min_steps:
                values.append(contrast(sums))
        if not values:
            print(f"{folder}: no window with {args.min_steps} depth steps")
            continue
        print(f"{folder}: {len(values)} windows, contrast {min(values):.2f}-{max(values):.2f}")

if __name__ == "__main__":
    main()
