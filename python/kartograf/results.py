"""Results as plain values: dataclasses of NumPy arrays and numbers, picklable."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from . import _kartograf


@dataclass
class Ate:
    """Absolute trajectory error after a rigid (se3) or similarity (sim3) alignment."""

    rmse_m: float
    mean_m: float
    median_m: float
    max_m: float
    count: int
    scale: float


def ate(estimate: np.ndarray, ground_truth: list, align: str = "se3") -> Ate:
    """ATE of an N x 4 x 4 trajectory against per-frame ground truth (4 x 4 or None)."""
    return Ate(**_kartograf.ate(np.asarray(estimate, dtype=np.float64), list(ground_truth), align))


@dataclass
class StepError:
    """One step's error, and the ATE with that step from the ground truth."""

    frame: int  # the frame the step ends at
    translation_m: float
    rotation_deg: float
    ate_rmse_with_true_step_m: float


@dataclass
class WorstSteps:
    """The steps that carry a trajectory's error (`kartograf eval traj --worst-steps`)."""

    steps: list  # StepError, largest translation error first
    ate_rmse_m: float
    ate_rmse_with_true_steps_m: float  # with all of `steps` from the ground truth


def worst_steps(estimate: np.ndarray, ground_truth: list, count: int = 10,
                align: str = "se3") -> WorstSteps:
    """The `count` steps with the largest error, each with the ATE the trajectory would have
    with that step from the ground truth; meant for an odometry's trajectory."""
    d = _kartograf.worst_steps(np.asarray(estimate, dtype=np.float64), list(ground_truth), count,
                               align)
    return WorstSteps(steps=[StepError(**step) for step in d["steps"]], ate_rmse_m=d["ate_rmse_m"],
                      ate_rmse_with_true_steps_m=d["ate_rmse_with_true_steps_m"])


@dataclass
class ClockOffset:
    """Another sensor's clock lead over a trajectory's, measured from how fast both turn."""

    offset_s: float  # read the other trajectory at a pose's time + offset_s
    sigma_s: float  # its standard error (inf where the turning cannot tell it)
    rms_deg: float  # the steps' rotation disagreement at offset_s (deg a step)
    given_rms_deg: float  # and at the offset given
    steps: int  # steps compared
    observable: bool  # inside the search range and known to 10 ms


def clock_offset(times: np.ndarray, poses: np.ndarray, other_times: np.ndarray,
                 other_poses: np.ndarray, given: float = 0.0,
                 half_range: float = 0.5) -> ClockOffset:
    """The clock offset between two trajectories of one body (N times and N x 4 x 4 poses each;
    say a camera's odometry and a robot's wheel odometry), searched within given +- half_range
    seconds: the steps of the sparser one turn by the angles the other turns over the same spans
    read `offset_s` later. Mounts and translation scale do not matter; see docs/slam.md."""
    arrays = [np.ascontiguousarray(a, dtype=np.float64)
              for a in (times, poses, other_times, other_poses)]
    return ClockOffset(**_kartograf.clock_offset(*arrays, given, half_range))


@dataclass
class FrameReport:
    """What the odometry did with one frame (see registration/odometry.hpp)."""

    index: int
    fallback: bool
    degenerate: bool
    keyframe: bool
    retried: bool
    seconds: float
    pose: Optional[np.ndarray] = None  # 4 x 4 camera-to-world, when tracked frame by frame
    previous: Optional[dict] = None  # the registration against the previous frame
    reestimate: Optional[dict] = None  # against the anchor (every k-th frame)
    extra: dict = field(default_factory=dict)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "FrameReport":
        known = {k: d[k] for k in ("index", "fallback", "degenerate", "keyframe", "retried",
                                   "seconds")}
        extra = {k: v for k, v in d.items()
                 if k not in known and k not in ("pose", "previous", "reestimate")}
        return cls(**known, pose=d.get("pose"), previous=d.get("previous"),
                   reestimate=d.get("reestimate"), extra=extra)


def _has_truth(ground_truth: list) -> bool:
    return sum(g is not None for g in ground_truth) >= 3


@dataclass
class OdometryRun:
    poses: np.ndarray  # N x 4 x 4 camera-to-world, frame 0 = identity
    timestamps: list
    frames: list  # FrameReport per frame
    keyframes: list
    wall_seconds: float
    compute_seconds: float
    model_tracking: bool
    ground_truth: list  # per frame: 4 x 4 or None

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "OdometryRun":
        return cls(poses=d["poses"], timestamps=list(d["timestamps"]),
                   frames=[FrameReport.from_dict(f) for f in d["frames"]],
                   keyframes=list(d["keyframes"]), wall_seconds=d["wall_seconds"],
                   compute_seconds=d["compute_seconds"], model_tracking=d["model_tracking"],
                   ground_truth=list(d.get("ground_truth", [])))

    @property
    def frames_per_second(self) -> float:
        """Throughput without file I/O."""
        return len(self.poses) / self.compute_seconds if self.compute_seconds > 0 else 0.0

    def ate(self, align: str = "se3") -> Optional[Ate]:
        """ATE against the sequence's ground truth; None without (3 frames or more needed)."""
        return ate(self.poses, self.ground_truth, align) if _has_truth(self.ground_truth) else None

    def worst_steps(self, count: int = 10, align: str = "se3") -> Optional[WorstSteps]:
        """The steps that carry the ATE (see worst_steps); None without ground truth."""
        if not _has_truth(self.ground_truth):
            return None
        return worst_steps(self.poses, self.ground_truth, count, align)


