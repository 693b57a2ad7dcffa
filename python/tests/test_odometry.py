"""The odometry from Python: no copy of the depth image, the same poses as over the whole
sequence and as the CLI, picklable results."""

import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kartograf as kg


def frames_of(sequence):
    return [sequence.frame(i) for i in range(len(sequence))]


def test_the_depth_array_is_read_in_place(cpu, synthetic):
    sequence = kg.open_sequence(synthetic)
    odometry = kg.Odometry(cpu, sequence.camera, sequence.depth_units_per_metre)
    depth = np.ascontiguousarray(sequence.frame(0)["depth"])
    odometry.track(depth)
    assert odometry.last_depth_address == depth.ctypes.data
    # A layout the library cannot read in place is copied first (and still tracked).
    flipped = np.ascontiguousarray(sequence.frame(1)["depth"][::-1, :])[::-1, :]
    assert not flipped.flags["C_CONTIGUOUS"]
    report = odometry.track(flipped)
    assert odometry.last_depth_address != flipped.ctypes.data
    assert report.index == 1
    with pytest.raises(TypeError):
        odometry.track(np.zeros((240, 320, 2), np.uint16))


def test_frame_by_frame_equals_the_sequence_run(cpu, synthetic):
    sequence = kg.open_sequence(synthetic)
    odometry = kg.Odometry(cpu, sequence.camera, sequence.depth_units_per_metre)
    reports = [odometry.track(f["depth"], f["color"]) for f in frames_of(sequence)]
    run = kg.run_odometry(cpu, sequence)
    assert run.poses.shape == (30, 4, 4)
    assert np.allclose(odometry.poses, run.poses, atol=1e-9)
    assert [r.keyframe for r in reports] == [f.keyframe for f in run.frames]
    ate = run.ate()
    assert ate is not None and ate.count == 30
    assert ate.rmse_m < 0.05, ate


def test_a_motion_prior_predicts_each_step(cpu, synthetic):
    """Another sensor's poses (here the sequence's own, an ideal wheel odometry, moved 1 m away:
    only their relative motion counts) predict every step after the first; a pose that is no
    rigid motion is an Error."""
    sequence = kg.open_sequence(synthetic)
    odometry = kg.Odometry(cpu, sequence.camera, sequence.depth_units_per_metre)
    offset = np.eye(4)
    offset[:3, 3] = (1.0, 0.0, 0.0)
    reports = [odometry.track(f["depth"], None, offset @ f["pose"]) for f in frames_of(sequence)]
    assert [r.extra["from_motion_prior"] for r in reports] == [False] + [True] * 29
    # How far each step ended from the prior's: the registration's error against an ideal prior.
    assert np.median([r.extra["prior_difference_m"] for r in reports[1:]]) < 0.005
    truth = [f["pose"] for f in frames_of(sequence)]
    assert kg.ate(odometry.poses, truth).rmse_m < 0.05
    with pytest.raises(kg.Error, match="Odometry.track"):
        odometry.track(sequence.frame(0)["depth"], None, np.zeros((4, 4)))


def test_worst_steps_are_the_largest_and_agree_with_the_ate(cpu, synthetic):
    run = kg.run_odometry(cpu, kg.open_sequence(synthetic))
    worst = run.worst_steps(count=5)
    assert len(worst.steps) == 5
    errors = [s.translation_m for s in worst.steps]
    assert errors == sorted(errors, reverse=True) and errors[0] > 0
    assert abs(worst.ate_rmse_m - run.ate().rmse_m) < 1e-12
    steps = [np.linalg.inv(a) @ b for a, b in zip(run.poses[:-1], run.poses[1:])]
    truth = [np.linalg.inv(a) @ b for a, b in zip(run.ground_truth[:-1], run.ground_truth[1:])]
    first = worst.steps[0]
    error = np.linalg.inv(truth[first.frame - 1]) @ steps[first.frame - 1]
    assert abs(np.linalg.norm(error[:3, 3]) - first.translation_m) < 1e-9
    with pytest.raises(Exception, match="align"):
        kg.worst_steps(run.poses, run.ground_truth, 3, "affine")


