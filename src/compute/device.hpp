#pragma once
// The interface every backend implements: the CPU (compute/cpu), Vulkan and OpenCL. Operations never see it directly: they
// go through compute/kernel.hpp and compute/buffer.hpp.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "kartograf/compute/backend.hpp"
#include "kartograf/compute/kernel.hpp"

namespace kartograf::compute::detail {

class DeviceBuffer {
 public:
  virtual ~DeviceBuffer() = default;
};

// Commands are executed in the order they are issued. dispatch and fill_zero may be deferred and
// batched; read waits for everything issued before it.
class Device {
 public:
  virtual ~Device() = default;
  virtual const DeviceInfo& info() const = 0;

  virtual std::unique_ptr<DeviceBuffer> create_buffer(std::size_t bytes) = 0;
  virtual void write(DeviceBuffer& buffer, std::size_t offset, const void* source,
                     std::size_t bytes) = 0;
  virtual void read(const DeviceBuffer& buffer, std::size_t offset, void* destination,
                    std::size_t bytes) = 0;
  virtual void fill_zero(DeviceBuffer& buffer, std::size_t offset, std::size_t bytes) = 0;

  // buffers: null entries are absent optional inputs (bind a placeholder).
  virtual void dispatch(const KernelSpec& kernel, std::span<DeviceBuffer* const> buffers,
                        std::span<const std::byte> params, GroupCount groups) = 0;
  // Copies bytes between two buffers of this device, in order with the other commands.
  virtual void copy(const DeviceBuffer& source, std::size_t source_offset, DeviceBuffer& target,
                    std::size_t target_offset, std::size_t bytes) = 0;
  // The buffer's bytes when they live in host memory (the CPU backend), else null.
  virtual std::byte* host_pointer(DeviceBuffer&) const { return nullptr; }
  // A buffer that is a view of `bytes` of host memory the caller keeps alive; null where buffers
  // are not host memory (then the caller uploads).
  virtual std::unique_ptr<DeviceBuffer> view_host(std::byte*, std::size_t) { return nullptr; }
  virtual void finish() = 0;
  virtual void build_all_kernels() = 0;

  virtual std::uint64_t validation_errors() const { return 0; }
  virtual bool validation_active() const { return false; }
  // Completed commands' device times (ContextParams::profile); waits for pending commands.
  virtual std::vector<DeviceTiming> take_device_timings() = 0;
};

DeviceInfo cpu_device_info();

// Which of a backend's usable devices a context takes: options.device_index if given (checked),
// else a discrete GPU, else an integrated GPU, else the first.
std::size_t choose_device(const std::vector<const DeviceInfo*>& usable, const ContextParams& options,
                          std::string_view backend);

// Each throws Error naming why the backend or the requested device cannot be used.
std::shared_ptr<Device> create_vulkan_device(const ContextParams& options);
std::shared_ptr<Device> create_opencl_device(const ContextParams& options);
BackendStatus probe_vulkan();
BackendStatus probe_opencl();

}  // namespace kartograf::compute::detail
