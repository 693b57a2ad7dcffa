#!/usr/bin/env python3
"""The table of scripts/map-bench.sh: one row per map run, read from RUNS/NAME/report.json.

Usage: map-bench-table.py RUNS NAME...
"""
import json
import sys
from pathlib import Path

# The sequences the defaults were tuned on (issue 23: figures tuned on a seed or sequence are marked).
TUNED = {"survey-1": "yes", "7scenes": "frames 0-299", "tour-10": "large-motion rules"}


def tuned(name):
    """Whether the defaults were tuned on the sequence: the tours of seeds 1-10 (tour-10-N) are
    where the odometry's large-motion rules were found; higher seeds are held out."""
    if name.startswith("tour-10-") and name[len("tour-10-"):].isdigit():
        return "large-motion rules" if int(name[len("tour-10-"):]) <= 10 else "no"
    return TUNED.get(name, "no")
CLASSES = ("floor", "wall", "door", "furniture")


def cm(value):
    return "-" if value is None else f"{100 * value:.2f}"


def number(value, form="{:.2f}"):
    return "-" if value is None else form.format(value)


def get(report, *path):
    node = report
    for key in path:
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return node


def ate_text(r, value, at_measured):
    """The ATE in cm, and where the ground truth interpolates between measured poses (SUN3D's every
    5th frame) the ATE at those alone."""
    measured = get(r, "evaluation", at_measured)
    if value is None or not measured:
        return cm(value)
    return f"{cm(value)} ({cm(measured['ate_rmse_m'])} at the {measured['poses']} measured)"


def loops_text(r):
    """Accepted loop closures, those found by appearance, and frames from features by features."""
    accepted = get(r, "slam", "loop_closures_accepted")
    appearance = get(r, "slam", "loop_closures_by_appearance")
    recovered = get(r, "slam", "frames_from_features")
    if appearance is None:
        return str(accepted)
    return f"{accepted} ({appearance} app.) / {recovered}"


def row(runs, name):
    path = Path(runs) / name / "report.json"
    if not path.exists():
        return f"| {name} | failed: no report.json (see {name}.log) |" + " |" * 10
    r = json.loads(path.read_text())
    odometry = get(r, "evaluation", "odometry_trajectory", "ate_rmse_m")
    slam = get(r, "evaluation", "trajectory", "ate_rmse_m")
    ratio = "-" if not odometry or slam is None else f"{slam / odometry:.2f}"
    if get(r, "slam", "poses_given"):  # --poses: nothing was estimated
        odometry = slam = None
        ratio = "poses given"
    labelled, unlabelled = get(r, "views", "labelled") or 0, get(r, "views", "unlabelled") or 0
    views = "-" if labelled + unlabelled == 0 else f"{100 * labelled / (labelled + unlabelled):.0f} %"
    ious = " / ".join(number(get(r, "evaluation", "classes", "iou", c)) for c in CLASSES)
    rooms = get(r, "evaluation", "rooms")
    rooms_text = "-" if not rooms else f"{rooms['recall_mean']:.2f} / {rooms['precision_mean']:.2f}"
    cells = [name, str(r.get("frames", "-")),
             ate_text(r, odometry, "odometry_at_measured_poses"),
             ate_text(r, slam, "trajectory_at_measured_poses"), ratio,
             loops_text(r), views, ious, rooms_text,
             number(get(r, "timing_s", "odometry_ms_per_frame"), "{:.1f}"),
             number(get(r, "timing_s", "total"), "{:.0f}"), tuned(name)]
    return "| " + " | ".join(cells) + " |"


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    runs = sys.argv[1]
    print("| sequence | frames | odometry ATE cm | SLAM ATE cm | SLAM / odometry | loops accepted (by appearance) / frames from features "
          "| views labelled | IoU floor / wall / door / furniture | rooms recall / precision "
          "| odometry ms/frame | total s | tuned on |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---|---:|---:|---|")
    for name in sys.argv[2:]:
        print(row(runs, name))


if __name__ == "__main__":
    main()
