# Issue 20 "limits": inputs too large for memory are refused before allocating (KARTOGRAF_MEMORY_LIMIT
# keeps the tests small), KARTOGRAF_DEVICE works on every command, invalid option values are
# errors rather than silent defaults. Included from tests/CMakeLists.txt.

# Each test sources cli_fails_with.sh (its $1), which defines
# `fails_with [--regex] LOG PATTERN... -- COMMAND...`.
set(fails_with_helper ${CMAKE_CURRENT_SOURCE_DIR}/cli_fails_with.sh)

# Defect 7: a map whose rooms would not fit is refused before segmenting (a 4000 x 4000 PGM, 16 MB,
# under a 200 MB limit); an image whose header declares 20000 x 20000 pixels is refused before
# decoding; a map YAML pointing at /dev/zero is refused at once. No output folder is left.
add_test(NAME Cli.limits_maps_too_large_for_memory_are_refused
  COMMAND sh -c [=[
. "$1" && shift || exit 1
rm -rf "$1" && mkdir -p "$1" || exit 1
{ printf 'P5\n4000 4000\n255\n'; head -c 16000000 /dev/zero | tr '\000' '\376'; } > "$1/big.pgm"
fails_with "$1/rooms.txt" \
  "room segmentation (morphological) of a 4000 x 4000 map needs about" \
  "KARTOGRAF_MEMORY_LIMIT allows 200.0 MB" -- env KARTOGRAF_MEMORY_LIMIT=200M "$0" rooms "$1/big.pgm" --out "$1/rooms" || exit 1
test ! -e "$1/rooms" || { echo "FAIL: $1/rooms was created"; exit 1; }
printf '\211PNG\r\n\032\n\000\000\000\015IHDR\000\000\116\040\000\000\116\040\010\000\000\000\000crc!\000\000\000\000IEND\256B`\202' > "$1/huge.png"
fails_with "$1/huge.txt" "huge.png" "(20000x20000 pixels) needs about" \
  -- env KARTOGRAF_MEMORY_LIMIT=64M "$0" rooms "$1/huge.png" --out "$1/rooms" || exit 1
printf 'image: /dev/zero\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n' > "$1/zero.yaml"
fails_with "$1/zero.txt" "/dev/zero" "not a regular file" -- "$0" rooms "$1/zero.yaml" --out "$1/rooms" || exit 1
ln -sf /dev/zero "$1/link.yaml"
fails_with "$1/link.txt" "link.yaml" "not a regular file" -- "$0" rooms "$1/link.yaml" --out "$1/rooms" || exit 1
test ! -e "$1/rooms" || { echo "FAIL: $1/rooms was created"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${fails_with_helper} ${CMAKE_BINARY_DIR}/cli-limits-maps)

# Defect 11 and the semantic range image of defect 7: out-of-range, zero, negative, NaN and
# infinite values are errors naming the option, never silently replaced by a default.
add_test(NAME Cli.limits_invalid_option_values_are_errors
  COMMAND sh -c [=[
. "$1" && shift || exit 1
rm -rf "$1" && mkdir -p "$1" || exit 1
pcd="$2/pcl_mosd/test0.pcd"; map="$2/ipa_room_maps/test_maps/lab_ipa.png"
for value in 0 -500 nan inf; do
  fails_with "$1/fx.txt" "--fx" -- "$0" planes "$pcd" --fx "$value" --out "$1/p" || exit 1
done
fails_with "$1/fy.txt" "--fy" -- "$0" planes "$pcd" --fy nan --out "$1/p" || exit 1
fails_with "$1/cx.txt" "--cx" -- "$0" planes "$pcd" --cx -3 --out "$1/p" || exit 1
fails_with "$1/scale.txt" "--depth-scale" -- "$0" planes "$pcd" --depth-scale nan --out "$1/p" || exit 1
fails_with "$1/lab.txt" "--lab-threshold" -- "$0" planes "$pcd" --lab-threshold nan --out "$1/p" || exit 1
fails_with "$1/angle.txt" "--normal-angle" -- "$0" planes "$pcd" --normal-angle nan --out "$1/p" || exit 1
fails_with "$1/min.txt" "--min-area" -- "$0" rooms "$map" --min-area -5 --max-area 100 --out "$1/r" || exit 1
fails_with "$1/max.txt" "--max-area" -- "$0" rooms "$map" --min-area 1 --max-area nan --out "$1/r" || exit 1
fails_with "$1/res.txt" "--resolution" -- "$0" rooms "$map" --resolution nan --out "$1/r" || exit 1
for value in 0.01 0 nan 1000; do
  fails_with "$1/step.txt" "--angular-step" -- "$0" semantic "$pcd" --angular-step "$value" --out "$1/s" || exit 1
done
fails_with "$1/sres.txt" "--resolution" -- "$0" semantic "$pcd" --resolution nan --out "$1/s" || exit 1
fails_with "$1/view.txt" "--viewpoint" -- "$0" semantic "$pcd" --viewpoint 0 nan 0 --out "$1/s" || exit 1
fails_with "$1/pixels.txt" "--min-plane-pixels: '-5' is not a whole number" -- "$0" planes "$pcd" --min-plane-pixels -5 --out "$1/p" || exit 1
fails_with "$1/threads.txt" "--threads" -- "$0" synth --threads -3 --out "$1/y" || exit 1
fails_with "$1/seed.txt" "--seed" -- "$0" synth --seed -1 --out "$1/y" || exit 1
fails_with "$1/look.txt" "--look-around" -- "$0" synth --look-around nan --out "$1/y" || exit 1
fails_with "$1/sfx.txt" "--fx" -- "$0" synth --fx -1 --out "$1/y" || exit 1
fails_with "$1/delta.txt" "--delta" -- "$0" eval traj "$3" "$3" --delta nan || exit 1
fails_with "$1/threshold.txt" "--threshold" -- "$0" eval planes "$3" "$3" --threshold nan || exit 1
fails_with "$1/rres.txt" "--resolution" -- "$0" eval rooms "$4" "$4" --resolution nan || exit 1
fails_with "$1/voxel.txt" "--voxel" -- "$0" slam "$1" --voxel nan --out "$1/v" || exit 1
fails_with "$1/mres.txt" "--resolution" -- "$0" map "$1" --resolution nan --out "$1/m" || exit 1
for dir in p r s y v m; do test ! -e "$1/$dir" || { echo "FAIL: $1/$dir was created"; exit 1; }; done
]=] $<TARGET_FILE:kartograf> ${fails_with_helper} ${CMAKE_BINARY_DIR}/cli-limits-options ${KARTOGRAF_DATA_DIR}
    ${KARTOGRAF_DATA_DIR}/tum_fr1_xyz_lists_only/groundtruth.txt
    ${KARTOGRAF_DATA_DIR}/ipa_room_maps/test_maps/office_e_gt_segmentation.png)

# Defect 9: KARTOGRAF_DEVICE picks the device on every command: a bad value or an index beyond
# the backend's devices is an error naming the variable, the value and the devices there are.
add_test(NAME Cli.limits_kartograf_device_on_every_command
  COMMAND sh -c [=[
. "$1" && shift || exit 1
rm -rf "$1" && mkdir -p "$1" || exit 1
pcd="$2/pcl_mosd/test0.pcd"
fails_with "$1/vulkan9.txt" "KARTOGRAF_DEVICE=9: no such device" \
  "Vulkan backend has 1 usable device(s): [0] " -- env KARTOGRAF_DEVICE=9 "$0" planes "$pcd" --backend vulkan --out "$1/p" || exit 1
fails_with "$1/abc.txt" "KARTOGRAF_DEVICE='abc'" \
  -- env KARTOGRAF_DEVICE=abc "$0" planes "$pcd" --backend cpu --out "$1/p" || exit 1
fails_with "$1/cpu1.txt" "KARTOGRAF_DEVICE=1" "cpu backend has 1 usable device(s): [0] host CPU" \
  -- env KARTOGRAF_DEVICE=1 "$0" rooms "$2/ipa_room_maps/test_maps/lab_ipa.png" --method feature --backend cpu --out "$1/r" || exit 1
fails_with "$1/odometry.txt" "KARTOGRAF_DEVICE=7" \
  -- env KARTOGRAF_DEVICE=7 "$0" odometry "$2/7scenes_redkitchen" --frames 2 --backend cpu --out "$1/t.txt" || exit 1
test ! -e "$1/p" && test ! -e "$1/r" && test ! -e "$1/t.txt" || { echo "FAIL: output left"; exit 1; }
KARTOGRAF_DEVICE=0 "$0" planes "$pcd" --backend vulkan --out "$1/p" > "$1/ok.txt" 2>&1 || { cat "$1/ok.txt"; exit 1; }
test -s "$1/p/planes.json" || { echo "FAIL: KARTOGRAF_DEVICE=0 planes wrote nothing"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${fails_with_helper} ${CMAKE_BINARY_DIR}/cli-limits-device ${KARTOGRAF_DATA_DIR})
# A grid resolution other than the 0.05 m the semantic grid's thresholds were set for runs with a
# warning that says so (docs/user-guide.md, "Grid resolution"); the default runs without one.
add_test(NAME Cli.limits_an_untuned_grid_resolution_is_warned_of
  COMMAND sh -c [=[
rm -rf "$1" && mkdir -p "$1" || exit 1
"$0" semantic "$2/pcl_clouds/office1.pcd" --resolution 0.1 --out "$1/coarse" 2> "$1/coarse.err" ||
  { cat "$1/coarse.err"; exit 1; }
grep -qF "semantic: warning: --resolution 0.1 m: the semantic grid's thresholds are set for 0.05 m" "$1/coarse.err" ||
  { echo "FAIL: no warning in:"; cat "$1/coarse.err"; exit 1; }
"$0" semantic "$2/pcl_clouds/office1.pcd" --out "$1/default" 2> "$1/default.err" || exit 1
! grep -qF "warning: --resolution" "$1/default.err" || { echo "FAIL: a warning at 0.05 m"; exit 1; }
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-grid-resolution ${KARTOGRAF_DATA_DIR})

set_tests_properties(Cli.limits_maps_too_large_for_memory_are_refused
  Cli.limits_invalid_option_values_are_errors Cli.limits_kartograf_device_on_every_command
  Cli.limits_an_untuned_grid_resolution_is_warned_of
  PROPERTIES ENVIRONMENT "${KARTOGRAF_TEST_ENV}")

# The defaults the help prints are the ones the run uses: --anchor-bounds once listed 17 numbers,
# memory between two temporaries' arrays, after its three.
add_test(NAME Cli.help_shows_the_anchor_bounds_default
  COMMAND sh -c [=[
for command in odometry slam map; do
  "$0" "$command" --help | grep -F -- "=[0.4,25,100] x 3" ||
    { echo "FAIL: $command --help: $("$0" "$command" --help | grep -F -- --anchor-bounds)"; exit 1; }
done
]=] $<TARGET_FILE:kartograf>)
