#pragma once
// Room segmentations (rooms::RoomSegmentation) on disk, and the benchmark's folders of maps.
//
// rooms.json: {"format": "kartograf-rooms", "version": 1, "source", "method", "seconds",
// "resolution", "origin": [x, y, yaw], "width", "height", "rooms": [{"id", "area_m2", "cells",
// "centroid": [x, y], "bbox_min": [x, y], "bbox_max": [x, y] (map frame, metres),
// "bbox_cells": [col0, row0, col1, row1], "neighbours": [id...], "doorways": [{"to", "from": [x,
// y], "to_point": [x, y], "width_m", "cells"}]}], "run": {...}}. The label image is rooms.png
// (16-bit, occupancy_map_io.hpp's write_label_png). Writes are atomic.
#include <filesystem>
#include <string>
#include <vector>

#include "kartograf/core/color.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/rooms/room_segmentation.hpp"

namespace kartograf::io {

// run_json: a JSON object (text) stored under "run" (parameters, ...), or empty.
void write_rooms_json(const std::filesystem::path& path, const rooms::RoomSegmentation& rooms,
                      const OccupancyGrid& map, const std::string& source,
                      const std::string& run_json = {});

// For people: each room in its colour (colorize_labels), free cells without a room white,
// obstacles black (furniture in a room too), unknown grey, the borders between rooms dark.
RgbImage room_overlay(const OccupancyGrid& map, const LabelImage& rooms);

// A benchmark folder in ipa_room_segmentation's layout: NAME_gt_segmentation.png beside NAME.png
// and its variants NAME_furnitures.png, NAME_trashbins.png, NAME_furnitures_trashbins.png.
struct RoomMapCase {
  std::string name;     // NAME
  std::string variant;  // plain | furnitures | trashbins | furnitures_trashbins
  std::filesystem::path map, ground_truth;
};
inline const std::vector<std::string>& room_map_variants() {
  static const std::vector<std::string> variants{"plain", "furnitures", "trashbins",
                                                 "furnitures_trashbins"};
  return variants;
}
// Every map with a ground truth, sorted by name then variant order. Throws Error naming the
// folder when it is missing or holds no NAME_gt_segmentation.png with its map.
std::vector<RoomMapCase> find_room_maps(const std::filesystem::path& folder);

}  // namespace kartograf::io
