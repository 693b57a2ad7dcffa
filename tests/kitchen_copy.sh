# Sourced by the CLI input tests (cli_input_tests.cmake) with DATA set to the real data folder:
# kitchen_copy DIR FIRST LAST links frames FIRST..LAST of the 7-Scenes kitchen into DIR, with its
# camera file, so that a test can break some of them without copying the data.
kitchen_copy() {
  mkdir -p "$1" && cp "$DATA/7scenes_redkitchen/camera-intrinsics.txt" "$1/" || exit 1
  for n in $(seq "$2" "$3"); do
    for s in color.jpg depth.png pose.txt; do
      f=$(printf 'frame-%06d.%s' "$n" "$s")
      ln -s "$DATA/7scenes_redkitchen/frames/$f" "$1/$f" || exit 1
    done
  done
}

# kitchen_depth_alone DIR FIRST LAST: the same frames without their colour images (a depth camera
# alone).
kitchen_depth_alone() {
  kitchen_copy "$1" "$2" "$3"
  rm "$1"/frame-*.color.jpg || exit 1
}
