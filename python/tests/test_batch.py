"""`kartograf batch`: 8 synthetic sequences on 2 Ray workers give what sequential runs give; a
broken sequence among them is reported while the others finish."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import kartograf as kg
from kartograf import batch


@pytest.fixture(scope="module")
def sequences(tmp_path_factory):
    root = tmp_path_factory.mktemp("batch_input")
    # Eight hand-held worlds the map pipeline can label (seed 7's first views see no floor to
    # take gravity from: an error of the input, not of the batch).
    for seed in (1, 2, 3, 4, 5, 6, 8, 10):
        kg.synthesize(root / f"seed{seed}", seed=seed, frames=12, trajectory="handheld",
                      width=320, height=240)
    broken = root / "seed9_broken"
    shutil.copytree(root / "seed1", broken)
    for depth in sorted((broken / "depth").glob("*.png"))[3:6]:
        depth.write_bytes(b"not a png")  # a truncated recording
    return root


def trajectories(out):
    return {p.parent.name: p.read_text() for p in Path(out).glob("*/trajectory.txt")}


def test_ray_batch_equals_sequential_runs_and_reports_the_broken_one(sequences, tmp_path):
    out = tmp_path / "ray"
    done = subprocess.run([sys.executable, "-m", "kartograf._cli", "batch", str(sequences),
                           "--out", str(out), "--workers", "2", "--", "--backend", "cpu"],
                          capture_output=True, text=True)
    assert done.returncode == 1, done.stderr  # one sequence failed
    assert "batch: 9/9" in done.stderr
    summary = {r["name"]: r for r in json.loads((out / "summary.json").read_text())}
    assert len(summary) == 9
    broken = summary.pop("seed9_broken")
    assert not broken["ok"] and "seed9_broken/depth" in broken["error"]
    assert all(r["ok"] and r["frames"] == 12 and r["ate_rmse_m"] < 0.05 for r in summary.values())
    sequential = batch.run_sequential(batch.find_sequences(sequences), str(tmp_path / "one"),
                                      extra=["--backend", "cpu"], progress=lambda line: None)
    by_name = {r.name: r for r in sequential}
    for name, r in summary.items():
        assert (r["frames"], r["ate_rmse_m"], r["rooms"]) == (
            by_name[name].frames, by_name[name].ate_rmse_m, by_name[name].rooms), name
    ray_runs, one_by_one = trajectories(out), trajectories(tmp_path / "one")
    assert len(ray_runs) == 8 and ray_runs == one_by_one
    assert "| seed9_broken | failed:" in (out / "summary.md").read_text()


def test_a_list_file_and_one_sequence(sequences, tmp_path):
    listing = tmp_path / "list.txt"
    listing.write_text(f"# two of them\n{sequences / 'seed2'}\n{sequences / 'seed3'}\n")
    assert [p.name for p in batch.find_sequences(listing)] == ["seed2", "seed3"]
    assert batch.find_sequences(sequences / "seed4") == [sequences / "seed4"]
    assert len(batch.find_sequences(sequences)) == 9
