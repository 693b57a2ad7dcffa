#pragma once
// A compute context owns one backend and one device. Operations take a Context and run on it;
// Buffers made from a Context live on its device.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kartograf/compute/backend.hpp"

namespace kartograf::compute {

// One device command as the device timed it (ContextParams::profile).
struct DeviceTiming {
  std::string command;  // the kernel's name, or "upload", "download", "copy", "fill"
  double milliseconds = 0;
};

namespace detail {
class Device;
}

struct ContextParams {
  BackendChoice backend = BackendChoice::automatic;
  // Index into the backend's usable devices (the CPU backend has one: 0); empty: the best one
  // (discrete > integrated > other). With `automatic`, an index into the backend it takes.
  std::optional<int> device_index;
  // What set device_index, for messages ("KARTOGRAF_DEVICE" when read from the environment).
  std::string device_index_source = "device index";
  // Vulkan only: enable VK_LAYER_KHRONOS_validation with synchronization validation, and count
  // every error it reports (see Context::validation_errors). Ignored when the layer is missing.
  bool vulkan_validation = false;
  // Time every device command (kernels, copies, fills) on the device: Vulkan timestamp queries,
  // OpenCL profiling events. Costs a little per command; for benchmarks. Ignored on the CPU.
  bool profile = false;

  // KARTOGRAF_BACKEND=auto|cpu|vulkan|opencl, KARTOGRAF_DEVICE=<index>,
  // KARTOGRAF_VULKAN_VALIDATION=1.
  static ContextParams from_environment();
  // Only KARTOGRAF_DEVICE and KARTOGRAF_VULKAN_VALIDATION, for callers that choose the backend
  // themselves (the CLI's --backend). Throws Error naming the variable and its value when
  // KARTOGRAF_DEVICE is not a device index.
  void read_device_environment();
};

class Context {
 public:
  // Throws Error naming the backend and why it cannot be used (no loader, no driver, no device...).
  explicit Context(const ContextParams& options);
  // The backend named by KARTOGRAF_BACKEND (automatic when unset).
  static Context from_environment();
  static Context cpu();

  Context(Context&&) noexcept;
  Context& operator=(Context&&) noexcept;
  ~Context();

  BackendKind backend() const;
  const DeviceInfo& device_info() const;
  // For the compute layer and tests only: operations dispatch the same way on every backend.
  bool is_cpu() const { return backend() == BackendKind::cpu; }

  // Waits until every dispatched operation has finished.
  void finish() const;
  // Compiles every embedded shader pipeline / OpenCL kernel now, so none is first compiled later.
  void build_all_kernels() const;
  // Vulkan with validation on: messages of severity error so far. Zero elsewhere.
  std::uint64_t validation_errors() const;
  bool validation_active() const;
  // With ContextParams::profile: every command completed since the last call, in issue order
  // (waits for what is pending). Empty on the CPU backend or without profiling.
  std::vector<DeviceTiming> take_device_timings() const;

  // The backend's device, for compute/kernel.hpp's dispatch (every backend has one).
  detail::Device* device() const { return &checked_device(); }

 private:
  friend class RawBuffer;
  std::shared_ptr<detail::Device> shared_device() const { return device_; }
  detail::Device& checked_device() const;
  std::shared_ptr<detail::Device> device_;
};

}  // namespace kartograf::compute
