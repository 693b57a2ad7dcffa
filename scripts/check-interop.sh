#!/usr/bin/env bash
# Point-cloud interop check: clouds Kartograf writes (PCD ascii / binary / binary_compressed, PLY
# binary and ascii) are read by Open3D and by PCL's command-line tools with the expected counts and
# values, and what PCL and Open3D write from them is read back by Kartograf to the same values.
# Exits non-zero on any mismatch. Builds nothing: pass a build folder where the Kartograf side,
# kartograf_interop_samples (tests/pcd_interop_samples.cpp), is built and up to date.
#
#   scripts/check-interop.sh <build-dir> [work-dir]
#
# Needs python3-open3d for /usr/bin/python3 and pcl-tools (pcl_pcd2ply, pcl_ply2pcd,
# pcl_convert_pcd_ascii_binary, pcl_fpfh_estimation). See docs/interop.md.
set -euo pipefail

if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: $0 <build-dir> [work-dir]" >&2
  exit 2
fi
samples="$1/tests/kartograf_interop_samples"
work="${2:-$(mktemp -d "${TMPDIR:-/tmp}/kartograf-interop.XXXXXX")}"
python=/usr/bin/python3  # Open3D is installed for the system Python, not a pyenv one on PATH

build_hint="ninja -C $1 kartograf_interop_samples"
[ -x "$samples" ] || { echo "FAIL: $samples is not built ($build_hint)" >&2; exit 2; }
# A stale program would check an older reader or writer. (Not `ninja -n`: with CMake's
# CONFIGURE_DEPENDS globs a dry run always reports that CMake would run again.)
repo="$(cd "$(dirname "$0")/.." && pwd)"
newer=$(find "$repo/src/io" "$repo/include/kartograf/io" "$repo/tests/pcd_interop_samples.cpp" \
  -type f -newer "$samples" -print -quit)
[ -z "$newer" ] || { echo "FAIL: $samples is older than $newer ($build_hint)" >&2; exit 2; }
"$python" -c 'import open3d' 2>/dev/null || { echo "FAIL: $python cannot import open3d" >&2; exit 2; }
for tool in pcl_pcd2ply pcl_ply2pcd pcl_convert_pcd_ascii_binary pcl_fpfh_estimation; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool is missing (apt-get install pcl-tools)" >&2; exit 2; }
done

failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
ok() { echo "ok    $*"; }

rm -rf "$work/pcl" "$work/open3d"
mkdir -p "$work/pcl" "$work/open3d"
echo "== Kartograf writes the samples into $work"
KARTOGRAF_INTEROP_DIR="$work" "$samples" --gtest_filter=PcdInterop.WriteSamples --gtest_brief=1 \
  >"$work/write.log" 2>&1 || { cat "$work/write.log"; echo "FAIL: writing the samples" >&2; exit 1; }
cat "$work/expected.txt"

echo "== Open3D $("$python" -c 'import open3d; print(open3d.__version__)') reads them, then writes its own"
"$python" - "$work" <<'PY' || failures=$((failures + 1))
import os, sys
import numpy as np
import open3d as o3d

work = sys.argv[1]
bad = 0
for line in open(os.path.join(work, "expected.txt")):
    name, count, normals, colors, *rest = line.split()
    first = [float(v) for v in rest[:3]]
    rgb = [int(v) for v in rest[3:]]
    cloud = o3d.io.read_point_cloud(os.path.join(work, name))
    points = np.asarray(cloud.points)
    got_rgb = [int(round(c * 255)) for c in np.asarray(cloud.colors)[0]] if cloud.has_colors() else None
    print(f"{name}: {len(points)} points, has_normals={cloud.has_normals()}, "
          f"has_colors={cloud.has_colors()}, first point {points[0].tolist() if len(points) else None}, "
          f"first colour {got_rgb}")
    problems = []
    if len(points) != int(count): problems.append(f"{len(points)} points, expected {count}")
    if cloud.has_normals() != (normals == "1"): problems.append("has_normals differs")
    if cloud.has_colors() != (colors == "1"): problems.append("has_colors differs")
    if len(points) and np.abs(points[0] - first).max() > 1e-6: problems.append(f"first point, expected {first}")
    if got_rgb != rgb: problems.append(f"first colour, expected {rgb}")
    for p in problems: print(f"FAIL: Open3D, {name}: {p}")
    bad += len(problems)

