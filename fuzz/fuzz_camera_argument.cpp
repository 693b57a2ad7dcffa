// Fuzz target: the --camera value (a preset name or "fx,fy,cx,cy"), then fitted to a frame size
// taken from the first bytes. Values that could name a file (with '/' or a leading '.') are
// skipped so that the fuzzer cannot make the parser open arbitrary files.
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/camera_intrinsics.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const int width = 1 + data[0] * 8, height = 1 + data[1] * 8;
  const std::string value(reinterpret_cast<const char*>(data + 2), size - 2);
  if (value.find('/') != std::string::npos || (!value.empty() && value[0] == '.')) return 0;
  try {
    const kartograf::io::Camera camera = kartograf::io::parse_camera_argument(value);
    kartograf::io::describe(kartograf::io::fit_camera_to_frames(camera, width, height));
  } catch (const kartograf::Error&) {
  }
  return 0;
}
