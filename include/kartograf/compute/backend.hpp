#pragma once
// Which compute backends exist on this machine, and what their devices are.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace kartograf::compute {

enum class BackendKind { cpu, vulkan, opencl };
// What a caller asks for: one backend, or `automatic` (a GPU if there is one, else the CPU).
enum class BackendChoice { automatic, cpu, vulkan, opencl };

std::string_view to_string(BackendKind kind);
std::string_view to_string(BackendChoice choice);
// Parses "auto|cpu|vulkan|opencl"; throws Error naming `source` (e.g. "KARTOGRAF_BACKEND").
BackendChoice parse_backend_choice(std::string_view text, std::string_view source);
// The choice that asks for exactly `kind`.
BackendChoice choice_of(BackendKind kind);

enum class DeviceType { cpu, integrated_gpu, discrete_gpu, virtual_gpu, other };
std::string_view to_string(DeviceType type);

// What a device offers beyond Kartograf's requirements, for `kartograf devices` and benchmarks.
struct DeviceLimits {
  std::uint32_t compute_units = 0;              // 0: the API does not say (Vulkan)
  std::uint32_t max_workgroup_invocations = 0;  // per work-group
  std::uint64_t shared_memory_bytes = 0;        // per work-group (Vulkan shared, OpenCL local)
  std::uint64_t max_buffer_bytes = 0;           // largest storage buffer / allocation
  std::uint32_t subgroup_size = 0;              // 0: no subgroups exposed to compute
  bool fp64 = false;
  bool int64 = false;  // 64-bit integers in kernels
  bool int64_atomics = false;
  bool device_timestamps = false;  // kernels can be timed on the device (ContextParams::profile)
};

// One line: "work-group 1024, shared 48 KiB, subgroup 32, fp64 yes, ..." (unknown values left out).
std::string describe(const DeviceLimits& limits);

struct DeviceInfo {
  BackendKind backend = BackendKind::cpu;
  std::string name;
  DeviceType type = DeviceType::cpu;
  std::string api_version;  // "Vulkan 1.3.230", "OpenCL 3.0 PoCL ...", or the CPU's "C++/Eigen"
  std::string driver;
  std::uint64_t memory_bytes = 0;
  bool unified_memory = false;  // buffers are host-visible: no staging copies
  bool usable = true;           // meets Kartograf's requirements (fp64, int64 atomics)
  std::string unusable_reason;
  DeviceLimits limits;
  bool is_gpu() const { return type == DeviceType::discrete_gpu || type == DeviceType::integrated_gpu; }
};

struct BackendStatus {
  BackendKind backend = BackendKind::cpu;
  bool available = false;
  std::string reason;  // why it is unavailable; empty when available
  std::vector<DeviceInfo> devices;
};

// Probes every backend (loads the Vulkan and OpenCL loaders if present). Never throws.
std::vector<BackendStatus> probe_backends();

}  // namespace kartograf::compute
