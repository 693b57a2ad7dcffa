# Issue 20, sequence input: the CLI reads the real 7-Scenes 300-599 and SUN3D folders with no
# options and prints an ATE; TUM cameras (presets, the folder's name, numbers, files), depth
# scale and frame range are used, printed and recorded; each input defect's repro is a clear
# error (or, with --skip-bad-frames, frames left out and counted). Test sequences are built in
# the build folder from the real data by symbolic links, never in the repository. The tests
# source cli_fails_with.sh, which defines `fails_with [--regex] LOG PATTERN... -- COMMAND...`.
set(fails_with_helper ${CMAKE_CURRENT_SOURCE_DIR}/cli_fails_with.sh)

# slam (100 frames) and map (no options at all) on frames 300-599: an ATE printed, the camera
# (camera-intrinsics.txt) and depth scale printed and recorded.
add_test(NAME Cli.input_slam_on_7scenes_frames_300_to_599
  COMMAND sh -c [=[
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" slam "$2/7scenes_redkitchen_300_599" --frames 100 --out "$1/slam" > "$1/slam.log" 2> "$1/slam.err" || { cat "$1/slam.log" "$1/slam.err"; exit 1; }
cat "$1/slam.log"
grep -q "^  slam_ate_rmse_m [0-9]" "$1/slam.log" || { echo "FAIL: no ATE"; exit 1; }
grep -q "input: 100 frames; camera fx 585 fy 585 cx 320 cy 240 (640x480, file '.*camera-intrinsics.txt'); depth 1000 units per metre" "$1/slam.err" || { cat "$1/slam.err"; echo "FAIL: input line"; exit 1; }
grep -q '"depth_units_per_metre": 1000' "$1/slam/stats.json" && grep -q '"fx": 585' "$1/slam/stats.json" || { echo "FAIL: stats.json input"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-7scenes-slam ${KARTOGRAF_DATA_DIR})
# With --features the statistics count loop candidates by appearance and frames seeded by features.
add_test(NAME Cli.input_slam_with_features_on_7scenes
  COMMAND sh -c [=[
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" slam "$2/7scenes_redkitchen" --frames 150 --features --no-map --out "$1/slam" > "$1/slam.log" 2> "$1/slam.err" || { cat "$1/slam.log" "$1/slam.err"; exit 1; }
grep -q "^  slam_ate_rmse_m 0\.0[0-4]" "$1/slam.log" || { cat "$1/slam.log"; echo "FAIL: ATE"; exit 1; }
grep -q '"appearance_candidates": [0-9]' "$1/slam/stats.json" || { echo "FAIL: no appearance_candidates"; exit 1; }
grep -q '"from_features": [0-9]' "$1/slam/stats.json" || { echo "FAIL: no from_features count"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-7scenes-slam-features ${KARTOGRAF_DATA_DIR})
add_test(NAME Cli.input_map_on_7scenes_frames_300_to_599
  COMMAND sh -c [=[
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" map "$2/7scenes_redkitchen_300_599" --out "$1/map" > "$1/map.log" 2> "$1/map.err" || { cat "$1/map.log" "$1/map.err"; exit 1; }
cat "$1/map.log"
grep -q "^  ate_rmse_m [0-9]" "$1/map.log" || { echo "FAIL: no ATE"; exit 1; }
grep -q "(7scenes)" "$1/map.log" && grep -q "300 frames" "$1/map.log" || { echo "FAIL: frames"; exit 1; }
grep -q '"depth_units_per_metre": 1000' "$1/map/report.json" && grep -q '"fx": 585' "$1/map/report.json" || { echo "FAIL: report.json input"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-7scenes-map ${KARTOGRAF_DATA_DIR})
# SUN3D (3DMatch layout: frame-000935.color.png, its own camera-intrinsics.txt): no options.
add_test(NAME Cli.input_slam_and_map_on_sun3d
  COMMAND sh -c [=[
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" slam "$2/sun3d_studyroom_fragment1" --out "$1/slam" > "$1/slam.log" 2> "$1/slam.err" || { cat "$1/slam.log" "$1/slam.err"; exit 1; }
cat "$1/slam.log"
grep -q "^  slam_ate_rmse_m [0-9]" "$1/slam.log" || { echo "FAIL: no slam ATE"; exit 1; }
grep -q "input: 50 frames; camera fx 570.342 fy 570.342 cx 320 cy 240" "$1/slam.err" || { cat "$1/slam.err"; echo "FAIL: input line"; exit 1; }
"$0" map "$2/sun3d_studyroom_fragment1" --out "$1/map" > "$1/map.log" 2> "$1/map.err" || { cat "$1/map.log" "$1/map.err"; exit 1; }
cat "$1/map.log"
grep -q "^  ate_rmse_m [0-9]" "$1/map.log" || { echo "FAIL: no map ATE"; exit 1; }
grep -q '"fx": 570.342205' "$1/map/report.json" || { echo "FAIL: report.json camera"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-sun3d ${KARTOGRAF_DATA_DIR})
# map --poses: the map from a known trajectory (the sequence's ground truth, then the trajectory
# that run wrote, matched by timestamp): nothing estimated, the ATE zero; a trajectory that lacks
# the frames and a missing file are errors naming the input.
add_test(NAME Cli.input_map_with_known_poses
  COMMAND sh -c [=[
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" map "$2/sun3d_studyroom_fragment1" --poses groundtruth --out "$1/truth" > "$1/truth.log" 2> "$1/truth.err" || { cat "$1/truth.log" "$1/truth.err"; exit 1; }
grep -q "^  ate_rmse_m 0.0000 " "$1/truth.log" || { cat "$1/truth.log"; echo "FAIL: ATE with ground-truth poses"; exit 1; }
grep -q '"poses_given": true' "$1/truth/report.json" || { echo "FAIL: poses_given"; exit 1; }
"$0" map "$2/sun3d_studyroom_fragment1" --poses "$1/truth/trajectory.txt" --out "$1/file" > "$1/file.log" 2> "$1/file.err" || { cat "$1/file.log" "$1/file.err"; exit 1; }
grep -q "^  ate_rmse_m 0.0000 " "$1/file.log" || { cat "$1/file.log"; echo "FAIL: ATE with the trajectory file"; exit 1; }
head -20 "$1/truth/trajectory.txt" > "$1/short.txt"
"$0" map "$2/sun3d_studyroom_fragment1" --poses "$1/short.txt" --out "$1/short" > "$1/short.log" 2>&1 && { echo "FAIL: a short trajectory was accepted"; exit 1; }
grep -q "short.txt' has no pose within 20 ms of frame" "$1/short.log" || { cat "$1/short.log"; echo "FAIL: message"; exit 1; }
test ! -e "$1/short/report.json" || { echo "FAIL: partial output"; exit 1; }
"$0" map "$2/sun3d_studyroom_fragment1" --poses "$1/none.txt" --out "$1/none" > "$1/none.log" 2>&1 && { echo "FAIL: a missing file was accepted"; exit 1; }
grep -q "none.txt" "$1/none.log" || { cat "$1/none.log"; echo "FAIL: message"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-map-known-poses ${KARTOGRAF_DATA_DIR})
# fuse: the SUN3D fragment fused at its ground-truth poses into a coloured mesh with a summary
# (and, with --floor-z, the height band's occupancy and ESDF);
# a volume too small for the frames is an error naming max_blocks that leaves no output, and a
# trajectory without the frames an error naming the frame.
add_test(NAME Cli.fuse_with_known_poses
  COMMAND sh -c [=[
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" fuse "$2/sun3d_studyroom_fragment1" --poses groundtruth --voxel 0.02 --floor-z -1.2 --out "$1/mesh" > "$1/mesh.log" 2> "$1/mesh.err" || { cat "$1/mesh.log" "$1/mesh.err"; exit 1; }
cat "$1/mesh.log"
grep -q "^fuse: 50 frames, [1-9][0-9]* blocks of 0.020 m voxels, mesh [1-9][0-9]* vertices [1-9][0-9]* triangles" "$1/mesh.log" || { echo "FAIL: summary line"; exit 1; }
head -c 400 "$1/mesh/mesh.ply" | grep -a -q "^element face [1-9]" || { echo "FAIL: no faces in mesh.ply"; exit 1; }
head -c 400 "$1/mesh/mesh.ply" | grep -a -q "^property uchar red" || { echo "FAIL: no colours in mesh.ply"; exit 1; }
grep -q '"frames": 50' "$1/mesh/fuse.json" || { cat "$1/mesh/fuse.json"; echo "FAIL: fuse.json"; exit 1; }
grep -q "^image: occupancy.pgm" "$1/mesh/occupancy.yaml" && test -s "$1/mesh/occupancy.pgm" && test -s "$1/mesh/esdf.png" || { ls "$1/mesh"; echo "FAIL: --floor-z maps"; exit 1; }
"$0" fuse "$2/sun3d_studyroom_fragment1" --poses groundtruth --max-blocks 10 --out "$1/small" > "$1/small.log" 2>&1 && { echo "FAIL: a full volume was accepted"; exit 1; }
grep -q "volume is full.*max_blocks" "$1/small.log" || { cat "$1/small.log"; echo "FAIL: message"; exit 1; }
test ! -e "$1/small/mesh.ply" || { echo "FAIL: partial output"; exit 1; }
printf '0 0 0 0 0 0 0 1\n' > "$1/one.txt"
"$0" fuse "$2/sun3d_studyroom_fragment1" --poses "$1/one.txt" --out "$1/one" > "$1/one.log" 2>&1 && { echo "FAIL: a short trajectory was accepted"; exit 1; }
grep -q "fuse --poses: '.*one.txt' has no pose within 20 ms of frame 1" "$1/one.log" || { cat "$1/one.log"; echo "FAIL: message"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-fuse ${KARTOGRAF_DATA_DIR})
# odometry, slam and map --tracking model: the frame-to-model line and an ATE; slam's stats and
# map's report record the model's tracking.
add_test(NAME Cli.odometry_tracking_model
  COMMAND sh -c [=[
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" odometry "$2/sun3d_studyroom_fragment1" --tracking model --out "$1/model.txt" > "$1/model.log" 2> "$1/model.err" || { cat "$1/model.log" "$1/model.err"; exit 1; }
cat "$1/model.log"
grep -q "^  model tracking: the model's pose kept on [0-9]* of 50 frames" "$1/model.log" || { echo "FAIL: model line"; exit 1; }
grep -q "^  ate_rmse_m [0-9]" "$1/model.log" || { echo "FAIL: no ATE"; exit 1; }
# The planar odometry's pyramid has one ICP level: the tracker builds its own.
"$0" odometry "$2/sun3d_studyroom_fragment1" --tracking model --method planar --frames 8 --out "$1/planar.txt" > "$1/planar.log" 2>&1 || { cat "$1/planar.log"; echo "FAIL: planar"; exit 1; }
grep -q "^  model tracking: the model's pose kept on [0-9]* of 8 frames" "$1/planar.log" || { cat "$1/planar.log"; echo "FAIL: planar model line"; exit 1; }
"$0" slam "$2/sun3d_studyroom_fragment1" --tracking model --no-map --out "$1/slam" > "$1/slam.log" 2>&1 || { cat "$1/slam.log"; echo "FAIL: slam"; exit 1; }
cat "$1/slam.log"
grep -q "^  model tracking: the model's pose kept on [0-9]* of 50 frames" "$1/slam.log" || { echo "FAIL: slam model line"; exit 1; }
grep -q "^  slam_ate_rmse_m [0-9]" "$1/slam.log" || { echo "FAIL: no SLAM ATE"; exit 1; }
grep -q '"kind": "model"' "$1/slam/stats.json" || { cat "$1/slam/stats.json"; echo "FAIL: stats"; exit 1; }
"$0" map "$2/sun3d_studyroom_fragment1" --tracking model --out "$1/map" > "$1/map.log" 2>&1 || { cat "$1/map.log"; echo "FAIL: map"; exit 1; }
grep -q "^  model tracking: the model's pose kept on [0-9]* of 50 frames" "$1/map.log" || { cat "$1/map.log"; echo "FAIL: map model line"; exit 1; }
grep -q '"tracking": "model"' "$1/map/report.json" || { echo "FAIL: map report"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-odometry-model ${KARTOGRAF_DATA_DIR})
set_tests_properties(Cli.input_slam_on_7scenes_frames_300_to_599 Cli.input_map_on_7scenes_frames_300_to_599
  Cli.input_slam_and_map_on_sun3d Cli.input_slam_with_features_on_7scenes Cli.input_map_with_known_poses
  Cli.fuse_with_known_poses Cli.odometry_tracking_model PROPERTIES TIMEOUT 600 ENVIRONMENT "${KARTOGRAF_TEST_ENV}")

# A TUM folder (kartograf synth output without world.json and camera_intrinsics.json): the
# default camera with a warning naming --camera; --camera tum-fr3 (fx 535.4, fy 539.2) printed and
# recorded; a folder named ...freiburg2... gets tum-fr2; --camera as numbers and as a file;
# --depth-scale; --first/--frames/--step; --frames -1 and an unknown camera are errors.
add_test(NAME Cli.input_tum_cameras_depth_scale_and_frame_range
  COMMAND sh -c [=[
. "$2"
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" synth --out "$1/synth" --frames 4 --trajectory handheld > /dev/null 2>&1 || { echo "FAIL: synth"; exit 1; }
cp -r "$1/synth" "$1/tum" && rm "$1/tum/world.json" "$1/tum/camera_intrinsics.json" || exit 1
W=$1
run() { name=$1; shift; "$0" odometry "$@" --out "$W/$name.txt" --stats "$W/$name.json" --no-progress > "$W/$name.log" 2> "$W/$name.err" || { cat "$W/$name.log" "$W/$name.err"; echo "FAIL: $name"; exit 1; }; }
run default "$1/tum"
grep -q "warning: .*no camera file: assuming the kinect camera.*--camera" "$1/default.err" && grep -q "fx 525 fy 525" "$1/default.err" || { cat "$1/default.err"; echo "FAIL: default camera warning"; exit 1; }
run fr3 "$1/tum" --camera tum-fr3
grep -q "camera fx 535.4 fy 539.2 cx 320.1 cy 247.6 (640x480, preset tum-fr3); depth 5000 units per metre" "$1/fr3.err" || { cat "$1/fr3.err"; echo "FAIL: tum-fr3 line"; exit 1; }
grep -q "fx 535.4 fy 539.2" "$1/fr3.log" && grep -q '"fx": 535.4' "$1/fr3.json" && grep -q '"fy": 539.2' "$1/fr3.json" || { echo "FAIL: tum-fr3 recorded"; exit 1; }
grep -q warning "$1/fr3.err" && { echo "FAIL: warning with --camera"; exit 1; }
cp -r "$1/tum" "$1/rgbd_dataset_freiburg2_test" || exit 1
run fr2 "$1/rgbd_dataset_freiburg2_test"
grep -q "fx 520.9 fy 521 cx 325.1 cy 249.7 (640x480, preset tum-fr2, from the folder's name)" "$1/fr2.err" || { cat "$1/fr2.err"; echo "FAIL: tum-fr2 by name"; exit 1; }
run numbers "$1/tum" --camera 500,501,320,240
grep -q "fx 500 fy 501 cx 320 cy 240 (640x480, --camera 500,501,320,240)" "$1/numbers.err" || { cat "$1/numbers.err"; echo "FAIL: numbers"; exit 1; }
printf '600 0 321\n0 601 241\n0 0 1\n' > "$1/K.txt"
run file "$1/tum" --camera "$1/K.txt"
grep -q "fx 600 fy 601 cx 321 cy 241 (640x480, file '.*K.txt')" "$1/file.err" || { cat "$1/file.err"; echo "FAIL: file"; exit 1; }
run scale "$1/tum" --depth-scale 5000 --first 1 --frames 2
grep -q "depth 5000 units per metre (--depth-scale)" "$1/scale.err" && grep -q "(tum, 2 frames)" "$1/scale.log" || { cat "$1/scale.err" "$1/scale.log"; echo "FAIL: depth scale / range"; exit 1; }
grep -q '"depth_scale_source": "--depth-scale"' "$1/scale.json" || { echo "FAIL: depth scale recorded"; exit 1; }
run step "$1/tum" --step 2
grep -q "(tum, 2 frames)" "$1/step.log" || { echo "FAIL: --step"; exit 1; }
for bad in "--frames -1" "--first -2" "--step 0" "--depth-scale 0"; do
  fails_with "$1/bad.err" "${bad%% *}" -- "$0" odometry "$1/tum" $bad --out "$1/bad.txt" || exit 1
done
fails_with --regex "$1/bad.err" "tum-fr9.*tum-fr1|tum-fr2|tum-fr3|kinect|7scenes" -- "$0" slam "$1/tum" --camera tum-fr9 --out "$1/bad" || exit 1
exit 0
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-tum ${fails_with_helper})

# Defect 1: colour frames of 16x12 in a 640x480 7-Scenes copy: an error naming the colour file and
# both sizes (no heap over-read, no map); with --skip-bad-frames those frames are left out.
# Defect 12: a 320x240 depth frame names the file and both sizes; a truncated JPEG is an error.
add_test(NAME Cli.input_colour_and_depth_sizes_and_truncated_images
  COMMAND sh -c [=[
DATA=$2; . "$3"; . "$4"
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" synth --out "$1/tiny" --frames 1 --width 16 --height 12 > /dev/null 2>&1 || exit 1
"$0" synth --out "$1/qvga" --frames 1 --width 320 --height 240 > /dev/null 2>&1 || exit 1
small=$(ls "$1"/tiny/rgb/*.png | head -1); qvga=$(ls "$1"/qvga/depth/*.png | head -1)
kitchen_copy "$1/colour" 0 9
for n in 2 3 4 5 6; do f="$1/colour/frame-00000$n.color.jpg"; rm "$f" && cp "$small" "$f"; done
fails_with --regex "$1/err" "colour image '.*frame-000002.color.jpg' is 16x12, its depth image '.*frame-000002.depth.png' is 640x480" \
  -- "$0" slam "$1/colour" --frames 7 --out "$1/out" || exit 1
test -e "$1/out/map.ply" && { echo "FAIL: a map was written"; exit 1; }
"$0" slam "$1/colour" --skip-bad-frames --out "$1/skip" > "$1/skip.log" 2> "$1/skip.err" || { cat "$1/skip.err"; echo "FAIL: --skip-bad-frames"; exit 1; }
test "$(grep -c 'left out: colour image' "$1/skip.err")" = 5 && grep -q "(5 bad frames left out)" "$1/skip.err" || { cat "$1/skip.err"; echo "FAIL: skipped frames reported"; exit 1; }
grep -q '"frames_skipped": 5' "$1/skip/stats.json" && grep -q "(7scenes, 5 frames)" "$1/skip.log" || { echo "FAIL: skipped frames counted"; exit 1; }
kitchen_copy "$1/depth" 0 5
rm "$1/depth/frame-000003.depth.png" && cp "$qvga" "$1/depth/frame-000003.depth.png"
fails_with --regex "$1/err" "depth image '.*frame-000003.depth.png' is 320x240, the sequence's frames are 640x480" \
  -- "$0" slam "$1/depth" --out "$1/out2" || exit 1
kitchen_copy "$1/cut" 0 5
f="$1/cut/frame-000002.color.jpg"; head -c 20000 "$DATA/7scenes_redkitchen/frames/frame-000002.color.jpg" > "$1/part" && rm "$f" && mv "$1/part" "$f"
fails_with --regex "$1/err" "frame-000002.color.jpg'*: truncated JPEG" -- "$0" odometry "$1/cut" --out "$1/cut.txt" || exit 1
exit 0
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-sizes ${KARTOGRAF_DATA_DIR}
  ${CMAKE_CURRENT_SOURCE_DIR}/kitchen_copy.sh ${fails_with_helper})

# Defect 5: a missing depth file in the numbered run is an error naming it (not 15 of 30 frames
# and exit 0); --skip-bad-frames leaves it out and counts it. Defect 6: a pose that is not a
# rotation names its file; a semantic --trajectory with fewer poses than frames names both counts.
# Defect 11: --frames -1 is an error on every sequence command. planes takes --camera and the
# range too. A scan whose up cannot be found is an error naming it.
add_test(NAME Cli.input_missing_frames_bad_poses_and_short_trajectories
  COMMAND sh -c [=[
DATA=$2; . "$3"; . "$4"
rm -rf "$1" && mkdir -p "$1" || exit 1
kitchen_copy "$1/seq" 0 29
rm "$1/seq/frame-000015.depth.png"
fails_with "$1/err" "frame-000015.depth.png': no such file (frame 15 of the sequence; --skip-bad-frames" \
  -- "$0" odometry "$1/seq" --out "$1/a.txt" || exit 1
"$0" odometry "$1/seq" --skip-bad-frames --out "$1/b.txt" --stats "$1/b.json" > "$1/b.log" 2> "$1/b.err" || { cat "$1/b.err"; exit 1; }
grep -q "warning: frame 15 left out: '.*frame-000015.depth.png': no such file" "$1/b.err" && test "$(grep -vc '^#' "$1/b.txt")" = 29 || { cat "$1/b.err"; echo "FAIL: skip"; exit 1; }
grep -q '"frames_skipped": 1' "$1/b.json" || { echo "FAIL: skipped frame not counted"; exit 1; }
kitchen_copy "$1/poses" 0 5
rm "$1/poses/frame-000002.pose.txt" && printf '0 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 1\n' > "$1/poses/frame-000002.pose.txt"
fails_with "$1/err" "frame-000002.pose.txt': the pose's 3x3 block is not a rotation" -- "$0" slam "$1/poses" --out "$1/out" || exit 1
kitchen_copy "$1/short" 0 5
printf '0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n' > "$1/short.txt"
fails_with --regex "$1/err" "short.txt' holds 3 poses, the sequence '.*short' has 6 frames" \
  -- "$0" semantic "$1/short" --trajectory "$1/short.txt" --out "$1/sem" || exit 1
printf '0 0 0 0 0 0 0 0\n' > "$1/zero.txt"
fails_with "$1/err" "zero.txt' line 1: quaternion norm" -- "$0" semantic "$1/short" --trajectory "$1/zero.txt" --out "$1/sem" || exit 1
"$0" planes "$1/short" --first 2 --frames 1 --camera kinect --out "$1/planes" > /dev/null 2> "$1/planes.err" || { cat "$1/planes.err"; echo "FAIL: planes --camera"; exit 1; }
grep -q '"fx": 525' "$1/planes/summary.json" && test -d "$1/planes/000002" || { cat "$1/planes/summary.json"; echo "FAIL: planes camera / range"; exit 1; }
for command in odometry slam map semantic planes; do
  fails_with "$1/err" "--frames" -- "$0" $command "$1/short" --frames -1 --out "$1/x" || exit 1
done
# A scan in which no plane tells which way is up (a table top seen steeply from above) names itself.
fails_with "$1/err" "table_scene_mug_stereo_textured.pcd': estimate_gravity: no plane of at least 0.3 m^2 to tell which way is up" \
  -- "$0" semantic "$2/pcl_clouds/table_scene_mug_stereo_textured.pcd" --out "$1/mug" || exit 1
test ! -e "$1/mug" || { echo "FAIL: semantic left an output folder behind"; exit 1; }
exit 0
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-missing ${KARTOGRAF_DATA_DIR}
  ${CMAKE_CURRENT_SOURCE_DIR}/kitchen_copy.sh ${fails_with_helper})

# Defect 8: depth that is all zero, or read at a scale that puts it all beyond range (metres
# stored as millimetres) or most of it (a scale 10 times too small), is an error before the run
# naming the depth file, the scale and the values, suggesting --depth-scale; for odometry, slam
# and map (not a gravity message).
add_test(NAME Cli.input_unusable_depth_is_named_before_the_run
  COMMAND sh -c [=[
DATA=$2; . "$3"; . "$4"
rm -rf "$1" && mkdir -p "$1" || exit 1
kitchen_copy "$1/zero" 0 5
python3 - "$1/zero.png" <<'PY' || exit 1
import struct, sys, zlib
w, h = 640, 480
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
raw = b"".join(b"\0" + b"\0\0" * w for _ in range(h))
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 0, 0, 0, 0))
open(sys.argv[1], "wb").write(png + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
PY
for n in 0 1 2 3 4 5; do f="$1/zero/frame-00000$n.depth.png"; rm "$f" && cp "$1/zero.png" "$f"; done
for command in odometry slam map planes semantic; do
  fails_with --regex "$1/err" "depth image '.*frame-000000.depth.png' (and the next 4 frames): no pixel within the usable depth range.*1000 units per metre (every depth value is 0.*--depth-scale" \
    -- "$0" $command "$1/zero" --out "$1/out-$command" || exit 1
  [ ! -e "$1/out-$command" ] || { echo "FAIL: $command left $1/out-$command"; exit 1; }
done
kitchen_copy "$1/far" 0 5
fails_with --regex "$1/err" "frame-000000.depth.png'.*at a depth scale of 1 units per metre (values [0-9]* to [0-9]*, i.e. .* m).*--depth-scale" \
  -- "$0" slam "$1/far" --depth-scale 1 --out "$1/out" || exit 1
for command in odometry planes semantic; do
  fails_with --regex "$1/err" "frame-000000.depth.png'.*: only [0-9]* % of the measured pixels within the usable depth range, 0.1 to 10 m at a depth scale of 100 units per metre (values .*, median .* m).*--depth-scale" \
    -- "$0" $command "$1/far" --depth-scale 100 --out "$1/out100-$command" || exit 1
done
exit 0
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-depth ${KARTOGRAF_DATA_DIR}
  ${CMAKE_CURRENT_SOURCE_DIR}/kitchen_copy.sh ${fails_with_helper})
# A depth camera without colour: planes of a depth PNG alone or an organized PCD without colour
# in the cells mode (fy = fx when only --fx is given); the regions mode, which grows colour
# regions, refuses them naming the cells mode. A depth PNG read at the wrong scale is refused.
add_test(NAME Cli.input_planes_from_depth_alone
  COMMAND sh -c [=[
DATA=$2; . "$3"
rm -rf "$1" && mkdir -p "$1" || exit 1
depth="$DATA/7scenes_redkitchen/frames/frame-000000.depth.png"
scan="$DATA/dlut_laser_scans/A601.pcd"
fails_with "$1/err" "is a depth image: give its colour image with --color" "--mode cells for depth alone" \
  -- "$0" planes "$depth" --fx 585 --out "$1/regions" || exit 1
fails_with "$1/err" "A601.pcd' has no colour (rgb/rgba field)" "--mode cells works on depth alone" \
  -- "$0" planes "$scan" --out "$1/regions" || exit 1
test ! -e "$1/regions" || { echo "FAIL: a refused run left its folder"; exit 1; }
"$0" planes "$depth" --fx 585 --mode cells --out "$1/depth" > "$1/depth.log" 2>&1 || { cat "$1/depth.log"; echo "FAIL: cells mode on depth alone"; exit 1; }
grep -q '"fy": 585' "$1/depth/planes.json" || { echo "FAIL: fy is not fx"; exit 1; }
planes=$(grep -c '"normal"' "$1/depth/planes.json")
[ "$planes" -ge 20 ] && test -s "$1/depth/segmentation.png" && test -s "$1/depth/labels.png" || { cat "$1/depth.log"; echo "FAIL: $planes planes from depth alone"; exit 1; }
"$0" planes "$scan" --mode cells --out "$1/scan" > "$1/scan.log" 2>&1 || { cat "$1/scan.log"; echo "FAIL: cells mode on a colourless scan"; exit 1; }
grep -q "A601.pcd: [1-9][0-9]* planes" "$1/scan.log" || { cat "$1/scan.log"; echo "FAIL: no plane in the scan"; exit 1; }
# A TUM depth image (5000 units per metre) read as millimetres puts most of it beyond range.
tum="$DATA/open3d_testdata/RGBD/other_formats/TUM_depth.png"
fails_with "$1/err" "TUM_depth.png': only" "at a depth scale of 1000 units per metre" "--depth-scale" \
  -- "$0" planes "$tum" --mode cells --camera tum-fr1 --out "$1/tum" || exit 1
"$0" planes "$tum" --mode cells --camera tum-fr1 --depth-scale 5000 --out "$1/tum" > "$1/tum.log" 2>&1 || { cat "$1/tum.log"; echo "FAIL: TUM depth at its scale"; exit 1; }
exit 0
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-depth-alone ${KARTOGRAF_DATA_DIR}
  ${fails_with_helper})

# A depth camera's sequence (the kitchen's frames 0-29 without their colour images): odometry,
# slam without features, fuse, map (without features, said; a mesh without colour), semantic (the
# same labels as with colour: it reads the depth alone) and planes --mode cells run on depth
# alone; what needs colour (--features, --method color and planar, the regions mode) is refused
# before any work, naming the folder.
add_test(NAME Cli.input_sequence_from_depth_alone
  COMMAND sh -c [=[
DATA=$2; . "$3"; . "$4"
rm -rf "$1" && mkdir -p "$1" || exit 1
kitchen_depth_alone "$1/seq" 0 29
"$0" odometry "$1/seq" --out "$1/odometry.txt" > "$1/odometry.log" 2> "$1/odometry.err" || { cat "$1/odometry.err"; echo "FAIL: odometry on depth alone"; exit 1; }
grep -q "has no colour images: depth alone" "$1/odometry.err" || { cat "$1/odometry.err"; echo "FAIL: depth alone not said"; exit 1; }
ate=$(sed -n 's/^  ate_rmse_m \([0-9.]*\).*/\1/p' "$1/odometry.log")
awk -v a="$ate" 'BEGIN { exit !(a != "" && a < 0.05) }' || { cat "$1/odometry.log"; echo "FAIL: ATE '$ate'"; exit 1; }
"$0" slam "$1/seq" --no-map --out "$1/slam" --no-progress > /dev/null 2> "$1/slam.err" || { cat "$1/slam.err"; echo "FAIL: slam on depth alone"; exit 1; }
"$0" fuse "$1/seq" --poses groundtruth --out "$1/fuse" --no-progress > /dev/null 2> "$1/fuse.err" && test -s "$1/fuse/mesh.ply" || { cat "$1/fuse.err"; echo "FAIL: fuse on depth alone"; exit 1; }
"$0" planes "$1/seq" --mode cells --frames 2 --out "$1/planes" --no-progress > /dev/null 2> "$1/planes.err" && test -s "$1/planes/000001/labels.png" || { cat "$1/planes.err"; echo "FAIL: planes --mode cells on depth alone"; exit 1; }
fails_with "$1/err" "--features (ORB on the colour images) needs colour images" "seq' has none" -- "$0" slam "$1/seq" --features --out "$1/x" || exit 1
fails_with "$1/err" "--method color" "needs colour images" -- "$0" odometry "$1/seq" --method color --out "$1/x.txt" || exit 1
fails_with "$1/err" "--method planar" "needs colour images" -- "$0" slam "$1/seq" --method planar --out "$1/x" || exit 1
fails_with "$1/err" "the regions mode" "--mode cells works on depth alone" -- "$0" planes "$1/seq" --out "$1/x" || exit 1
test ! -e "$1/x" && test ! -e "$1/x.txt" || { echo "FAIL: a refused run left output"; exit 1; }
"$0" map "$1/seq" --out "$1/map" --no-progress > "$1/map.log" 2> "$1/map.err" || { cat "$1/map.err"; echo "FAIL: map on depth alone"; exit 1; }
grep -q "no colour images: no local image features" "$1/map.err" || { cat "$1/map.err"; echo "FAIL: features not said"; exit 1; }
grep -q '"colour": false' "$1/map/report.json" && grep -q '"features": false' "$1/map/report.json" || { echo "FAIL: report.json"; exit 1; }
grep -q "none: a depth camera alone" "$1/map/report.html" || { echo "FAIL: report.html does not say so"; exit 1; }
grep -q '"degenerate_frames_unmeasured": 0' "$1/map/report.json" && grep -q '"degenerate_unmeasured_poses": \[\]' "$1/map/report.json" || { echo "FAIL: degenerate views not counted"; exit 1; }
! grep -a -q "property uchar red" "$1/map/mesh.ply" && ! grep -a -q "property uchar red" "$1/map/map.ply" || { echo "FAIL: a mesh of black colours"; exit 1; }
ate=$(sed -n 's/^  ate_rmse_m \([0-9.]*\).*/\1/p' "$1/map.log")
awk -v a="$ate" 'BEGIN { exit !(a != "" && a < 0.05) }' || { cat "$1/map.log"; echo "FAIL: map ATE '$ate'"; exit 1; }
kitchen_copy "$1/coloured" 0 29
"$0" semantic "$1/coloured" --out "$1/sem-colour" > /dev/null 2>&1 || { echo "FAIL: semantic with colour"; exit 1; }
"$0" semantic "$1/seq" --out "$1/sem-depth" > /dev/null 2> "$1/sem.err" || { cat "$1/sem.err"; echo "FAIL: semantic on depth alone"; exit 1; }
for f in labels.png semantic.png occupancy.pgm; do
  cmp -s "$1/sem-colour/$f" "$1/sem-depth/$f" || { echo "FAIL: semantic $f differs without colour"; exit 1; }
done
exit 0
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-depth-alone-sequence ${KARTOGRAF_DATA_DIR}
  ${CMAKE_CURRENT_SOURCE_DIR}/kitchen_copy.sh ${fails_with_helper})

# --motion-prior: another sensor's camera poses predict each step (the kitchen's frames 0-29
# without colour): its ground truth, and a TUM file (the odometry's own trajectory, stamped by
# frame number as Kartograf stamps layouts without timestamps), each frame predicted by it (in
# --stats); a file that lacks frames and a missing file are Errors naming it, before any output;
# on a timestamped layout a prior sampled slower than the frames is interpolated between its poses;
# --prior-time-offset reads it on another clock, the summary measures that clock's offset, and
# --prior-time-offset auto measures it before the run;
# --pose-mount turns a body's poses into the camera's.
add_test(NAME Cli.input_motion_prior
  COMMAND sh -c [=[
DATA=$2; . "$3"; . "$4"
rm -rf "$1" && mkdir -p "$1" || exit 1
kitchen_depth_alone "$1/seq" 0 29
"$0" odometry "$1/seq" --out "$1/plain.txt" > "$1/plain.log" 2>&1 || { cat "$1/plain.log"; exit 1; }
"$0" odometry "$1/seq" --motion-prior groundtruth --out "$1/truth.txt" --stats "$1/truth.json" > "$1/truth.log" 2>&1 || { cat "$1/truth.log"; echo "FAIL: groundtruth prior"; exit 1; }
grep -q "predicted by the motion prior 29" "$1/truth.log" || { cat "$1/truth.log"; echo "FAIL: frames predicted by the prior not counted"; exit 1; }
test "$(grep -o '"from_motion_prior": true' "$1/truth.json" | wc -l)" -eq 29 || { echo "FAIL: --stats"; exit 1; }
"$0" odometry "$1/seq" --motion-prior "$1/plain.txt" --out "$1/file.txt" > "$1/file.log" 2>&1 || { cat "$1/file.log"; echo "FAIL: file prior"; exit 1; }
grep -q "predicted by the motion prior 29" "$1/file.log" || { cat "$1/file.log"; echo "FAIL: file prior not used"; exit 1; }
for log in plain truth file; do
  ate=$(sed -n 's/^  ate_rmse_m \([0-9.]*\).*/\1/p' "$1/$log.log")
  awk -v a="$ate" 'BEGIN { exit !(a != "" && a < 0.05) }' || { cat "$1/$log.log"; echo "FAIL: $log ATE '$ate'"; exit 1; }
done
head -7 "$1/plain.txt" > "$1/short.txt"
fails_with "$1/err" "--motion-prior: '$1/short.txt' has no pose within 20 ms of frame" -- "$0" odometry "$1/seq" --motion-prior "$1/short.txt" --out "$1/x.txt" || exit 1
fails_with "$1/err" "none.txt" -- "$0" slam "$1/seq" --motion-prior "$1/none.txt" --out "$1/x" || exit 1
test ! -e "$1/x" && test ! -e "$1/x.txt" || { echo "FAIL: a refused run left output"; exit 1; }
# A timestamped layout (30 Hz) and a prior at 10 Hz: interpolated at the frames between its poses;
# a gap over 0.5 s (frames 1-12 between poses 0.9 s apart) is an Error naming the frame.
"$0" synth --out "$1/syn" --frames 13 --width 320 --height 240 --trajectory handheld > /dev/null 2>&1 || { echo "FAIL: synth"; exit 1; }
grep -v '^#' "$1/syn/groundtruth.txt" | awk 'NR % 3 == 1' > "$1/ten_hz.txt"
test "$(wc -l < "$1/ten_hz.txt")" -eq 5 || { echo "FAIL: the 10 Hz prior"; exit 1; }
"$0" odometry "$1/syn" --motion-prior "$1/ten_hz.txt" --out "$1/syn.txt" > "$1/syn.log" 2>&1 || { cat "$1/syn.log"; echo "FAIL: 10 Hz prior"; exit 1; }
grep -q "predicted by the motion prior 12" "$1/syn.log" || { cat "$1/syn.log"; echo "FAIL: 10 Hz prior not used at every frame"; exit 1; }
grep -v '^#' "$1/syn/groundtruth.txt" | awk 'NR == 1 { print } NR == 13 { $1 = "0.9"; print }' > "$1/gap.txt"
fails_with "$1/err" "no pose within 20 ms of frame 1 (timestamp 0.033333), nor two at most 0.5 s apart around it" -- "$0" odometry "$1/syn" --motion-prior "$1/gap.txt" --out "$1/x.txt" || exit 1
# --prior-time-offset: the same prior on a clock 50 ms ahead (its stamps + 0.05) is refused at
# frame 0 without the offset and with it gives the 10 Hz run's steps to the digit.
awk '{ $1 = sprintf("%.6f", $1 + 0.05); print }' "$1/ten_hz.txt" > "$1/ahead.txt"
fails_with "$1/err" "no pose within 20 ms of frame 0" -- "$0" odometry "$1/syn" --motion-prior "$1/ahead.txt" --out "$1/x.txt" || exit 1
"$0" odometry "$1/syn" --motion-prior "$1/ahead.txt" --prior-time-offset 0.05 --out "$1/ahead_run.txt" > "$1/ahead.log" 2>&1 || { cat "$1/ahead.log"; echo "FAIL: --prior-time-offset"; exit 1; }
off() { grep -o "predicted by the motion prior [^)]*)" "$1"; }
test -n "$(off "$1/syn.log")" && test "$(off "$1/syn.log")" = "$(off "$1/ahead.log")" || { echo "FAIL: offset prior '$(off "$1/ahead.log")' against '$(off "$1/syn.log")'"; exit 1; }
# The summary measures the prior's clock from how the camera turned: on a longer hand-held
# sequence (16 s; at 8 s the measurement's spread, 6-10 ms, reached the 10 ms it may have) with the
# prior 40 ms ahead, it names the offset to pass (within 10 ms) when none
# is given, and agrees with the right one; the 13-frame run above is too short to measure it.
grep -q "motion prior clock: not measured (the file's poses do not span the frames' times +- 500 ms)" "$1/syn.log" || { cat "$1/syn.log"; echo "FAIL: a short run's clock"; exit 1; }
"$0" synth --out "$1/hand" --frames 480 --width 320 --height 240 --trajectory handheld > /dev/null 2>&1 || { echo "FAIL: synth 480"; exit 1; }
grep -v '^#' "$1/hand/groundtruth.txt" | awk '{ $1 = sprintf("%.6f", $1 + 0.04); print }' > "$1/hand_ahead.txt"
"$0" odometry "$1/hand" --first 20 --motion-prior "$1/hand_ahead.txt" --out "$1/hand.txt" > "$1/hand.log" 2>&1 || { cat "$1/hand.log"; echo "FAIL: hand-held run"; exit 1; }
named=$(sed -n 's/.*motion prior clock: .* try --prior-time-offset \([0-9.]*\)$/\1/p' "$1/hand.log")
awk -v s="$named" 'BEGIN { exit !(s != "" && s > 0.03 && s < 0.05) }' || { cat "$1/hand.log"; echo "FAIL: the clock offset named '$named' (0.04)"; exit 1; }
"$0" odometry "$1/hand" --first 20 --motion-prior "$1/hand_ahead.txt" --prior-time-offset 0.04 --out "$1/hand.txt" --force > "$1/hand_right.log" 2>&1 || { cat "$1/hand_right.log"; exit 1; }
grep -q "motion prior clock: agrees with the offset in use (+0.040 s" "$1/hand_right.log" || { cat "$1/hand_right.log"; echo "FAIL: the right offset not agreed with"; exit 1; }
# auto: measured first (the odometry over the frames without the prior), then read at it; a run
# too short to tell it is refused.
"$0" odometry "$1/hand" --first 20 --motion-prior "$1/hand_ahead.txt" --prior-time-offset auto --out "$1/hand.txt" --force > "$1/hand_auto.log" 2> "$1/hand_auto.err" || { cat "$1/hand_auto.err"; echo "FAIL: --prior-time-offset auto"; exit 1; }
grep -q "motion prior clock: +0.0[345][0-9] s (+- [0-9.]* ms) measured over the first 460 frames (--prior-time-offset auto)" "$1/hand_auto.err" && grep -q "motion prior clock: agrees with the offset in use (+0.0[345]" "$1/hand_auto.log" || { cat "$1/hand_auto.err" "$1/hand_auto.log"; echo "FAIL: the measured offset not used"; exit 1; }
fails_with "$1/err" "--prior-time-offset auto: the motion prior's clock is not measurable from the first 13 frames" -- "$0" odometry "$1/syn" --motion-prior "$1/ten_hz.txt" --prior-time-offset auto --out "$1/x.txt" || exit 1
"$0" map "$1/hand" --first 20 --frames 220 --no-features --motion-prior "$1/hand_ahead.txt" --out "$1/hand_map" --no-progress > "$1/hand_map.log" 2>&1 || { cat "$1/hand_map.log"; echo "FAIL: map with the prior"; exit 1; }
grep -q "motion prior clock: its turning matches best read at +0.0[345]" "$1/hand_map.log" && grep -q '"agrees": false' "$1/hand_map/report.json" && grep -q "the prior's clock: its turning matches" "$1/hand_map/report.html" || { cat "$1/hand_map.log"; echo "FAIL: the map's report of the clock"; exit 1; }
fails_with "$1/err" "--prior-time-offset: no --motion-prior FILE to apply it to" -- "$0" odometry "$1/syn" --prior-time-offset 0.1 --out "$1/x.txt" || exit 1
fails_with "$1/err" "has no timestamps" -- "$0" odometry "$1/seq" --motion-prior "$1/plain.txt" --prior-time-offset 0.1 --out "$1/x.txt" || exit 1
# --pose-mount: a file of a body's poses (base = camera x mount^-1) and the camera's pose on it give
# the camera's poses (map --poses: its steps are the ground truth's, RPE < 1e-6 m; without the
# mount over 1 mm); a quaternion that is not a unit one, and a mount with no file to apply it to,
# are Errors.
python3 - "$1/syn/groundtruth.txt" "$1/base.txt" <<'PY' || exit 1
import sys
def mul(a, b):  # quaternions (x, y, z, w)
    ax, ay, az, aw = a; bx, by, bz, bw = b
    return (aw*bx + ax*bw + ay*bz - az*by, aw*by - ax*bz + ay*bw + az*bx,
            aw*bz + ax*by - ay*bx + az*bw, aw*bw - ax*bx - ay*by - az*bz)
def rotate(q, v):
    x, y, z, w = mul(mul(q, (v[0], v[1], v[2], 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return (x, y, z)
mount_t, mount_q = (0.1, -0.05, 0.3), (0.5, 0.5, 0.5, 0.5)
inverse_q = (-0.5, -0.5, -0.5, 0.5)
inverse_t = tuple(-c for c in rotate(inverse_q, mount_t))
with open(sys.argv[2], "w") as out:
    for line in open(sys.argv[1]):
        if line.startswith("#"): continue
        v = [float(x) for x in line.split()]
        q = tuple(v[4:8]); step = rotate(q, inverse_t)
        t = [v[1 + k] + step[k] for k in range(3)]
        out.write("%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n" % (v[0], *t, *mul(q, inverse_q)))
PY
"$0" map "$1/syn" --poses "$1/base.txt" --pose-mount 0.1,-0.05,0.3,0.5,0.5,0.5,0.5 --out "$1/mount" --no-progress > "$1/mount.log" 2>&1 || { cat "$1/mount.log"; echo "FAIL: map --poses with --pose-mount"; exit 1; }
"$0" map "$1/syn" --poses "$1/base.txt" --out "$1/body" --no-progress > "$1/body.log" 2>&1 || { cat "$1/body.log"; echo "FAIL: map --poses of the body"; exit 1; }
rpe() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["evaluation"]["trajectory"]["rpe_translation_rmse_m"])' "$1/report.json"; }
awk -v a="$(rpe "$1/mount")" -v b="$(rpe "$1/body")" 'BEGIN { exit !(a != "" && a < 1e-6 && b > 1e-3) }' || { echo "FAIL: RPE with the mount '$(rpe "$1/mount")' (< 1e-6 m), without '$(rpe "$1/body")' (> 1 mm)"; exit 1; }
fails_with "$1/err" "--pose-mount: quaternion (0.000000, 0.000000, 0.000000, 2.000000) has norm 2.000000, not 1" -- "$0" map "$1/syn" --poses "$1/base.txt" --pose-mount 0,0,0,0,0,0,2 --out "$1/x" || exit 1
fails_with "$1/err" "--pose-mount: no --poses or --motion-prior FILE to apply it to" -- "$0" odometry "$1/syn" --pose-mount 0,0,0,0,0,0,1 --out "$1/x.txt" || exit 1
test ! -e "$1/x" && test ! -e "$1/x.txt" || { echo "FAIL: a refused run left output"; exit 1; }
exit 0
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-input-motion-prior ${KARTOGRAF_DATA_DIR}
  ${CMAKE_CURRENT_SOURCE_DIR}/kitchen_copy.sh ${fails_with_helper})

set_tests_properties(Cli.input_colour_and_depth_sizes_and_truncated_images
  Cli.input_motion_prior
  Cli.input_sequence_from_depth_alone
  Cli.input_planes_from_depth_alone
  Cli.input_missing_frames_bad_poses_and_short_trajectories
  Cli.input_unusable_depth_is_named_before_the_run PROPERTIES ENVIRONMENT "${KARTOGRAF_TEST_ENV}")
