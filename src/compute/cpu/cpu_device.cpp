#include "compute/cpu/cpu_device.hpp"

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "compute/cpu/cpu_kernel.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute::detail {

namespace {

// Host memory: its own, or a view of memory the caller keeps alive (RawBuffer::refer_or_upload).
class CpuBuffer final : public DeviceBuffer {
 public:
  // Uninitialised, as device memory is (fill_zero clears): pages a kernel never touches are never
  // faulted in, e.g. region growing's per-tile stacks, tens of MB of which a frame uses a little.
  explicit CpuBuffer(std::size_t bytes)
      : owned_(std::make_unique_for_overwrite<std::byte[]>(bytes)),
        data_(owned_.get()),
        size_(bytes) {}
  CpuBuffer(std::byte* view, std::size_t bytes) : data_(view), size_(bytes) {}
  std::byte* data() { return data_; }
  std::size_t size() const { return size_; }

 private:
  std::unique_ptr<std::byte[]> owned_;
  std::byte* data_;
  std::size_t size_;
};

CpuBuffer& host(DeviceBuffer& buffer) { return static_cast<CpuBuffer&>(buffer); }
const CpuBuffer& host(const DeviceBuffer& buffer) { return static_cast<const CpuBuffer&>(buffer); }

class CpuDevice final : public Device {
 public:
  CpuDevice() : info_(cpu_device_info()) {}
  const DeviceInfo& info() const override { return info_; }

  std::unique_ptr<DeviceBuffer> create_buffer(std::size_t bytes) override {
    return std::make_unique<CpuBuffer>(bytes);
  }
  void write(DeviceBuffer& buffer, std::size_t offset, const void* source,
             std::size_t bytes) override {
    std::memcpy(host(buffer).data() + offset, source, bytes);
  }
  void read(const DeviceBuffer& buffer, std::size_t offset, void* destination,
            std::size_t bytes) override {
    std::memcpy(destination, const_cast<CpuBuffer&>(host(buffer)).data() + offset, bytes);
  }
  void fill_zero(DeviceBuffer& buffer, std::size_t offset, std::size_t bytes) override {
    // A view (refer_or_upload) has no padding to a whole word.
    std::memset(host(buffer).data() + offset, 0, std::min(bytes, host(buffer).size() - offset));
  }
  void copy(const DeviceBuffer& source, std::size_t source_offset, DeviceBuffer& target,
            std::size_t target_offset, std::size_t bytes) override {
    std::memmove(host(target).data() + target_offset,
                 const_cast<CpuBuffer&>(host(source)).data() + source_offset, bytes);
  }
  void dispatch(const KernelSpec& kernel, std::span<DeviceBuffer* const> buffers,
                std::span<const std::byte> params, GroupCount groups) override;
  std::byte* host_pointer(DeviceBuffer& buffer) const override { return host(buffer).data(); }
  std::unique_ptr<DeviceBuffer> view_host(std::byte* data, std::size_t bytes) override {
    return std::make_unique<CpuBuffer>(data, bytes);
  }
  void finish() override {}
  void build_all_kernels() override { cpu_kernels(); }
  std::vector<DeviceTiming> take_device_timings() override { return {}; }

 private:
  DeviceInfo info_;
};

void CpuDevice::dispatch(const KernelSpec& kernel, std::span<DeviceBuffer* const> buffers,
                         std::span<const std::byte> params, GroupCount groups) {
  const CpuKernel run = cpu_kernels().find(kernel.name);
  require(run != nullptr, "kernel '" + std::string(kernel.name) +
                              "': the CPU backend has no such kernel (no kernels/*/*_cpu.cpp "
                              "registers it)");
  constexpr std::size_t kMaxBuffers = 16;
  std::byte* pointers[kMaxBuffers] = {};
  std::size_t sizes[kMaxBuffers] = {};
  for (std::size_t i = 0; i < buffers.size() && i < kMaxBuffers; ++i) {
    if (!buffers[i]) continue;
    pointers[i] = host(*buffers[i]).data();
    sizes[i] = host(*buffers[i]).size();
  }
  run(CpuDispatch{kernel, std::span<std::byte* const>(pointers, buffers.size()),
                  std::span<const std::size_t>(sizes, buffers.size()), params, groups});
}

}  // namespace

void CpuKernelRegistry::add(std::string_view name, CpuKernel kernel) {
  const bool added = kernels_.emplace(std::string(name), kernel).second;
  require(added, "CPU kernel '" + std::string(name) + "' is registered twice");
}

CpuKernel CpuKernelRegistry::find(std::string_view name) const {
  const auto found = kernels_.find(name);
  return found == kernels_.end() ? nullptr : found->second;
}

std::shared_ptr<Device> create_cpu_device() { return std::make_shared<CpuDevice>(); }

}  // namespace kartograf::compute::detail
