"""Synthetic data sets: a procedural building rendered with the Kinect's noise model."""

from __future__ import annotations

import os

from . import _kartograf


def synthesize(folder: str | os.PathLike, seed: int = 1, frames: int = 300,
               trajectory: str = "robot", noise: bool = True, survey: bool = False,
               width: int = 640, height: int = 480, force: bool = False, threads: int = 0) -> dict:
    """Writes a data set as `kartograf synth` does (a TUM folder with ground truth); returns
    frames, files, rooms and the poses (N x 4 x 4)."""
    return _kartograf.synthesize(os.fspath(folder), seed, frames, trajectory, noise, survey,
                                 width, height, force, threads)
