"""`kartograf batch`: many recordings mapped in parallel on Ray (pip install ray), one sequence
per task: local by default, a cluster when given its address.

    kartograf batch FOLDER_OR_LIST --out DIR [--address ray://host:10001] [--workers N]
                    [--command map|slam|odometry] [-- extra arguments for each run]

FOLDER_OR_LIST: a folder of sequence folders (or bags), a text file with one path per line, or
one sequence. Each task runs the packaged CLI on its sequence, exactly as one would by hand
(`kartograf map SEQ --out DIR/NAME ...`), so the results are those of sequential runs. A sequence
that fails is reported (its error, in the summary) while the others go on. DIR/summary.json,
summary.csv and summary.md: per sequence its frames, time, ATE where there is ground truth, rooms.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Optional, Sequence as Seq

from . import rosbag

COMMANDS = ("map", "slam", "odometry")


@dataclass
class BatchResult:
    name: str
    sequence: str
    ok: bool
    seconds: float
    frames: Optional[int] = None
    ate_rmse_m: Optional[float] = None
    rooms: Optional[int] = None
    error: str = ""


def _looks_like_sequence(path: Path) -> bool:
    names = {p.name for p in path.iterdir()} if path.is_dir() else set()
    return rosbag.is_bag(path) or bool(names & {"rgb.txt", "depth.txt", "frames", "depth"}) or any(
        n.startswith("frame-") for n in names)


def find_sequences(source: str | os.PathLike) -> list:
    """The sequences of a folder of sequences, of a list file, or the one sequence given."""
    source = Path(source)
    if source.is_file() and not rosbag.is_bag(source):
        lines = [line.strip() for line in source.read_text().splitlines()]
        return [Path(line) for line in lines if line and not line.startswith("#")]
    if _looks_like_sequence(source):
        return [source]
    if not source.is_dir():
        raise FileNotFoundError(f"batch: {source} is neither a folder nor a list file")
    return sorted(p for p in source.iterdir() if _looks_like_sequence(p))


def _cli() -> list:
    return [sys.executable, "-m", "kartograf._cli"]


def _outputs(command: str, out: Path) -> list:
    if command == "odometry":
        return ["--out", str(out / "trajectory.txt"), "--stats", str(out / "stats.json")]
    return ["--out", str(out)]


def _figures(command: str, out: Path) -> dict:
    """Frames, ATE and rooms from the run's own summary file."""
    if command == "map":
        report = json.loads((out / "report.json").read_text())
        ate = report.get("evaluation", {}).get("trajectory") or {}
        return {"frames": report.get("frames"), "ate_rmse_m": ate.get("ate_rmse_m"),
                "rooms": report.get("rooms", {}).get("count")}
    stats = json.loads((out / "stats.json").read_text())
    if command == "slam":
        return {"frames": stats.get("frames"), "ate_rmse_m": stats.get("slam_ate_rmse_m")}
    return {"frames": (stats.get("summary") or {}).get("frames"),
            "ate_rmse_m": stats.get("ate_rmse_m")}