# Open3D's own files from the unorganized sample, for Kartograf to read back.
cloud = o3d.io.read_point_cloud(os.path.join(work, "kartograf_unorganized_binary.pcd"))
out = os.path.join(work, "open3d")
for name, kw in [("ascii", dict(write_ascii=True)), ("binary", {}),
                 ("binary_compressed", dict(compressed=True))]:
    if not o3d.io.write_point_cloud(os.path.join(out, f"open3d_{name}.pcd"), cloud, **kw): bad += 1
for name, kw in [("binary", {}), ("ascii", dict(write_ascii=True))]:
    if not o3d.io.write_point_cloud(os.path.join(out, f"open3d_{name}.ply"), cloud, **kw): bad += 1
print("Open3D wrote:", " ".join(sorted(os.listdir(out))))
sys.exit(1 if bad else 0)
PY

echo "== PCL reads them (pcl_pcd2ply, pcl_ply2pcd) and writes its own"
# Runs a PCL tool; checks its exit code and that the output holds the expected number of points.
pcl_check() {
  local expected=$1 output=$2
  shift 2
  local log rc=0 count
  log=$("$@" 2>&1) || rc=$?
  if [ $rc -ne 0 ] || [ ! -s "$output" ]; then
    fail "$* exited with $rc"; echo "$log" | tail -3; return
  fi
  case "$output" in
    *.ply) count=$(sed -n 's/^element vertex \([0-9]*\).*/\1/p' "$output" | head -1) ;;
    *.pcd) count=$(sed -n 's/^POINTS \([0-9]*\).*/\1/p' "$output" | head -1) ;;
  esac
  if [ "$count" = "$expected" ]; then
    ok "$1 -> ${output#"$work"/}: exit 0, $count points"
  else
    fail "$* wrote $count points, expected $expected"
  fi
}
expected_count() { awk -v f="$1" '$1 == f { print $2 }' "$work/expected.txt"; }
for kind in unorganized organized; do
  for encoding in ascii binary binary_compressed; do
    file="kartograf_${kind}_${encoding}.pcd"
    pcl_check "$(expected_count "$file")" "$work/pcl/pcd2ply_${kind}_${encoding}.ply" \
      pcl_pcd2ply -format 1 "$work/$file" "$work/pcl/pcd2ply_${kind}_${encoding}.ply"
  done
  # PCL's PCD writer in each encoding (0 ascii, 1 binary, 2 binary_compressed; ascii with 9 digits).
  file="kartograf_${kind}_binary.pcd"
  for pair in 0:ascii 1:binary 2:binary_compressed; do
    pcl_check "$(expected_count "$file")" "$work/pcl/convert_${kind}_${pair#*:}.pcd" \
      pcl_convert_pcd_ascii_binary "$work/$file" "$work/pcl/convert_${kind}_${pair#*:}.pcd" \
      "${pair%%:*}" 9
  done
done
for encoding in binary_little_endian ascii; do
  file="kartograf_unorganized_${encoding}.ply"
  pcl_check "$(expected_count "$file")" "$work/pcl/ply2pcd_${encoding}.pcd" \
    pcl_ply2pcd -format 1 "$work/$file" "$work/pcl/ply2pcd_${encoding}.pcd"
done
# A PCL cloud with a COUNT 33 field (FPFH histograms) ahead of x y z.
pcl_check 500 "$work/pcl/fpfh.pcd" \
  pcl_fpfh_estimation "$work/kartograf_unorganized_binary.pcd" "$work/pcl/fpfh.pcd" -k 10
head -11 "$work/pcl/fpfh.pcd" | grep -E '^(FIELDS|COUNT|DATA)' | sed 's/^/      fpfh.pcd: /'

echo "== Kartograf reads what PCL and Open3D wrote"
if KARTOGRAF_INTEROP_DIR="$work" "$samples" --gtest_filter='PcdInterop.Reads*' \
  >"$work/read.log" 2>&1; then
  grep -E '^\[ +(OK|PASSED) ' "$work/read.log" | sed 's/^/      /'
else
  cat "$work/read.log"
  fail "Kartograf did not read back what PCL/Open3D wrote (see above)"
fi

if [ $failures -ne 0 ]; then
  echo "INTEROP CHECK FAILED: $failures mismatch(es); files in $work"
  exit 1
fi
echo "INTEROP CHECK PASSED (files in $work)"
