"""Planes and rooms from Python: the same results as the CLI on the same inputs."""

import subprocess
import sys

import numpy as np
import pytest

import kartograf as kg


def cli(*args):
    subprocess.run([sys.executable, "-m", "kartograf._cli", *map(str, args)], check=True,
                   capture_output=True)


def test_planes_of_a_real_frame_equal_the_clis(cpu, data_dir, tmp_path):
    frames = data_dir / "7scenes_redkitchen" / "frames"
    sequence = kg.open_sequence(data_dir / "7scenes_redkitchen", frames=1)
    frame = sequence.frame(0)
    result = kg.extract_planes(cpu, sequence.camera, frame["depth"], frame["color"],
                               sequence.depth_units_per_metre)
    assert len(result.planes) >= 3
    assert result.labels.shape == frame["depth"].shape
    assert {p.id for p in result.planes} == set(np.unique(result.labels)) - {0}
    normal = np.asarray(result.planes[0].normal)
    assert abs(np.linalg.norm(normal) - 1) < 1e-9
    camera = sequence.camera
    cli("planes", frames / "frame-000000.depth.png", "--color", frames / "frame-000000.color.jpg",
        "--fx", camera.fx, "--fy", camera.fy, "--cx", camera.cx, "--cy", camera.cy,
        "--backend", "cpu", "--out", tmp_path / "planes")
    labels = kg.read_room_ground_truth(tmp_path / "planes" / "labels.png")
    assert np.array_equal(labels, result.labels)
    # The cells mode, through both.
    cells = kg.extract_planes(cpu, sequence.camera, frame["depth"], frame["color"],
                              sequence.depth_units_per_metre, mode="cells")
    assert len(cells.planes) >= 3 and not np.array_equal(cells.labels, result.labels)
    cli("planes", frames / "frame-000000.depth.png", "--color", frames / "frame-000000.color.jpg",
        "--fx", camera.fx, "--fy", camera.fy, "--cx", camera.cx, "--cy", camera.cy,
        "--backend", "cpu", "--mode", "cells", "--out", tmp_path / "cells")
    labels = kg.read_room_ground_truth(tmp_path / "cells" / "labels.png")
    assert np.array_equal(labels, cells.labels)
    with pytest.raises(kg.Error, match="mode"):
        kg.extract_planes(cpu, sequence.camera, frame["depth"], frame["color"], mode="fast")
    # Depth alone: the cells mode, through both; the regions mode names what is missing.
    alone = kg.extract_planes(cpu, sequence.camera, frame["depth"], None,
                              sequence.depth_units_per_metre, mode="cells")
    assert len(alone.planes) >= 3
    cli("planes", frames / "frame-000000.depth.png",
        "--fx", camera.fx, "--fy", camera.fy, "--cx", camera.cx, "--cy", camera.cy,
        "--backend", "cpu", "--mode", "cells", "--out", tmp_path / "alone")
    labels = kg.read_room_ground_truth(tmp_path / "alone" / "labels.png")
    assert np.array_equal(labels, alone.labels)
    with pytest.raises(kg.Error, match="no colour image"):
        kg.extract_planes(cpu, sequence.camera, frame["depth"], None)


def test_rooms_of_a_real_map_equal_the_clis_and_score(cpu, data_dir, tmp_path):
    maps = data_dir / "ipa_room_maps" / "test_maps"
    grid = kg.read_map(maps / "lab_ipa.png")
    assert set(np.unique(grid.cells)) <= {1, 2}
    truth = kg.read_room_ground_truth(maps / "lab_ipa_gt_segmentation.png")
    assert "voronoi" in kg.room_methods()
    rooms = kg.segment_rooms(cpu, grid, "morphological")
    assert rooms.rooms.shape == grid.cells.shape
    assert len(rooms.records) == len(set(np.unique(rooms.rooms)) - {0})
    cli("rooms", maps / "lab_ipa.png", "--method", "morphological", "--backend", "cpu",
        "--out", tmp_path / "rooms")
    assert np.array_equal(kg.read_room_ground_truth(tmp_path / "rooms" / "rooms.png"), rooms.rooms)
    scores = kg.evaluate_rooms(truth, rooms.rooms)
    assert scores.recall > 0.7 and scores.precision > 0.7, scores
    with pytest.raises(kg.Error, match="room"):
        kg.segment_rooms(cpu, grid, "watershed")


def test_a_synthetic_views_labels_agree_with_its_ground_truth(cpu, synthetic):
    sequence = kg.open_sequence(synthetic)
    frame = sequence.frame(10)
    labels = kg.label_view(cpu, sequence.camera, frame["depth"], sequence.depth_units_per_metre)
    assert labels.classes.shape == frame["depth"].shape
    assert labels.region_count > 3
    up = np.asarray(labels.up)
    assert abs(np.linalg.norm(up) - 1) < 1e-9
    # The true up in the camera frame: the world's z seen from the frame's pose.
    true_up = frame["pose"][:3, :3].T @ np.array([0.0, 0.0, 1.0])
    assert np.degrees(np.arccos(np.clip(up @ true_up, -1, 1))) < 5
    stamp = f"{frame['timestamp']:.6f}"
    truth = kg.read_semantic_png(synthetic / "gt" / "semantic" / f"{stamp}.png")
    labelled = (labels.classes != 0) & (truth != 0)
    assert labelled.mean() > 0.3
    agree = (labels.classes == truth)[labelled].mean()
    assert agree > 0.8, agree


def write_organized_pcd(path, points):
    """A binary organized PCD (x y z float32) of an H x W x 4 point array."""
    height, width = points.shape[:2]
    header = ("VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
              f"WIDTH {width}\nHEIGHT {height}\nVIEWPOINT 0 0 0 1 0 0 0\n"
              f"POINTS {width * height}\nDATA binary\n")
    path.write_bytes(header.encode() + np.ascontiguousarray(points[..., :3]).tobytes())


@pytest.mark.parametrize("source, index", [("synthetic", 10), ("7scenes", 0)])
def test_a_views_labels_equal_the_clis_on_its_organized_scan(cpu, synthetic, data_dir, tmp_path,
                                                              source, index):
    folder = synthetic if source == "synthetic" else data_dir / "7scenes_redkitchen"
    sequence = kg.open_sequence(folder, frames=index + 1)
    frame = sequence.frame(index)
    points = kg.backproject(cpu, sequence.camera, frame["depth"], sequence.depth_units_per_metre)
    assert points.shape == frame["depth"].shape + (4,) and points.dtype == np.float32
    missing = frame["depth"] == 0
    assert np.isnan(points[missing, 0]).all() and not np.isnan(points[~missing, 2]).any()
    # z is the depth in metres where there is one.
    z = frame["depth"][~missing] / sequence.depth_units_per_metre
    assert np.allclose(points[~missing, 2], z, rtol=1e-6)
    labels = kg.label_view(cpu, sequence.camera, frame["depth"], sequence.depth_units_per_metre)
    assert np.array_equal(kg.label_points(cpu, points[..., :3]).classes, labels.classes)
    write_organized_pcd(tmp_path / "view.pcd", points)
    cli("semantic", tmp_path / "view.pcd", "--backend", "cpu", "--out", tmp_path / "semantic")
    from_cli = kg.read_semantic_png(tmp_path / "semantic" / "labels.png")
    assert np.array_equal(from_cli, labels.classes)
    assert len(np.unique(labels.classes)) >= 3  # floor, walls and more: not a blank view
