#pragma once
// Raw copies of real images, for the device tests that must run without kartograf_io (OpenCV):
// kartograf_export_device_data writes them, kartograf_device_tests reads them. One text line,
//   kartograf-raw 1 KIND WIDTH HEIGHT CHANNELS TYPE\n
// then WIDTH x HEIGHT x CHANNELS values of TYPE, row-major, little-endian, nothing after them.
// KIND / CHANNELS / TYPE: depth 1 u16 (raw depth units), color 3 u8 (RGB), occupancy 1 u8
// (CellState: 0 unknown, 1 free, 2 occupied).
#include <filesystem>

#include "kartograf/core/color.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::testing::raw {

void write_depth(const std::filesystem::path& path, const DepthImage& image);
void write_color(const std::filesystem::path& path, const RgbImage& image);
void write_occupancy(const std::filesystem::path& path, const Image<CellState>& cells);

// A missing, truncated or malformed file, or one of another kind, is an Error naming the file.
DepthImage read_depth(const std::filesystem::path& path);
RgbImage read_color(const std::filesystem::path& path);
Image<CellState> read_occupancy(const std::filesystem::path& path);

}  // namespace kartograf::testing::raw
