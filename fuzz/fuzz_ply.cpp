// Fuzz target: PLY point clouds (ascii and binary).
#include "fuzz_input_file.hpp"
#include "kartograf/formats/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kartograf::fuzz::read_as_file("cloud.ply", data, size,
                                [](const auto& path) { kartograf::io::read_ply(path); });
  return 0;
}
