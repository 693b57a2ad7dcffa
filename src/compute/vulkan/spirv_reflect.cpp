#include "compute/vulkan/spirv_reflect.hpp"

#include <algorithm>

#include "kartograf/core/error.hpp"

namespace kartograf::compute::detail {

SpirvShape reflect_spirv(const std::uint32_t* words, std::size_t word_count, const std::string& name) {
  constexpr std::uint32_t kMagic = 0x07230203;
  constexpr std::uint32_t kOpExecutionMode = 16, kOpVariable = 59, kOpDecorate = 71;
  constexpr std::uint32_t kModeLocalSize = 17, kDecorationBinding = 33;
  constexpr std::uint32_t kStoragePushConstant = 9;
  require(word_count > 5 && words[0] == kMagic, "shader '" + name + "' is not SPIR-V");

  SpirvShape shape;
  for (std::size_t at = 5; at < word_count;) {
    const std::uint32_t length = words[at] >> 16;
    const std::uint32_t opcode = words[at] & 0xffff;
    require(length > 0 && at + length <= word_count, "shader '" + name + "': truncated SPIR-V");
    if (opcode == kOpDecorate && length >= 4 && words[at + 2] == kDecorationBinding) {
      shape.binding_count = std::max(shape.binding_count, words[at + 3] + 1);
    } else if (opcode == kOpExecutionMode && length >= 6 && words[at + 2] == kModeLocalSize) {
      for (int axis = 0; axis < 3; ++axis) shape.local_size[axis] = words[at + 3 + axis];
    } else if (opcode == kOpVariable && length >= 4 && words[at + 3] == kStoragePushConstant) {
      shape.has_push_constants = true;
    }
    at += length;
  }
  return shape;
}

}  // namespace kartograf::compute::detail
