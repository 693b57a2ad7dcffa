"""Camera poses from a bag's transforms, as a robot records them: /tf_static holds fixed transforms
(base to camera), /tf holds transforms that change over time (odom to base_link, a pan-tilt head),
and a nav_msgs/Odometry topic holds its child frame's pose in its header's frame. All of them are
edges of one frame tree; the camera's pose at an image's stamp is the chain from the world frame
to the images' frame, each changing edge interpolated at that stamp (translation linearly,
rotation by slerp), as tf2 looks transforms up."""

from __future__ import annotations

from collections import deque
from typing import Optional

import numpy as np

from . import _kartograf

# How far before a changing edge's first sample or after its last one a stamp may lie and still
# take the nearest sample: the CLI's own tolerance for pairing a pose with a frame.
MAX_EXTRAPOLATION = 0.02  # seconds


def matrix_of(translation, rotation) -> np.ndarray:
    """A 4x4 transform from x, y, z and a quaternion x, y, z, w (any length)."""
    x, y, z, w = np.asarray(rotation, dtype=np.float64) / np.linalg.norm(rotation)
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = translation
    return m


def message_matrix(translation, rotation) -> np.ndarray:
    """matrix_of a message's Vector3 / Point and Quaternion."""
    return matrix_of((translation.x, translation.y, translation.z),
                     (rotation.x, rotation.y, rotation.z, rotation.w))


