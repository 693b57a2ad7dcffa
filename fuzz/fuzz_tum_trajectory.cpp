// Fuzz target: TUM trajectory files (timestamp tx ty tz qx qy qz qw).
#include "fuzz_input_file.hpp"
#include "kartograf/formats/tum.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kartograf::fuzz::read_as_file("trajectory.txt", data, size,
                                [](const auto& path) { kartograf::io::read_tum_trajectory(path); });
  return 0;
}
