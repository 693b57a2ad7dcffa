// Fuzz target: depth and colour images as sequences store them (PNG, JPEG; PNM too): the header
// checks, truncation checks and size limits before OpenCV decodes them, and the refusal of the
// other formats OpenCV would decode (BMP, TIFF, WebP, ...) whose size is not checked first.
#include "fuzz_input_file.hpp"
#include "kartograf/formats/image_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using kartograf::fuzz::read_as_file;
  read_as_file("depth.png", data, size,
               [](const auto& path) { kartograf::io::read_depth_png(path); });
  read_as_file("color.png", data, size,
               [](const auto& path) { kartograf::io::read_color_image(path); });
  read_as_file("color.jpg", data, size,
               [](const auto& path) { kartograf::io::read_color_image(path); });
  return 0;
}
