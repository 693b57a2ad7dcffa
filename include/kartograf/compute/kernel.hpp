#pragma once
// How an operation runs its device path: name a kernel, bind buffers in order, pass a small
// parameter block, and give the number of work-groups. The same call drives the GLSL shader
// `shaders/<name>.comp` (buffers are set 0 bindings 0..n-1, params the push-constant block) and
// the OpenCL kernel `<name>` in `kernels/` (buffers are arguments 0..n-1, params argument n).
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string_view>
#include <type_traits>

#include "kartograf/compute/buffer.hpp"

namespace kartograf::compute {

struct KernelSpec {
  std::string_view name;
  std::uint32_t local_x = 64;  // must equal the shader's local_size_x (checked by the Vulkan backend)
  std::uint32_t local_y = 1;
};

struct GroupCount {
  std::uint32_t x = 1;
  std::uint32_t y = 1;
};

inline std::uint32_t groups_for(std::size_t items, std::uint32_t local_size) {
  return static_cast<std::uint32_t>((items + local_size - 1) / local_size);
}

// A buffer bound to a kernel; a default-constructed one binds a placeholder (an absent input).
struct BufferArg {
  const RawBuffer* raw = nullptr;
  BufferArg() = default;
  BufferArg(const RawBuffer& buffer) : raw(&buffer) {}  // NOLINT: implicit by design
  template <class T>
  BufferArg(const Buffer<T>& buffer) : raw(&buffer.raw()) {}  // NOLINT
};

// The most bytes of parameters a kernel takes: Vulkan's guaranteed push-constant size.
inline constexpr std::size_t kMaxKernelParamBytes = 128;

void dispatch_raw(const Context& context, const KernelSpec& kernel, std::span<const BufferArg> buffers,
                  std::span<const std::byte> params, GroupCount groups);

// Params: a struct of 4-byte scalars only, laid out exactly like the shader's push-constant
// block and the OpenCL kernel's struct argument.
template <class Params>
void dispatch(const Context& context, const KernelSpec& kernel,
              std::initializer_list<BufferArg> buffers, const Params& params, GroupCount groups) {
  static_assert(std::is_trivially_copyable_v<Params> && alignof(Params) == 4 &&
                    sizeof(Params) % 4 == 0 && sizeof(Params) <= kMaxKernelParamBytes,
                "kernel params are a small block of 4-byte scalars");
  dispatch_raw(context, kernel, std::span<const BufferArg>(buffers.begin(), buffers.size()),
               std::as_bytes(std::span<const Params>(&params, 1)), groups);
}

}  // namespace kartograf::compute
