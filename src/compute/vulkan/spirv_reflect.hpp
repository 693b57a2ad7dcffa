#pragma once
// The two facts a compute pipeline needs from a SPIR-V module: how many storage-buffer bindings
// it declares (set 0, bindings 0..n-1) and its work-group size.
#include <cstddef>
#include <cstdint>
#include <string>

namespace kartograf::compute::detail {

struct SpirvShape {
  std::uint32_t binding_count = 0;
  std::uint32_t local_size[3] = {1, 1, 1};
  bool has_push_constants = false;
};

// Throws Error naming `name` if the words are not a SPIR-V module.
SpirvShape reflect_spirv(const std::uint32_t* words, std::size_t word_count, const std::string& name);

}  // namespace kartograf::compute::detail
