// Fuzz target: PCD v0.7 point clouds (ascii, binary, binary_compressed).
#include "fuzz_input_file.hpp"
#include "kartograf/formats/pcd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kartograf::fuzz::read_as_file("cloud.pcd", data, size, [](const auto& path) {
    const auto cloud = kartograf::io::read_pcd(path);
    if (cloud.organized()) cloud.to_point_image();
    cloud.to_point_cloud();
  });
  return 0;
}
