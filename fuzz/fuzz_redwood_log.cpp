// Fuzz target: Redwood / Open3D .log trajectories.
#include "fuzz_input_file.hpp"
#include "kartograf/formats/sequence.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kartograf::fuzz::read_as_file("trajectory.log", data, size,
                                [](const auto& path) { kartograf::io::read_redwood_log(path); });
  return 0;
}
