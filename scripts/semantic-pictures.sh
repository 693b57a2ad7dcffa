#!/usr/bin/env bash
# The real-scan pictures of docs/semantic.md: `kartograf semantic` on the DLUT laser scans, PCL's
# office1 Kinect frame and PCL's unorganized room_scan1 (labelled on a range image from its
# VIEWPOINT), each view's labels (shaded class colours, up at the top) written as
# docs/images/semantic_<scan>.png.
#
#   scripts/semantic-pictures.sh [build-dir]
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$repo/build}"
data="${KARTOGRAF_DATA_DIR:-$repo/../shared/data}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

for scan in "$data"/dlut_laser_scans/{A601,A603,A605,B602}.pcd "$data"/pcl_clouds/office1.pcd \
  "$data"/pcl_tutorials/room_scan1.pcd; do
  name="$(basename "$scan" .pcd)"
  "$build/apps/kartograf/kartograf" semantic "$scan" --out "$work/$name"
  cp "$work/$name/labels_color.png" "$repo/docs/images/semantic_${name}.png"
done
