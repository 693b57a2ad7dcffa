"""Odometry: frame by frame from NumPy arrays, or over a whole sequence."""

from __future__ import annotations

from typing import Optional, Sequence as Seq

import numpy as np

from . import _kartograf
from .results import FrameReport, OdometryRun

# The C++ defaults (pipeline/tracking_choices.hpp), one source for the CLI and this package.
DEFAULTS = _kartograf.tracking_defaults()


class Odometry:
    """Frame-to-frame RGB-D odometry (the M3 paper's, registration/odometry.hpp).

    depth: H x W uint16 in depth_units per metre; read in place when C-contiguous (no copy),
    copied first otherwise. color: H x W x 3 uint8 on the depth camera's pixel grid, or None.
    """

    def __init__(self, context: _kartograf.Context, camera: _kartograf.PinholeIntrinsics,
                 depth_units: float = 1000.0, method: str = DEFAULTS["method"],
                 reestimate_every: int = DEFAULTS["reestimate_every"],
                 anchor_bounds: Seq[float] = DEFAULTS["anchor_bounds"],
                 min_depth: float = DEFAULTS["min_depth"],
                 max_depth: float = DEFAULTS["max_depth"]):
        self._odometry = _kartograf.Odometry(context, camera, depth_units, method,
                                             reestimate_every, tuple(anchor_bounds), min_depth,
                                             max_depth)

    def track(self, depth: np.ndarray, color: Optional[np.ndarray] = None,
              motion_prior: Optional[np.ndarray] = None) -> FrameReport:
        """Registers the next frame; its report carries its pose (4 x 4, camera-to-world).
        motion_prior: another sensor's camera-to-world pose of this frame (a wheeled robot's
        odometry through the camera mount); with the previous frame's it predicts the step, and
        a view that leaves a direction free takes its motion there."""
        return FrameReport.from_dict(self._odometry.track(depth, color, motion_prior))

    @property
    def poses(self) -> np.ndarray:
        """N x 4 x 4: every frame's current estimate (re-estimates correct earlier ones)."""
        return self._odometry.poses

    @property
    def last_depth_address(self) -> int:
        """Where the last depth image was read from: the array's own memory when not copied."""
        return self._odometry.last_depth_address

    def __len__(self) -> int:
        return len(self._odometry)


def run_odometry(context: _kartograf.Context, sequence: _kartograf.Sequence,
                 method: str = DEFAULTS["method"],
                 reestimate_every: int = DEFAULTS["reestimate_every"],
                 anchor_bounds: Seq[float] = DEFAULTS["anchor_bounds"],
                 tracking: str = DEFAULTS["tracking"],
                 model_voxel: float = DEFAULTS["model_voxel"]) -> OdometryRun:
    """The odometry over a whole sequence, as `kartograf odometry` runs it (same choices, same
    defaults); tracking "model": frame-to-model tracking against a TSDF."""
    return OdometryRun.from_dict(_kartograf.run_odometry(
        context, sequence, method, reestimate_every, tuple(anchor_bounds), tracking, model_voxel))
