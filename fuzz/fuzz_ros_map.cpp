// Fuzz target: ROS map_server YAML + the PGM it names. The input is the YAML text, then a line
// "---pgm---", then the image bytes (stored as map.pgm beside the YAML). Inputs whose YAML
// mentions another path ('/' or "..") are skipped: the reader would open arbitrary files.
#include <string_view>

#include "fuzz_input_file.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view separator = "\n---pgm---\n";
  const auto split = input.find(separator);
  const std::string_view yaml = input.substr(0, split);
  if (yaml.find('/') != std::string_view::npos || yaml.find("..") != std::string_view::npos) return 0;
  const std::size_t image_offset = split == std::string_view::npos ? size : split + separator.size();
  kartograf::fuzz::write_input("map.pgm", data + image_offset, size - image_offset);
  kartograf::fuzz::read_as_file("map.yaml", data, yaml.size(),
                                [](const auto& path) { kartograf::io::read_ros_map(path); });
  return 0;
}
