// Fuzz target: camera_intrinsics.json (Open3D's PinholeCameraIntrinsic).
#include "fuzz_input_file.hpp"
#include "kartograf/formats/sequence.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kartograf::fuzz::read_as_file("camera_intrinsics.json", data, size, [](const auto& path) {
    kartograf::io::read_camera_intrinsics_json(path);
  });
  return 0;
}
