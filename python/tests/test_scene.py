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