def run_one(sequence: str, out_dir: str, command: str = "map", extra: Seq[str] = ()) -> BatchResult:
    """One sequence through the CLI into out_dir/NAME (what a Ray task runs)."""
    sequence_path = Path(sequence)
    name = sequence_path.stem if rosbag.is_bag(sequence_path) and sequence_path.is_file() \
        else sequence_path.name
    out = Path(out_dir) / name
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    done = subprocess.run([*_cli(), command, str(sequence_path), *_outputs(command, out),
                           "--no-progress", "--force", *extra], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    (out / "log.txt").write_text(done.stdout + done.stderr)
    if done.returncode != 0:
        lines = [line for line in done.stderr.splitlines() if line.strip()]
        return BatchResult(name, str(sequence), False, seconds,
                           error=lines[-1] if lines else f"exit {done.returncode}")
    try:
        return BatchResult(name, str(sequence), True, seconds, **_figures(command, out))
    except (OSError, ValueError, KeyError) as error:
        return BatchResult(name, str(sequence), False, seconds, error=f"summary unreadable: {error}")


def run_sequential(sequences: Seq, out_dir: str, command: str = "map",
                   extra: Seq[str] = (), progress=print) -> list:
    results = []
    for i, sequence in enumerate(sequences):
        results.append(run_one(str(sequence), out_dir, command, extra))
        progress(_progress_line(results[-1], i + 1, len(sequences)))
    return results


def run_on_ray(sequences: Seq, out_dir: str, command: str = "map", extra: Seq[str] = (),
               address: Optional[str] = None, workers: Optional[int] = None,
               progress=print) -> list:
    """One Ray task per sequence; results in the sequences' order, progress as they finish."""
    try:
        import ray
    except ImportError as error:
        raise ImportError("kartograf batch needs Ray (pip install ray)") from error
    started_here = not ray.is_initialized()
    if started_here:
        ray.init(address=address, num_cpus=None if address else workers,
                 include_dashboard=False, log_to_driver=False)
    try:
        task = ray.remote(num_cpus=1)(run_one)
        pending = {task.remote(str(s), str(out_dir), command, list(extra)): i
                   for i, s in enumerate(sequences)}
        results: list = [None] * len(sequences)
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                index = pending.pop(ref)
                results[index] = ray.get(ref)
                progress(_progress_line(results[index], len(sequences) - len(pending),
                                        len(sequences)))
        return results
    finally:
        if started_here:
            ray.shutdown()


def _progress_line(result: BatchResult, done: int, total: int) -> str:
    state = f"ok in {result.seconds:.1f} s" if result.ok else f"FAILED: {result.error}"
    return f"batch: {done}/{total} {result.name}: {state}"


def write_summary(results: Seq, out_dir: str | os.PathLike) -> None:
    out = Path(out_dir)
    rows = [asdict(r) for r in results]
    (out / "summary.json").write_text(json.dumps(rows, indent=2) + "\n")
    with open(out / "summary.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]) if rows else ["name"])
        writer.writeheader()
        writer.writerows(rows)
    lines = ["| sequence | result | frames | time [s] | ATE RMSE [m] | rooms |",
             "|---|---|---|---|---|---|"]
    for r in results:
        ate = f"{r.ate_rmse_m:.4f}" if r.ate_rmse_m is not None else "-"
        state = "ok" if r.ok else f"failed: {r.error}"
        lines.append(f"| {r.name} | {state} | {r.frames if r.frames is not None else '-'} | "
                     f"{r.seconds:.1f} | {ate} | {r.rooms if r.rooms is not None else '-'} |")
    (out / "summary.md").write_text("\n".join(lines) + "\n")


def main(argv: Seq[str]) -> int:
    parser = argparse.ArgumentParser(prog="kartograf batch", description=__doc__.split("\n")[0])
    parser.add_argument("source", help="folder of sequences, list file, or one sequence")
    parser.add_argument("--out", required=True, help="output folder: one folder per sequence")
    parser.add_argument("--command", choices=COMMANDS, default="map")
    parser.add_argument("--address", default=None,
                        help="Ray cluster address (default: a local Ray instance)")
    parser.add_argument("--workers", type=int, default=None,
                        help="local workers (default: the cores); 0: no Ray, one after another")
    parser.epilog = "Arguments after -- go to every run (e.g. -- --backend cpu)."
    argv = list(argv)
    split = argv.index("--") if "--" in argv else len(argv)
    args, extra = parser.parse_args(argv[:split]), argv[split + 1:]
    sequences = find_sequences(args.source)
    if not sequences:
        print(f"kartograf batch: no sequence in {args.source}", file=sys.stderr)
        return 2
    Path(args.out).mkdir(parents=True, exist_ok=True)
    report = lambda line: print(line, file=sys.stderr, flush=True)  # noqa: E731
    if args.workers == 0:
        results = run_sequential(sequences, args.out, args.command, extra, report)
    else:
        results = run_on_ray(sequences, args.out, args.command, extra, args.address,
                             args.workers, report)
    write_summary(results, args.out)
    failed = [r for r in results if not r.ok]
    print(f"batch: {len(results) - len(failed)} of {len(results)} sequences mapped; "
          f"summary {Path(args.out) / 'summary.md'}")
    return 1 if failed else 0
