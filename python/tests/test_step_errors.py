"""scripts/step-errors.py: each step of a run against the truth, with the frame's flags."""

import json
import math
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "step-errors.py"


def write_trajectory(path, poses):
    """poses: (x, y, z, yaw in degrees about the camera's y axis) per frame, 0.1 s apart."""
    lines = ["# timestamp tx ty tz qx qy qz qw"]
    for i, (x, y, z, yaw) in enumerate(poses):
        half = math.radians(yaw) / 2
        lines.append(f"{0.1 * i:.6f} {x} {y} {z} 0 {math.sin(half)} 0 {math.cos(half)}")
    path.write_text("\n".join(lines) + "\n")


def make_run(folder, truth, estimate, flags):
    folder.mkdir()
    write_trajectory(folder / "groundtruth.txt", truth)
    write_trajectory(folder / "odometry.txt", estimate)
    per_frame = [dict({"frame": i, "eigenvalue_ratio": 0.1}, **f) for i, f in enumerate(flags)]
    (folder / "stats.json").write_text(json.dumps({"per_frame": per_frame}))
    return folder


def run(*args):
    done = subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True,
                          text=True, check=True)
    return done.stdout


def test_a_wrong_step_counts_once_where_it_happened(tmp_path):
    # The robot speeds up 0.1, 0.3, 0.5, 0.7 m a frame along z; the estimate takes the last step
    # as 0.5 (a degenerate view that the images did not measure), then drifts by it for ever.
    truth = [(0, 0, 0, 0), (0, 0, 0.1, 0), (0, 0, 0.4, 0), (0, 0, 0.9, 0), (0, 0, 1.6, 0)]
    estimate = [(0, 0, 0, 0), (0, 0, 0.1, 0), (0, 0, 0.4, 0), (0, 0, 0.9, 0), (0, 0, 1.4, 0)]
    flags = [{}, {}, {}, {}, {"degenerate": True, "photometric": False}]
    out = run(make_run(tmp_path / "speeding", truth, estimate, flags))
    assert "4 steps, 1 wrong" in out
    assert "step error 0.20 m (unmeasured 0.20, speed change 0.20)" in out
    assert "4(0.20,0)UA" in out


def test_a_turn_is_compared_in_the_camera_frame(tmp_path):
    # Turned 90 degrees, the robot steps along its new axis: right in the camera frame although
    # the world step differs from the first one; a missed turn is a wrong step of 90 degrees.
    truth = [(0, 0, 0, 0), (0, 0, 0, 90), (0.5, 0, 0, 90)]
    right = run(make_run(tmp_path / "right", truth, truth, [{}, {}, {}]))
    assert "2 steps, 0 wrong" in right
    missed = [(0, 0, 0, 0), (0, 0, 0, 0), (0, 0, 0.5, 0)]
    wrong = run(make_run(tmp_path / "missed", truth, missed, [{}, {}, {}]), "--frames", "1:1")
    assert "1(0.00,90)" in wrong
    assert "error 0.000 m  90.0 deg" in wrong