@dataclass
class Cloud:
    points: np.ndarray  # N x 3 float32, metres
    colors: np.ndarray  # N x 3 uint8, or 0 x 3

    def to_open3d(self):
        """An open3d.geometry.PointCloud (needs open3d)."""
        from .open3d_interop import cloud_to_open3d

        return cloud_to_open3d(self)

    @classmethod
    def from_open3d(cls, cloud) -> "Cloud":
        from .open3d_interop import cloud_from_open3d

        return cloud_from_open3d(cloud)


@dataclass
class Mesh:
    vertices: np.ndarray  # N x 3 float32, metres
    triangles: np.ndarray  # M x 3 int32, counter-clockwise seen from outside
    colors: np.ndarray  # N x 3 uint8, or 0 x 3

    def to_open3d(self):
        """An open3d.geometry.TriangleMesh (needs open3d)."""
        from .open3d_interop import mesh_to_open3d

        return mesh_to_open3d(self)

    @classmethod
    def from_open3d(cls, mesh) -> "Mesh":
        from .open3d_interop import mesh_from_open3d

        return mesh_from_open3d(mesh)


@dataclass
class Grid:
    """A 2-D occupancy grid: cells[row, col] 0 unknown, 1 free, 2 occupied; row 0 is the top."""

    cells: np.ndarray
    resolution: float
    origin: tuple  # x [m], y [m], yaw [rad] of the lower-left corner


@dataclass
class DistanceField:
    """The TSDF's 3-D distance field (mapping/esdf_volume.hpp): distances[z, y, x] in metres."""

    distances: np.ndarray
    occupied: np.ndarray
    resolution: float
    max_distance: float
    first_cell: tuple  # cell (i, j, k) spans [i, i + 1) x resolution, ...

    def distance(self, point) -> float:
        """Metres from a point (3,) to the nearest surface, max_distance outside the grid."""
        cell = np.floor(np.asarray(point, dtype=np.float64) / self.resolution).astype(int)
        x, y, z = cell - np.asarray(self.first_cell)
        dz, dy, dx = self.distances.shape
        if not (0 <= x < dx and 0 <= y < dy and 0 <= z < dz):
            return float(self.max_distance)
        return float(self.distances[z, y, x])


@dataclass
class SlamRun:
    poses: np.ndarray  # optimised, N x 4 x 4
    odometry: OdometryRun
    loop_closures: int  # accepted and kept
    loop_candidates: int
    graph_edges: int
    total_seconds: float
    map: Cloud
    ground_truth: list

    def ate(self, align: str = "se3") -> Optional[Ate]:
        return ate(self.poses, self.ground_truth, align) if _has_truth(self.ground_truth) else None


SEMANTIC_CLASSES = ("unknown", "floor", "wall", "ceiling", "door", "furniture")


@dataclass
class SemanticGrid:
    """The metric-semantic grid (M2): classes[row, col] (SEMANTIC_CLASSES' indices; row 0 is the
    top) and the traversability weight per cell in [0, 1] (NaN: unobserved)."""

    classes: np.ndarray
    weight: np.ndarray
    resolution: float
    origin: tuple  # lower-left corner [m]
    floor_z: float
    objects: int

    def share(self, name: str) -> float:
        """The share of cells of one class."""
        return float(np.mean(self.classes == SEMANTIC_CLASSES.index(name)))


@dataclass
class MapResult:
    poses: np.ndarray  # camera-to-map
    map_from_slam: np.ndarray
    mesh: Mesh
    band_occupancy: Grid
    occupancy: Grid
    rooms: np.ndarray  # room id per occupancy cell, 0 = none
    room_count: int
    semantic: SemanticGrid
    planes: int
    total_seconds: float


def grid_from(d: dict) -> Grid:
    return Grid(cells=d["cells"], resolution=d["resolution"], origin=tuple(d["origin"]))


def mesh_from(d: dict) -> Mesh:
    return Mesh(vertices=d["vertices"], triangles=d["triangles"], colors=d["colors"])


def cloud_from(d: dict) -> Cloud:
    return Cloud(points=d["points"], colors=d["colors"])
