#pragma once
// 2-D map files: ROS map_server maps (YAML + PGM/PNG), ipa_room_segmentation-style PNG maps and
// their ground-truth room drawings, 16-bit label images and 8-bit semantic-class images.
// Errors throw kartograf::Error naming the file, the key or pixel, and the problem; writes are
// atomic.
#include <filesystem>

#include "kartograf/core/color.hpp"
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/core/connected_components.hpp"

namespace kartograf::io {

// ---- ROS map_server --------------------------------------------------------------------------
// YAML keys (as map_server reads them): image (a PGM or PNG path, relative to the YAML's folder
// unless absolute), resolution (m/cell, > 0), origin [x, y, yaw], occupied_thresh and free_thresh
// (0 <= free_thresh <= occupied_thresh <= 1), negate (0/1 or false/true), optional mode.
// Cells follow map_server exactly: v = the mean of the pixel's channels, p = (255 - v) / 255
// (v / 255 when negate); occupied if p > occupied_thresh, free if p < free_thresh, else unknown.
// Modes: trinary (the default) as above, where map_server averages an alpha channel in with the
// colours; scale reads the same except that alpha is left out of the mean, and the graded cells
// map_server would give between the thresholds become unknown (OccupancyGrid has three states);
// raw is rejected (its cells are raw occupancy numbers, not thresholded grey levels).
// Images must be 8-bit with 1, 3 or 4 channels (OpenCV decodes a grey+alpha PNG as 4 channels
// g,g,g,a: store maps single-channel to match map_server exactly).
OccupancyGrid read_ros_map(const std::filesystem::path& yaml_path);

// Writes <yaml stem>.pgm beside the YAML, as map_saver does: occupied 0, free 254, unknown 205,
// with occupied_thresh 0.65, free_thresh 0.196, negate 0, mode trinary. Both files are staged
// completely before either replaces anything, so an error leaves no half-written pair.
void write_ros_map(const std::filesystem::path& yaml_path, const OccupancyGrid& grid);

// ---- ipa_room_segmentation maps ----------------------------------------------------------------
// An 8-bit PNG (grey, or colour read as luminance): grey >= free_threshold is free, anything else
// occupied (ipa maps draw unknown/outside space grey and treat it as not free). Origin (0, 0, 0).
OccupancyGrid read_png_map(const std::filesystem::path& path, double resolution = 0.05,
                           int free_threshold = 250);
// The grey values of such an image (colour read as luminance, as the reference reads its maps),
// e.g. a training drawing whose grey levels are labels.
GrayImage read_map_gray(const std::filesystem::path& path);
// Free 255, occupied 0, unknown 205 (read back as occupied: the format has no unknown).
void write_png_map(const std::filesystem::path& path, const OccupancyGrid& grid);

struct RoomGroundTruthParams {
  int min_white = 251;        // grey >= this is room (ipa thresholds at "> 250")
  int min_room_pixels = 100;  // smaller white regions are drawing specks, not rooms
  Connectivity connectivity = Connectivity::four;
};
// A `*_gt_segmentation.png`: every connected white region of >= min_room_pixels is one room,
// numbered 1..N in raster order of its first pixel; everything else is 0.
LabelImage read_room_ground_truth_png(const std::filesystem::path& path,
                                      const RoomGroundTruthParams& options = {});

// Ground-truth rooms from either kind of file: an 8-bit PNG is an ipa drawing (above), a 16-bit
// single-channel PNG a label image used as it is.
LabelImage read_ground_truth_rooms(const std::filesystem::path& path);

// ---- Label and semantic images -----------------------------------------------------------------
// 16-bit single-channel PNG, value = label, 0 = no label. 8-bit files are rejected.
LabelImage read_label_png(const std::filesystem::path& path);
void write_label_png(const std::filesystem::path& path, const LabelImage& labels);

// Deterministic, well-separated colours (hues a golden angle apart); label 0 is black.
RgbImage colorize_labels(const LabelImage& labels);

// 8-bit single-channel PNG of SemanticClass values; any other value is an error naming the pixel.
SemanticImage read_semantic_png(const std::filesystem::path& path);
void write_semantic_png(const std::filesystem::path& path, const SemanticImage& classes);

}  // namespace kartograf::io
