// Fuzz target: TUM frame lists (rgb.txt / depth.txt: timestamp filename).
#include "fuzz_input_file.hpp"
#include "kartograf/formats/tum.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kartograf::fuzz::read_as_file("rgb.txt", data, size,
                                [](const auto& path) { kartograf::io::read_tum_file_list(path); });
  return 0;
}
