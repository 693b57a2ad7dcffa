"""The Python odometry's throughput against the C++ one on the same frames (issue 25: within 10 %).

    python bench/python/odometry_throughput.py SEQUENCE [--frames N] [--backend cpu]

Runs, in one process and one after the other: the C++ loop over the whole sequence
(kartograf.run_odometry: frames/s without file I/O, the figure `kartograf odometry` prints) and
the Python loop, Odometry.track per frame on frames read beforehand (so that only tracking is
timed), with the same parameters; prints both and their ratio, and checks both give the same poses.
"""

import argparse
import time

import numpy as np

import kartograf as kg


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("sequence")
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--backend", default="cpu")
    args = parser.parse_args()
    context = kg.Context(args.backend)
    sequence = kg.open_sequence(args.sequence, frames=args.frames)
    frames = [sequence.frame(i) for i in range(len(sequence))]

    run = kg.run_odometry(context, sequence)
    cpp = len(run.poses) / run.compute_seconds

    odometry = kg.Odometry(context, sequence.camera, sequence.depth_units_per_metre)
    start = time.perf_counter()
    for frame in frames:
        odometry.track(frame["depth"], frame["color"])
    python = len(frames) / (time.perf_counter() - start)

    same = np.allclose(odometry.poses, run.poses, atol=1e-9)
    print(f"frames {len(frames)}, backend {context.backend}")
    print(f"C++ run_odometry (compute only): {cpp:.1f} frames/s")
    print(f"Python Odometry.track loop:      {python:.1f} frames/s ({python / cpp:.3f} of C++)")
    print(f"same poses: {same}")


if __name__ == "__main__":
    main()
