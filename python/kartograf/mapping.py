"""SLAM over a sequence, and the online mapper fed frame by frame."""

from __future__ import annotations

from typing import Optional, Sequence as Seq

import numpy as np

from . import _kartograf
from .odometry import DEFAULTS
from .results import (DistanceField, Grid, MapResult, OdometryRun, SemanticGrid, SlamRun,
                      cloud_from, grid_from, mesh_from)


def run_slam(context: _kartograf.Context, sequence: _kartograf.Sequence,
             method: str = DEFAULTS["method"],
             reestimate_every: int = DEFAULTS["reestimate_every"],
             anchor_bounds: Seq[float] = DEFAULTS["anchor_bounds"],
             tracking: str = DEFAULTS["tracking"], model_voxel: float = DEFAULTS["model_voxel"],
             loop_closure: bool = True, features: bool = False, build_map: bool = False,
             voxel: float = DEFAULTS["map_voxel"]) -> SlamRun:
    """Odometry, loop closure and pose graph (`kartograf slam`); build_map: the fused cloud."""
    d = _kartograf.run_slam(context, sequence, method, reestimate_every, tuple(anchor_bounds),
                            tracking, model_voxel, loop_closure, features, build_map, voxel)
    odometry = OdometryRun.from_dict({**d["odometry"], "ground_truth": d["ground_truth"]})
    return SlamRun(poses=d["poses"], odometry=odometry, loop_closures=d["loop_closures"],
                   loop_candidates=d["loop_candidates"], graph_edges=d["graph_edges"],
                   total_seconds=d["total_seconds"], map=cloud_from(d["map"]),
                   ground_truth=list(d["ground_truth"]))


class Mapper:
    """The online mapper (pipeline/mapper.hpp): add_frame returns the pose at once; the mesh,
    the distance field and the grids can be asked for at any time."""

    def __init__(self, context: _kartograf.Context, camera: _kartograf.PinholeIntrinsics,
                 depth_units: float = 1000.0, features: bool = True,
                 voxel: float = DEFAULTS["mapper_voxel"]):
        self._mapper = _kartograf.Mapper(context, camera, depth_units, features, voxel)

    def add_frame(self, depth: np.ndarray, color: Optional[np.ndarray] = None,
                  pose: Optional[np.ndarray] = None,
                  motion_prior: Optional[np.ndarray] = None) -> dict:
        """Tracks the frame (or takes its camera-to-world pose: give one with every frame or
        with none); returns frame, pose, status, keyframe, poses_moved, evicted, fitness.
        motion_prior: another sensor's camera pose of the frame, which predicts the step."""
        return self._mapper.add_frame(depth, color, pose, motion_prior)

    @property
    def poses(self) -> np.ndarray:
        return self._mapper.poses

    def __len__(self) -> int:
        return len(self._mapper)

    def mesh(self):
        return mesh_from(self._mapper.mesh())

    def distance_field(self) -> DistanceField:
        d = self._mapper.distance_field()
        return DistanceField(distances=d["distances"], occupied=d["occupied"],
                             resolution=d["resolution"], max_distance=d["max_distance"],
                             first_cell=tuple(d["first_cell"]))

    def occupancy(self) -> Grid:
        """The height band's 2-D grid (a snapshot: seconds per hundred kept views)."""
        return grid_from(self._mapper.occupancy())

    def finish(self) -> MapResult:
        d = self._mapper.finish()
        return MapResult(poses=d["poses"], map_from_slam=d["map_from_slam"],
                         mesh=mesh_from(d["mesh"]), band_occupancy=grid_from(d["band_occupancy"]),
                         occupancy=grid_from(d["occupancy"]), rooms=d["rooms"],
                         room_count=d["room_count"], planes=d["planes"],
                         semantic=SemanticGrid(**{**d["semantic"],
                                                  "origin": tuple(d["semantic"]["origin"])}),
                         total_seconds=d["total_seconds"])
