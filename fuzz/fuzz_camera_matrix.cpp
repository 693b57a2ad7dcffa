// Fuzz target: camera-intrinsics.txt (7-Scenes / 3DMatch / SUN3D: a 3x3 K as 9 numbers).
#include "fuzz_input_file.hpp"
#include "kartograf/formats/camera_intrinsics.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kartograf::fuzz::read_as_file("camera-intrinsics.txt", data, size, [](const auto& path) {
    kartograf::io::read_camera_matrix_txt(path);
  });
  return 0;
}
