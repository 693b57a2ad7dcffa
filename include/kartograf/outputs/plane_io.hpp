#pragma once
// Extracted planes (segmentation::PlaneSet) on disk: planes.json for programs, pictures for
// people, and the labelled points as a cloud. The label image itself is a 16-bit PNG
// (occupancy_map_io.hpp: write_label_png / read_label_png). Writes are atomic; reads throw Error
// naming the file and the field.
//
// planes.json: {"format": "kartograf-planes", "version": 1, "source": ..., "width", "height",
// "intrinsics": {fx, fy, cx, cy}, "planes": [{"id", "normal": [3], "offset", "centroid": [3],
// "major_axis": [3], "minor_axis": [3], "extent_min": [2], "extent_max": [2], "inlier_count",
// "rms_error"}, ...], "segment_count", "merged_count", "timings_ms": {...}} plus whatever the
// caller adds under "run". Planes: n . p + offset = 0 in the camera frame (metres), n towards the
// camera; extents are in the (major_axis, minor_axis) frame at the centroid.
#include <filesystem>
#include <string>
#include <vector>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"

namespace kartograf::io {

// What planes.json records besides the planes. run_json: a JSON object (text) stored under "run"
// (parameters, backend, ...), or empty.
struct PlaneFileInfo {
  std::string source;
  PinholeIntrinsics intrinsics;
  std::string run_json;
};

void write_planes_json(const std::filesystem::path& path, const segmentation::PlaneSet& planes,
                       const PlaneFileInfo& info);
// The planes of a planes.json (ids, geometry, counts; not the label image).
std::vector<segmentation::Plane> read_planes_json(const std::filesystem::path& path);

// For people: the colour image dimmed to grey, each plane's pixels in its colour (colorize_labels)
// blended over it, plane borders drawn dark. rgb and labels have the same size.
RgbImage plane_overlay(const RgbImage& rgb, const LabelImage& labels);

// A frame without colour seen as grey by depth, near bright and far dark (no depth: black), as
// plane_overlay's background.
RgbImage depth_shading(const PointImage& points);

// The pixels with a plane as a cloud, each in its plane's colour (colorize_labels).
PointCloud plane_points(const PointImage& points, const LabelImage& labels);

}  // namespace kartograf::io
