#!/usr/bin/env python3
"""Step-by-step errors of an odometry run against its ground truth (a development tool, not a test).

Usage: step-errors.py [--poses odometry.txt] [--min-m 0.05] [--min-deg 2] [--show 8]
                      [--frames FIRST:LAST] RUN...

RUN is a `kartograf slam` output folder: the estimate (odometry.txt by default; trajectory.txt for
the SLAM's), groundtruth.txt and stats.json (the per-frame flags; without it no step is marked). Each
step (frame i-1 to i) is compared with the true one, both in the camera frame of i-1, so a wrong
step counts once, where it happened, however far the chain drifts after it. Per run, one line:
the steps, the wrong ones (over --min-m or --min-deg), the summed translation error, the part of it
in steps whose motion the frame did not measure (a degenerate view whose images measured nothing:
stats.json `degenerate` and not `photometric`), the part where the true step length was the one
the speed's last change predicts (the estimate's two steps before: s2 + (s2 - s3), within 5 cm,
beyond 5 cm from the last step: a robot speeding up or slowing down at a constant rate), and the
first --show wrong steps as FRAME(error m, error deg)[U: unmeasured, A: that change of speed].
--frames lists every step in a range with its flags.
"""
import argparse
import json
import math
from pathlib import Path


def quaternion_matrix(x, y, z, w):
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def read_trajectory(path):
    """{timestamp (0.1 ms): (rotation rows, translation)} of a TUM trajectory file."""
    poses = {}
    for line in Path(path).read_text().splitlines():
        fields = line.split()
        if not fields or fields[0].startswith("#"):
            continue
        v = [float(f) for f in fields[:8]]
        poses[round(v[0], 4)] = (quaternion_matrix(*v[4:8]), v[1:4])
    return poses


def relative(a, b):
    """a^-1 b for (rotation, translation) pairs."""
    ra, ta = a
    rb, tb = b
    rt = [[ra[j][i] for j in range(3)] for i in range(3)]
    rotation = [[sum(rt[i][k] * rb[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    d = [tb[k] - ta[k] for k in range(3)]
    return rotation, [sum(rt[i][k] * d[k] for k in range(3)) for i in range(3)]


def angle_deg(rotation):
    trace = rotation[0][0] + rotation[1][1] + rotation[2][2]
    return math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))


def length(v):
    return math.sqrt(sum(c * c for c in v))


def steps(run, poses_file):
    """Per step i (1..n-1): (true step, estimated step, flags of frame i)."""
    estimate = read_trajectory(run / poses_file)
    truth = read_trajectory(run / "groundtruth.txt")
    stats_file = run / "stats.json"
    per_frame = json.loads(stats_file.read_text())["per_frame"] if stats_file.exists() else []
    times = sorted(t for t in estimate if t in truth)
    for i in range(1, len(times)):
        flags = per_frame[i] if i < len(per_frame) else {}
        yield (i, relative(truth[times[i - 1]], truth[times[i]]),
               relative(estimate[times[i - 1]], estimate[times[i]]), flags)


def describe(run, poses_file, min_m, min_deg):
    rows = []
    for i, true_step, est_step, flags in steps(run, poses_file):
        error = relative(true_step, est_step)
        rows.append({"frame": i, "error_m": length(error[1]), "error_deg": angle_deg(error[0]),
                     "true_m": length(true_step[1]), "true_deg": angle_deg(true_step[0]),
                     "est_m": length(est_step[1]), "est_deg": angle_deg(est_step[0]),
                     "flags": flags})
    for k, row in enumerate(rows):
        row["wrong"] = row["error_m"] > min_m or row["error_deg"] > min_deg
        row["unmeasured"] = bool(row["flags"].get("degenerate")) and not row["flags"].get(
            "photometric")
        row["speed_change"] = False
        if k >= 2:
            s2, s3 = rows[k - 1]["est_m"], rows[k - 2]["est_m"]
            changed = 2 * s2 - s3
            row["speed_change"] = (abs(row["true_m"] - changed) < 0.05 and
                                   abs(row["true_m"] - s2) > 0.05)
    return rows


def summary(name, rows, show):
    total = sum(r["error_m"] for r in rows)
    unmeasured = sum(r["error_m"] for r in rows if r["unmeasured"])
    speed = sum(r["error_m"] for r in rows if r["speed_change"])
    wrong = [r for r in rows if r["wrong"]]
    marks = " ".join("%d(%.2f,%.0f)%s%s" % (r["frame"], r["error_m"], r["error_deg"],
                                            "U" if r["unmeasured"] else "",
                                            "A" if r["speed_change"] else "")
                     for r in wrong[:show])
    return ("%s: %d steps, %d wrong, step error %.2f m (unmeasured %.2f, speed change %.2f) %s" %
            (name, len(rows), len(wrong), total, unmeasured, speed, marks))


def listing(rows, first, last):
    for r in rows:
        if first <= r["frame"] <= last:
            flags = [k for k, v in r["flags"].items() if v is True]
            print("  %4d true %.3f m %5.1f deg | estimate %.3f m %5.1f deg | error %.3f m %5.1f deg"
                  " | eigenvalue ratio %.3f %s" %
                  (r["frame"], r["true_m"], r["true_deg"], r["est_m"], r["est_deg"], r["error_m"],
                   r["error_deg"], r["flags"].get("eigenvalue_ratio", float("nan")), " ".join(flags)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--poses", default="odometry.txt")
    parser.add_argument("--min-m", type=float, default=0.05)
    parser.add_argument("--min-deg", type=float, default=2.0)
    parser.add_argument("--show", type=int, default=8)
    parser.add_argument("--frames", default="")
    args = parser.parse_args()
    for run in args.runs:
        rows = describe(run, args.poses, args.min_m, args.min_deg)
        print(summary(run.name, rows, args.show))
        if args.frames:
            first, last = (int(v) for v in args.frames.split(":"))
            listing(rows, first, last)


if __name__ == "__main__":
    main()
