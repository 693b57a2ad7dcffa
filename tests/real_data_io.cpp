// The real data of the device tests as the binaries above the file layers read it: the original
// files, through kartograf_formats.
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "real_data.hpp"

namespace kartograf::testing {

DepthImage read_depth(const std::filesystem::path& path) {
  return io::read_depth_png(path);
}

RgbImage read_color(const std::filesystem::path& path) {
  return io::read_color_image(path);
}

OccupancyGrid read_occupancy_map(const std::filesystem::path& path, double resolution) {
  return io::read_png_map(path, resolution);
}

}  // namespace kartograf::testing
