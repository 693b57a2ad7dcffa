"""Sequence folders and synthetic data sets as NumPy arrays."""

import numpy as np
import pytest

import kartograf as kg


def test_a_synthetic_sequence_reads_back_with_its_ground_truth(synthetic):
    sequence = kg.open_sequence(synthetic)
    assert len(sequence) == 30
    assert sequence.layout == "synthetic"
    assert sequence.depth_units_per_metre == 5000.0
    camera = sequence.camera
    assert (camera.width, camera.height) == (320, 240)
    frame = sequence.frame(4)
    assert frame["depth"].shape == (240, 320) and frame["depth"].dtype == np.uint16
    assert frame["color"].shape == (240, 320, 3) and frame["color"].dtype == np.uint8
    assert frame["pose"].shape == (4, 4)
    assert np.allclose(frame["pose"][:3, :3] @ frame["pose"][:3, :3].T, np.eye(3), atol=1e-9)
    assert (frame["depth"] > 0).mean() > 0.5


def test_synthesize_returns_the_poses_it_wrote(synthetic, tmp_path):
    summary = kg.synthesize(tmp_path / "again", seed=3, frames=30, trajectory="handheld",
                            width=320, height=240)
    sequence = kg.open_sequence(synthetic)
    assert summary["poses"].shape == (30, 4, 4)
    assert np.allclose(summary["poses"][7], sequence.frame(7)["pose"], atol=1e-6)


def test_synthesize_writes_what_the_cli_writes(synthetic, tmp_path):
    import subprocess
    import sys

    subprocess.run([sys.executable, "-m", "kartograf._cli", "synth", "--out", str(tmp_path / "cli"),
                    "--seed", "3", "--frames", "30", "--trajectory", "handheld", "--width", "320",
                    "--height", "240"], check=True, capture_output=True)
    for name in ("groundtruth.txt", "rgb.txt", "depth.txt", "world.json"):
        assert (tmp_path / "cli" / name).read_bytes() == (synthetic / name).read_bytes(), name
    first = sorted((synthetic / "depth").glob("*.png"))[5].name
    assert (tmp_path / "cli" / "depth" / first).read_bytes() == \
        (synthetic / "depth" / first).read_bytes()


def test_frame_ranges_and_bad_input(synthetic, tmp_path):
    part = kg.open_sequence(synthetic, first=10, frames=5, step=2)
    assert len(part) == 5
    assert part.frame(0)["index"] == 10
    with pytest.raises(kg.Error, match="frame 5"):
        part.frame(5)
    with pytest.raises(kg.Error, match="nowhere"):
        kg.open_sequence(tmp_path / "nowhere")
    with pytest.raises(kg.Error, match="trajectory"):
        kg.synthesize(tmp_path / "x", trajectory="drone")


def test_real_seven_scenes_frames(data_dir):
    sequence = kg.open_sequence(data_dir / "7scenes_redkitchen", frames=3)
    frame = sequence.frame(0)
    assert frame["depth"].shape == (480, 640)
    assert frame["pose"] is not None
    assert sequence.camera.fx == 585.0
    assert sequence.has_color


def test_a_depth_camera_alone(synthetic, tmp_path):
    """A TUM folder with depth.txt and no rgb.txt: frames without colour, said so."""
    folder = tmp_path / "depth_alone"
    folder.mkdir()
    for name in ("depth.txt", "groundtruth.txt", "camera_intrinsics.json"):
        (folder / name).write_bytes((synthetic / name).read_bytes())
    (folder / "depth").symlink_to(synthetic / "depth")
    sequence = kg.open_sequence(folder, frames=3)
    assert not sequence.has_color
    assert any("depth alone" in w for w in sequence.warnings)
    frame = sequence.frame(2)
    assert frame["color"] is None and frame["depth"].shape == (240, 320)
    assert frame["pose"] is not None
