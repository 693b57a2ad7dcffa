#!/usr/bin/env bash
# The whole pipeline on many sequences at once, one table (issue 23's development benchmark; not a
# test): `kartograf map` on the CPU backend, one thread, on
#   survey-N   the demo's synthetic survey (`kartograf synth --survey --pitch 20 --seed N`)
#   tour-10    the seed-1 survey taken every 10th frame (~130 frames): large motion
#   tours      tour-10-N: every --seeds survey taken every 10th frame (the large-motion rules were
#              found on seeds 1-10's; seeds 11 and up are held out: --seeds "$(seq 11 37)")
#   7scenes    7scenes_redkitchen + 7scenes_redkitchen_300_599 as one 600-frame sequence
#   sun3d      sun3d_studyroom_fragment1
# and prints, per sequence: the odometry's and the SLAM's ATE, accepted loop closures, labelled
# views, the grid's class IoUs and the rooms' recall/precision where a floor plan is known, the
# odometry's compute time per frame and the run's wall time. "tuned" marks the sequences the
# defaults were tuned on (survey seed 1, 7-Scenes frames 0-299 within the 600).
#   bash scripts/map-bench.sh [--out DIR] [--seeds "1 2 ... 10"] [--sets "survey tour-10 tours 7scenes sun3d"]
#                             [--kartograf BIN] [--data DIR (../shared/data)] [--jobs N (1)]
#                             [--peers PYTHON] [--poses groundtruth]
# --poses groundtruth: every map from the sequences' ground-truth poses (`kartograf map --poses`):
# the semantic stages judged apart from the SLAM's error (the ATE columns are then zero).
# --peers: a python with open3d, opencv-contrib-python-headless and scipy (a venv); then the
# odometry of Kartograf and of the peers (../shared/tools/peers/odometry_peers.py) runs on the
# real sequences one after the other, alone on the machine, and a second table gives median
# ms/frame and ATE of each.
# Synthetic data are written once under DIR/data and reused; each map run goes to DIR/runs/NAME.
set -euo pipefail
cd "$(dirname "$0")/.."
out=build/map-bench seeds="1 2 3 4 5 6 7 8 9 10" sets="survey tour-10 7scenes sun3d"
kartograf=build/apps/kartograf/kartograf data=../shared/data jobs=1 peers_python="" poses=""
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift ;;
    --seeds) seeds="$2"; shift ;;
    --sets) sets="$2"; shift ;;
    --kartograf) kartograf="$2"; shift ;;
    --data) data="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    --peers) peers_python="$2"; shift ;;
    --poses) poses="$2"; shift ;;
    *) echo "map-bench.sh: unknown argument '$1' (see the comment at the top)" >&2; exit 2 ;;
  esac
  shift
done
[ -x "$kartograf" ] || { echo "map-bench.sh: no kartograf binary at $kartograf (--kartograf)" >&2; exit 2; }
mkdir -p "$out/data" "$out/runs"
export KARTOGRAF_CPU_THREADS=1 OMP_NUM_THREADS=1

synth() {  # folder, synth arguments...
  local folder="$1"; shift
  [ -f "$folder/world.json" ] && return
  echo "map-bench: writing $folder" >&2
  "$kartograf" synth --out "$folder" --force "$@" >/dev/null
}

# The two 7-Scenes folders are frames 0-299 and 300-599 of one recording: one folder of links.
seven_scenes_600() {
  local folder="$out/data/7scenes_0_599"
  [ -d "$folder/frames" ] && return
  mkdir -p "$folder/frames"
  local first; first="$(cd "$data/7scenes_redkitchen" && pwd)"
  ln -sf "$first/camera-intrinsics.txt" "$first/gravity-direction.txt" "$folder/"
  for part in 7scenes_redkitchen 7scenes_redkitchen_300_599; do
    for file in "$(cd "$data/$part/frames" && pwd)"/frame-*; do ln -sf "$file" "$folder/frames/"; done
  done
}

