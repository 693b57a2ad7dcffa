#pragma once
// Reading and writing image files, and turning depth and normal images into pictures to look at.
// Errors throw kartograf::Error naming the file and the problem.
#include <filesystem>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::io {

// A single-channel 16-bit image (a PNG in practice) of raw depth units, 0 = no measurement.
// Rejects 8-bit or multi-channel files rather than guessing a scale.
DepthImage read_depth_png(const std::filesystem::path& path);

// An 8-bit colour image (JPEG, PNG, ... with 3 or 4 channels) in RGB order; alpha is dropped.
// Pixels are as stored: EXIF orientation is ignored so that colour stays aligned with depth.
RgbImage read_color_image(const std::filesystem::path& path);

// PNG writers: 8-bit gray, 8-bit RGB, 16-bit gray. Atomic: the file appears complete or not at all.
void write_png(const std::filesystem::path& path, const GrayImage& image);
void write_png(const std::filesystem::path& path, const RgbImage& image);
void write_png(const std::filesystem::path& path, const DepthImage& image);

// Depth through the viridis colormap from 0 m (dark purple) to max_metres (yellow, also beyond it);
// black where there is no depth.
RgbImage colorize_depth(const DepthImage& depth, double units_per_metre, double max_metres);

// (n + 1) / 2 * 255 per axis (x red, y green, z blue); black where the normal is NaN.
RgbImage colorize_normals(const NormalImage& normals);

}  // namespace kartograf::io
