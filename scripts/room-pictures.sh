#!/usr/bin/env bash
# The pictures of docs/rooms.md: every room segmentation method on a few benchmark maps of
# ../shared/data/ipa_room_maps/test_maps, written as docs/images/rooms_<map>_<method>.png.
#
#   scripts/room-pictures.sh [build-dir]
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$repo/build}"
maps="${KARTOGRAF_DATA_DIR:-$repo/../shared/data}/ipa_room_maps/test_maps"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

for map in office_e_furnitures lab_ipa; do
  for method in morphological distance voronoi feature vrf; do
    "$build/apps/kartograf/kartograf" rooms "$maps/$map.png" --method "$method" --out "$work/$map-$method"
    cp "$work/$map-$method/rooms_color.png" "$repo/docs/images/rooms_${map}_${method}.png"
  done
done
