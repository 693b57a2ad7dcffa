"""Planes of RGB-D frames (the M1 method) and rooms of 2-D maps (the M4 methods)."""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from . import _kartograf
from .results import Grid, grid_from


@dataclass
class Plane:
    """n . p + offset = 0 in the camera frame, n towards the camera."""

    id: int
    normal: tuple
    offset: float
    centroid: tuple
    inlier_count: int
    rms_error: float


@dataclass
class PlaneSet:
    planes: list  # Plane, by decreasing pixel count
    labels: np.ndarray  # H x W uint16 plane id per pixel, 0 = none
    milliseconds: float


def extract_planes(context: _kartograf.Context, camera: _kartograf.PinholeIntrinsics,
                   depth: np.ndarray, color: np.ndarray | None, depth_units: float = 1000.0,
                   mode: str = "regions") -> PlaneSet:
    """The planes of one frame, as `kartograf planes --mode MODE`: "regions" (the M1 paper's Lab
    region growing, fits, merging) or "cells" (planar cells first, about 3x faster). The cells
    mode also takes color=None (a depth camera alone); the regions mode raises kartograf.Error."""
    d = _kartograf.extract_planes(context, camera, depth, color, depth_units, mode)
    return PlaneSet(planes=[Plane(**p) for p in d["planes"]], labels=d["labels"],
                    milliseconds=d["milliseconds"])


@dataclass
class ViewLabels:
    """The M2 labelling of one view: classes per pixel (kartograf.SEMANTIC_CLASSES' indices),
    the regions it grew, and the up direction it found (camera frame)."""

    classes: np.ndarray  # H x W uint8
    regions: np.ndarray  # H x W uint16, 0 = no region
    region_count: int
    up: tuple


def backproject(context: _kartograf.Context, camera: _kartograf.PinholeIntrinsics,
                depth: np.ndarray, depth_units: float = 1000.0) -> np.ndarray:
    """A depth frame as an organized cloud in the camera frame: H x W x 4 float32 (x, y, z, 1;
    NaN where the depth is missing or out of range), handed over without a copy."""
    return _kartograf.backproject(context, camera, depth, depth_units)


def label_points(context: _kartograf.Context, points: np.ndarray) -> ViewLabels:
    """Normals, regions, gravity and the floor / wall / ceiling / door / furniture rules on one
    organized view (H x W x 3 or 4 float32 in the sensor's frame, NaN where there is no point),
    as `kartograf semantic SCAN.pcd` labels an organized scan (docs/methods.md M2 steps 1-3)."""
    points = np.asarray(points, dtype=np.float32)
    if points.ndim == 3 and points.shape[2] == 3:
        points = np.concatenate([points, np.ones(points.shape[:2] + (1,), np.float32)], axis=2)
    return ViewLabels(**_kartograf.label_points(context, np.ascontiguousarray(points)))


def label_view(context: _kartograf.Context, camera: _kartograf.PinholeIntrinsics,
               depth: np.ndarray, depth_units: float = 1000.0) -> ViewLabels:
    """label_points of a depth frame's back-projection."""
    return label_points(context, backproject(context, camera, depth, depth_units))


def read_semantic_png(path: str | os.PathLike) -> np.ndarray:
    """An 8-bit semantic image (a synthetic data set's gt/semantic/*.png)."""
    return _kartograf.read_semantic_png(os.fspath(path))


@dataclass
class Room:
    id: int
    area_m2: float
    centroid: tuple  # map frame [m]
    neighbours: list


@dataclass
class RoomSegmentation:
    rooms: np.ndarray  # H x W uint16 room id per cell, 0 = none
    records: list  # Room
    method: str
    seconds: float


@dataclass
class RoomScores:
    recall: float
    precision: float
    mcc: float
    ground_truth_rooms: int
    segments: int


def room_methods() -> list:
    """morphological, distance, voronoi, feature, vrf."""
    return _kartograf.room_methods()


def read_map(path: str | os.PathLike, resolution: float = 0.05) -> Grid:
    """A ROS map_server .yaml or an ipa-style PNG map as a Grid."""
    return grid_from(_kartograf.read_map(os.fspath(path), resolution))


def read_room_ground_truth(path: str | os.PathLike) -> np.ndarray:
    """Ground-truth rooms: an ipa *_gt_segmentation.png or a 16-bit label PNG."""
    return _kartograf.read_room_ground_truth(os.fspath(path))


def segment_rooms(context: _kartograf.Context, grid: Grid,
                  method: str = "voronoi") -> RoomSegmentation:
    """The rooms of a 2-D map by one of room_methods()."""
    d = _kartograf.segment_rooms(context, np.ascontiguousarray(grid.cells, dtype=np.uint8),
                                 grid.resolution, tuple(grid.origin), method)
    return RoomSegmentation(rooms=d["rooms"], records=[Room(**r) for r in d["records"]],
                            method=d["method"], seconds=d["seconds"])


def evaluate_rooms(ground_truth: np.ndarray, segmentation: np.ndarray) -> RoomScores:
    """Recall, precision (means over rooms and segments) and MCC, as `kartograf rooms-eval`."""
    return RoomScores(**_kartograf.evaluate_rooms(
        np.ascontiguousarray(ground_truth, dtype=np.uint16),
        np.ascontiguousarray(segmentation, dtype=np.uint16)))
