#pragma once
// The real input files of the device tests (paths under testing::data_dir()), read by whichever
// binary the tests are linked into: kartograf_pipeline_tests and kartograf_outputs_tests read the
// original files through kartograf_formats (real_data_io.cpp); kartograf_device_tests, built
// without OpenCV to travel to a GPU machine, and the per-layer binaries below the file layers read
// the raw copies that kartograf_export_device_data writes beside them as PATH.raw
// (real_data_raw.cpp, device_data_files.hpp). Text files (poses) are read as they are. A missing
// or malformed file is a kartograf::Error naming it, which fails the test.
#include <filesystem>

#include "kartograf/core/color.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::testing {

// A 16-bit depth image (a PNG), raw depth units.
DepthImage read_depth(const std::filesystem::path& path);

// An 8-bit colour image (a JPEG or PNG), RGB.
RgbImage read_color(const std::filesystem::path& path);

// An ipa room map (a grey PNG: >= 250 free, else occupied) at `resolution` metres per cell.
OccupancyGrid read_occupancy_map(const std::filesystem::path& path, double resolution);

}  // namespace kartograf::testing