map_one() {  # name, sequence, map arguments...
  local name="$1" sequence="$2"; shift 2
  echo "map-bench: mapping $name" >&2
  "$kartograf" map "$sequence" --out "$out/runs/$name" --force --no-progress --backend cpu \
    ${poses:+--poses "$poses"} "$@" \
    >"$out/runs/$name.log" 2>&1 || echo "map-bench: $name failed (see $out/runs/$name.log)" >&2
}

# With --jobs N, up to N maps run at once (each on one thread; timings then share the cores).
run_map() {
  if [ "$jobs" -le 1 ]; then map_one "$@"; return; fi
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
  map_one "$@" &
}

names=()
for set in $sets; do
  case "$set" in
    survey)
      for seed in $seeds; do
        synth "$out/data/survey-$seed" --survey --pitch 20 --seed "$seed"
        run_map "survey-$seed" "$out/data/survey-$seed"
        names+=("survey-$seed")
      done ;;
    tour-10)
      synth "$out/data/survey-1" --survey --pitch 20 --seed 1
      run_map tour-10 "$out/data/survey-1" --step 10
      names+=(tour-10) ;;
    tours)
      for seed in $seeds; do
        synth "$out/data/survey-$seed" --survey --pitch 20 --seed "$seed"
        run_map "tour-10-$seed" "$out/data/survey-$seed" --step 10
        names+=("tour-10-$seed")
      done ;;
    7scenes)
      seven_scenes_600
      run_map 7scenes "$out/data/7scenes_0_599"
      names+=(7scenes) ;;
    sun3d)
      run_map sun3d "$data/sun3d_studyroom_fragment1"
      names+=(sun3d) ;;
    *) echo "map-bench.sh: unknown set '$set'" >&2; exit 2 ;;
  esac
done
wait
python3 scripts/map-bench-table.py "$out/runs" "${names[@]}" | tee "$out/table.md"

# Odometry beside the peers, one sequence at a time (timings need the machine to themselves).
peer_odometry() {  # name, sequence
  local name="$1" sequence="$2" dir="$out/peers/$1"
  mkdir -p "$dir"
  "$kartograf" odometry "$sequence" --backend cpu --no-progress --force \
    --out "$dir/kartograf.txt" --stats "$dir/kartograf.json" >/dev/null 2>&1
  python3 - "$dir/kartograf.json" "$name" <<'PY'
import json, statistics, sys
j = json.load(open(sys.argv[1]))
ms = statistics.median(f["seconds"] for f in j["per_frame"][1:]) * 1000
print("| %s | kartograf | %.1f | %.2f |" % (sys.argv[2], ms, 100 * j["ate_rmse_m"]))
PY
  # A peer that fails (Open3D's hybrid odometry refuses SUN3D's one-channel colour) stops the
  # script after the methods it finished: their rows stay, and the failure is a row of its own.
  local rows status=0
  rows="$("$peers_python" "$data/../tools/peers/odometry_peers.py" "$sequence" "$dir" \
    2>"$dir/peers.log")" || status=$?
  awk -v n="$name" '/ms\/frame/ {printf "| %s | %s | %.1f | %.2f |\n", n, $1, $5, 100 * $8}' \
    <<<"$rows"
  [ "$status" -eq 0 ] || echo "| $name | (a peer failed, exit $status: $dir/peers.log) | - | - |"
}
if [ -n "$peers_python" ]; then
  {
    echo
    echo "| sequence | odometry | median ms/frame | ATE cm |"
    echo "|---|---|---:|---:|"
    for set in $sets; do
      case "$set" in
        7scenes) peer_odometry 7scenes "$out/data/7scenes_0_599" ;;
        sun3d) peer_odometry sun3d "$data/sun3d_studyroom_fragment1" ;;
      esac
    done
  } | tee -a "$out/table.md"
fi
