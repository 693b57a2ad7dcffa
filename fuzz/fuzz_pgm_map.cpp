// Fuzz target: 2-D map images (PGM/PNG decoded by OpenCV, then thresholded into a grid).
#include "fuzz_input_file.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kartograf::fuzz::read_as_file("map.pgm", data, size,
                                [](const auto& path) { kartograf::io::read_png_map(path); });
  return 0;
}
