// The real data of the device tests as kartograf_device_tests reads it: the raw copies
// (PATH.raw) that kartograf_export_device_data writes, so that no image library is needed.
#include <string>

#include "device_data_files.hpp"
#include "kartograf/core/error.hpp"
#include "raw_image_file.hpp"
#include "real_data.hpp"

namespace kartograf::testing {

DepthImage read_depth(const std::filesystem::path& path) {
  return raw::read_depth(raw_copy_path(path));
}

RgbImage read_color(const std::filesystem::path& path) {
  return raw::read_color(raw_copy_path(path));
}

OccupancyGrid read_occupancy_map(const std::filesystem::path& path, double resolution) {
  require(resolution > 0,
          "map " + path.string() + ": resolution must be > 0, got " + std::to_string(resolution));
  OccupancyGrid map;
  map.cells = raw::read_occupancy(raw_copy_path(path));
  map.resolution = resolution;
  return map;
}

}  // namespace kartograf::testing
