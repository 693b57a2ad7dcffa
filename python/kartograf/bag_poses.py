"""Camera poses from a bag's odometry: nav_msgs/Odometry gives the pose of its child frame (the
robot's base); /tf_static (and the first /tf messages) gives the fixed chain from that frame to
the camera's (the images' header frame_id). The camera's pose is their product."""

from __future__ import annotations

from collections import deque
from typing import Optional

import numpy as np

from . import _kartograf


def _matrix(translation, rotation) -> np.ndarray:
    x, y, z, w = rotation.x, rotation.y, rotation.z, rotation.w
    n = np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = [translation.x, translation.y, translation.z]
    return m


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


class FrameTree:
    """Fixed transforms between frames (parent -> child), looked up in either direction."""

    def __init__(self):
        self._edges: dict = {}

    def add(self, stamped) -> None:
        m = _matrix(stamped.transform.translation, stamped.transform.rotation)
        parent, child = stamped.header.frame_id.lstrip("/"), stamped.child_frame_id.lstrip("/")
        self._edges.setdefault(parent, {}).setdefault(child, m)
        self._edges.setdefault(child, {}).setdefault(parent, np.linalg.inv(m))

    def transform(self, source: str, target: str) -> Optional[np.ndarray]:
        """source_T_target (a point in target's frame to source's), or None when unconnected."""
        source, target = source.lstrip("/"), target.lstrip("/")
        if source == target:
            return np.eye(4)
        seen, queue = {source}, deque([(source, np.eye(4))])
        while queue:
            frame, pose = queue.popleft()
            for nxt, m in self._edges.get(frame, {}).items():
                if nxt in seen:
                    continue
                if nxt == target:
                    return pose @ m
                seen.add(nxt)
                queue.append((nxt, pose @ m))
        return None


def camera_poses(odometry: list, tree: FrameTree, camera_frame: str) -> list:
    """(stamp, world_T_camera) per odometry message: its pose times child_T_camera."""
    out = []
    for stamp, msg in odometry:
        child_T_camera = tree.transform(msg.child_frame_id, camera_frame)
        if child_T_camera is None:
            raise _kartograf.Error(f"bag: no transform from '{msg.child_frame_id}' (odometry) to "
                                   f"'{camera_frame}' (the images) in /tf_static or /tf")
        out.append((stamp, _matrix(msg.pose.pose.position, msg.pose.pose.orientation)
                    @ child_T_camera))
    return out


def write_tum(path, poses: list) -> None:
    lines = ["# camera poses from the bag's odometry: timestamp tx ty tz qx qy qz qw"]
    for stamp, pose in poses:
        q = quaternion(pose[:3, :3])
        t = pose[:3, 3]
        lines.append(f"{stamp:.6f} " + " ".join(f"{v:.9f}" for v in (*t, *q)))
    path.write_text("\n".join(lines) + "\n")
