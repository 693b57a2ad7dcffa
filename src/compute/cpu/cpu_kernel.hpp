#pragma once
// What a kernel's CPU wrapper (kernels/<operation>/<operation>_cpu.cpp) sees: the same call the
// GPU backends get (buffers in binding order, the parameter block, the work-group count), with
// the buffers as host memory. Wrappers loop over the work items with the helpers below, which
// run chunks on the CPU backend's threads (compute/cpu_parallel.hpp).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

#include "compute/cpu_parallel.hpp"
#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute::detail {

struct CpuDispatch {
  KernelSpec kernel;
  std::span<std::byte* const> buffers;      // null: an absent optional input
  std::span<const std::size_t> buffer_bytes;  // each buffer's size (0 when absent)
  std::span<const std::byte> params;
  GroupCount groups;

  template <class T>
  T* buffer(std::size_t binding) const {
    require(binding < buffers.size(), "CPU kernel '" + std::string(kernel.name) +
                                          "': no buffer at binding " + std::to_string(binding));
    return reinterpret_cast<T*>(buffers[binding]);
  }
  template <class T>
  std::size_t count(std::size_t binding) const {
    return binding < buffer_bytes.size() ? buffer_bytes[binding] / sizeof(T) : 0;
  }
  // The parameter block as the shader's struct (checked to be the size the caller passed).
  template <class Params>
  Params params_as() const {
    static_assert(std::is_trivially_copyable_v<Params>);
    require(params.size() == sizeof(Params), "CPU kernel '" + std::string(kernel.name) +
                                                 "': parameter block of " +
                                                 std::to_string(params.size()) + " bytes, expected " +
                                                 std::to_string(sizeof(Params)));
    Params value;
    std::memcpy(&value, params.data(), sizeof(Params));
    return value;
  }
  std::uint32_t global_x() const { return groups.x * kernel.local_x; }
  std::uint32_t global_y() const { return groups.y * kernel.local_y; }
};

using CpuKernel = void (*)(const CpuDispatch&);

// The CPU kernels by name; filled once from every kernels/*/*_cpu.cpp (see cpu_kernels.cpp).
class CpuKernelRegistry {
 public:
  void add(std::string_view name, CpuKernel kernel);  // a name given twice is an Error
  CpuKernel find(std::string_view name) const;        // null when none has that name
  std::size_t size() const { return kernels_.size(); }

 private:
  std::map<std::string, CpuKernel, std::less<>> kernels_;
};

// Every registered CPU kernel (built on first use from the generated list of wrappers).
const CpuKernelRegistry& cpu_kernels();

// body(x, y) for every work item of a 2-D dispatch (global size = groups x local size), rows split
// into chunks; the body checks its own bounds, exactly as the shader does.
template <class Body>
void for_each_item_2d(const CpuDispatch& call, Body&& body) {
  const std::uint32_t width = call.global_x();
  const std::uint32_t height = call.global_y();
  for_each_chunk(height, std::size_t(width) * height,
                 [&](std::size_t first, std::size_t last, std::size_t) {
                   for (std::size_t y = first; y < last; ++y) {
                     for (std::uint32_t x = 0; x < width; ++x) body(x, static_cast<std::uint32_t>(y));
                   }
                 });
}

// body(index) for every work item of a 1-D dispatch.
template <class Body>
void for_each_item(const CpuDispatch& call, Body&& body) {
  const std::size_t count = call.global_x();
  for_each_chunk(count, count, [&](std::size_t first, std::size_t last, std::size_t) {
    for (std::size_t i = first; i < last; ++i) body(static_cast<std::uint32_t>(i));
  });
}

}  // namespace kartograf::compute::detail