def quaternion(rotation: np.ndarray) -> np.ndarray:
    """x, y, z, w of a rotation matrix (w >= 0)."""
    r = rotation
    trace = np.trace(r)
    if trace > 0:
        s = 2 * np.sqrt(1 + trace)
        q = [(r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, s / 4]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2 * np.sqrt(1 + r[i, i] - r[j, j] - r[k, k])
        q = [0.0, 0.0, 0.0, (r[k, j] - r[j, k]) / s]
        q[i], q[j], q[k] = s / 4, (r[j, i] + r[i, j]) / s, (r[k, i] + r[i, k]) / s
    q = np.array(q)
    return -q if q[3] < 0 else q


def interpolate(a: np.ndarray, b: np.ndarray, fraction: float) -> np.ndarray:
    """The transform `fraction` of the way from a to b: translation linear, rotation slerp."""
    qa, qb = quaternion(a[:3, :3]), quaternion(b[:3, :3])
    if qa @ qb < 0:
        qb = -qb  # the shorter way round
    angle = np.arccos(np.clip(qa @ qb, -1.0, 1.0))
    if angle < 1e-9:
        q = qa
    else:
        q = (np.sin((1 - fraction) * angle) * qa + np.sin(fraction * angle) * qb) / np.sin(angle)
    return matrix_of((1 - fraction) * a[:3, 3] + fraction * b[:3, 3], q)


class Series:
    """A changing transform: samples (stamp, parent_T_child) looked up at any stamp they cover."""

    def __init__(self):
        self.stamps, self.matrices = [], []

    def add(self, stamp: float, m: np.ndarray) -> None:
        self.stamps.append(stamp)
        self.matrices.append(m)

    def sort(self) -> None:
        order = np.argsort(self.stamps, kind="stable")
        self.stamps = [self.stamps[i] for i in order]
        self.matrices = [self.matrices[i] for i in order]

    def at(self, stamp: float) -> Optional[np.ndarray]:
        """The transform at stamp, or None when stamp lies outside the samples' span."""
        first, last = self.stamps[0], self.stamps[-1]
        if stamp < first - MAX_EXTRAPOLATION or stamp > last + MAX_EXTRAPOLATION:
            return None
        after = int(np.searchsorted(self.stamps, stamp))
        if after == 0 or after == len(self.stamps):
            return self.matrices[min(after, len(self.stamps) - 1)]
        t0, t1 = self.stamps[after - 1], self.stamps[after]
        fraction = (stamp - t0) / (t1 - t0) if t1 > t0 else 1.0
        return interpolate(self.matrices[after - 1], self.matrices[after], fraction)

    def span(self) -> str:
        return f"{self.stamps[0]:.6f} to {self.stamps[-1]:.6f}"


def _name(frame: str) -> str:
    return frame.lstrip("/")


class FrameTree:
    """Transforms between frames (parent -> child), fixed or changing, looked up in either
    direction at a stamp."""

    def __init__(self):
        self._fixed: dict = {}  # (parent, child) -> parent_T_child
        self._changing: dict = {}  # (parent, child) -> Series
        self._parent: dict = {}  # child -> parent

    def add_fixed(self, parent: str, child: str, m: np.ndarray) -> None:
        edge = (_name(parent), _name(child))
        if edge not in self._changing:
            self._fixed.setdefault(edge, m)
            self._parent.setdefault(edge[1], edge[0])

    def add_sample(self, parent: str, child: str, stamp: float, m: np.ndarray) -> None:
        edge = (_name(parent), _name(child))
        self._fixed.pop(edge, None)
        self._changing.setdefault(edge, Series()).add(stamp, m)
        self._parent.setdefault(edge[1], edge[0])

    def has_edge(self, parent: str, child: str) -> bool:
        edge = (_name(parent), _name(child))
        return edge in self._fixed or edge in self._changing

    def finish(self) -> None:
        for series in self._changing.values():
            series.sort()

    def root(self, frame: str) -> str:
        """The topmost ancestor of frame (the world frame of its chain)."""
        frame, seen = _name(frame), set()
        while frame in self._parent and frame not in seen:
            seen.add(frame)
            frame = self._parent[frame]
        return frame

    def _neighbours(self, frame: str, stamp: float):
        for (parent, child), m in self._fixed.items():
            if parent == frame:
                yield child, m
            elif child == frame:
                yield parent, np.linalg.inv(m)
        for (parent, child), series in self._changing.items():
            if frame not in (parent, child):
                continue
            m = series.at(stamp)
            if m is not None:
                yield (child, m) if parent == frame else (parent, np.linalg.inv(m))

    def transform(self, source: str, target: str, stamp: float) -> Optional[np.ndarray]:
        """source_T_target at stamp (a point in target's frame to source's), or None when no
        chain connects them at that stamp."""
        source, target = _name(source), _name(target)
        if source == target:
            return np.eye(4)
        seen, queue = {source}, deque([(source, np.eye(4))])
        while queue:
            frame, pose = queue.popleft()
            for nxt, m in self._neighbours(frame, stamp):
                if nxt == target:
                    return pose @ m
                if nxt not in seen:
                    seen.add(nxt)
                    queue.append((nxt, pose @ m))
        return None

    def describe_changing(self) -> str:
        return "; ".join(f"{p} -> {c} from {s.span()}" for (p, c), s in self._changing.items())


def camera_poses(tree: FrameTree, world: str, camera_frame: str, stamps: list) -> list:
    """(stamp, world_T_camera) at every stamp; an Error naming the first stamp no chain covers."""
    out, missing = [], []
    for stamp in stamps:
        pose = tree.transform(world, camera_frame, stamp)
        if pose is None:
            missing.append(stamp)
        else:
            out.append((stamp, pose))
    if missing:
        raise _kartograf.Error(
            f"bag: no transform from '{world}' to '{camera_frame}' (the images' frame) for "
            f"{len(missing)} of {len(stamps)} depth images, the first at {missing[0]:.6f}; "
            f"changing transforms: {tree.describe_changing() or 'none'}")
    return out


def write_tum(path, poses: list, source: str) -> None:
    lines = [f"# camera poses from {source}: timestamp tx ty tz qx qy qz qw"]
    for stamp, pose in poses:
        q = quaternion(pose[:3, :3])
        t = pose[:3, 3]
        lines.append(f"{stamp:.6f} " + " ".join(f"{v:.9f}" for v in (*t, *q)))
    path.write_text("\n".join(lines) + "\n")