def test_results_pickle(cpu, synthetic):
    run = kg.run_odometry(cpu, kg.open_sequence(synthetic, frames=8))
    copy = pickle.loads(pickle.dumps(run))
    assert np.array_equal(copy.poses, run.poses)
    assert copy.frames[3] == run.frames[3]
    assert copy.ate() == run.ate()


def read_tum(path):
    rows = [line.split() for line in Path(path).read_text().splitlines()
            if line and not line.startswith("#")]
    return np.array([[float(v) for v in row[1:]] for row in rows])


def pose_rows(poses):
    """TUM rows (tx ty tz qx qy qz qw) of 4 x 4 poses."""
    from_matrix = []
    for pose in poses:
        r = pose[:3, :3]
        w = np.sqrt(max(0.0, 1 + np.trace(r))) / 2
        q = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / (4 * w)
        from_matrix.append([*pose[:3, 3], *q, w])
    return np.array(from_matrix)


def test_the_same_trajectory_as_the_cli(cpu, synthetic, tmp_path):
    out = tmp_path / "trajectory.txt"
    done = subprocess.run([sys.executable, "-m", "kartograf._cli", "odometry", str(synthetic),
                           "--out", str(out), "--backend", "cpu", "--no-progress"],
                          check=True, capture_output=True, text=True)
    run = kg.run_odometry(cpu, kg.open_sequence(synthetic))
    assert np.allclose(read_tum(out), pose_rows(run.poses), atol=2e-6)
    # The ATE the CLI prints (6 decimals) is the API's.
    printed = [line.split()[1] for line in done.stdout.splitlines() if "ate_rmse_m" in line]
    assert printed and abs(float(printed[0]) - run.ate().rmse_m) < 1e-6


def test_bad_choices_are_errors(cpu, synthetic):
    sequence = kg.open_sequence(synthetic, frames=3)
    with pytest.raises(kg.Error, match="'icp' is not an odometry method"):
        kg.run_odometry(cpu, sequence, method="icp")
    with pytest.raises(kg.Error, match="tracking"):
        kg.run_odometry(cpu, sequence, tracking="dense")
    odometry = kg.Odometry(cpu, sequence.camera, sequence.depth_units_per_metre)
    with pytest.raises(kg.Error, match="320x240|size"):
        odometry.track(np.zeros((10, 10), np.uint16))


def test_real_frames_track_and_score(cpu, data_dir):
    run = kg.run_odometry(cpu, kg.open_sequence(data_dir / "7scenes_redkitchen", frames=20))
    assert run.ate().rmse_m < 0.05
    assert run.frames_per_second > 0


def _turning_body(times):
    """A body turning unevenly about z while driving along x: N x 4 x 4 poses."""
    yaw = 0.8 * np.sin(1.3 * times) + 0.3 * np.sin(3.1 * times)
    poses = np.tile(np.eye(4), (len(times), 1, 1))
    poses[:, 0, 0] = poses[:, 1, 1] = np.cos(yaw)
    poses[:, 1, 0] = np.sin(yaw)
    poses[:, 0, 1] = -np.sin(yaw)
    poses[:, 0, 3] = 0.3 * times
    return poses


def test_clock_offset_finds_a_wheel_odometrys_lead():
    frames = np.arange(0.0, 20.0, 1 / 30)
    wheels = np.arange(-2.0, 22.0, 0.1)
    # The wheels' clock runs 40 ms ahead: the pose they stamp t + 0.04 is the body's at t.
    lead = kg.clock_offset(frames, _turning_body(frames), wheels + 0.04, _turning_body(wheels))
    assert lead.observable and abs(lead.offset_s - 0.04) < 0.002, lead
    assert lead.given_rms_deg > lead.rms_deg
    still = np.tile(np.eye(4), (len(frames), 1, 1))
    assert not kg.clock_offset(frames, still, frames, still).observable
    with pytest.raises(kg.Error, match="times but"):
        kg.clock_offset(frames[:5], _turning_body(frames), wheels, _turning_body(wheels))
