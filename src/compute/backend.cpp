#include "kartograf/compute/backend.hpp"

#include <thread>

#include <Eigen/Core>

#include "compute/device.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute {

std::string_view to_string(BackendKind kind) {
  switch (kind) {
    case BackendKind::cpu: return "cpu";
    case BackendKind::vulkan: return "vulkan";
    case BackendKind::opencl: return "opencl";
  }
  return "?";
}

std::string_view to_string(BackendChoice choice) {
  switch (choice) {
    case BackendChoice::automatic: return "auto";
    case BackendChoice::cpu: return "cpu";
    case BackendChoice::vulkan: return "vulkan";
    case BackendChoice::opencl: return "opencl";
  }
  return "?";
}

BackendChoice parse_backend_choice(std::string_view text, std::string_view source) {
  if (text == "auto" || text.empty()) return BackendChoice::automatic;
  if (text == "cpu") return BackendChoice::cpu;
  if (text == "vulkan") return BackendChoice::vulkan;
  if (text == "opencl") return BackendChoice::opencl;
  throw Error(std::string(source) + ": unknown backend '" + std::string(text) +
              "' (expected auto, cpu, vulkan or opencl)");
}

BackendChoice choice_of(BackendKind kind) {
  switch (kind) {
    case BackendKind::cpu: return BackendChoice::cpu;
    case BackendKind::vulkan: return BackendChoice::vulkan;
    case BackendKind::opencl: return BackendChoice::opencl;
  }
  return BackendChoice::cpu;
}

std::string_view to_string(DeviceType type) {
  switch (type) {
    case DeviceType::cpu: return "cpu";
    case DeviceType::integrated_gpu: return "integrated-gpu";
    case DeviceType::discrete_gpu: return "discrete-gpu";
    case DeviceType::virtual_gpu: return "virtual-gpu";
    case DeviceType::other: return "other";
  }
  return "?";
}

namespace detail {
DeviceInfo cpu_device_info() {
  DeviceInfo info;
  info.backend = BackendKind::cpu;
  info.name = "host CPU (" + std::to_string(std::thread::hardware_concurrency()) + " threads)";
  info.type = DeviceType::cpu;
  info.api_version = "C++20 / Eigen " + std::to_string(EIGEN_WORLD_VERSION) + "." +
                     std::to_string(EIGEN_MAJOR_VERSION) + "." + std::to_string(EIGEN_MINOR_VERSION);
  info.driver = "reference implementation";
  info.unified_memory = true;
  info.limits.compute_units = std::thread::hardware_concurrency();
  info.limits.fp64 = true;
  info.limits.int64 = true;
  info.limits.int64_atomics = true;
  return info;
}
}  // namespace detail

std::string describe(const DeviceLimits& limits) {
  std::string text;
  const auto add = [&](const std::string& part) { text += (text.empty() ? "" : ", ") + part; };
  const auto yes_no = [](bool value) { return std::string(value ? "yes" : "no"); };
  if (limits.compute_units) add("compute units " + std::to_string(limits.compute_units));
  if (limits.max_workgroup_invocations) {
    add("work-group " + std::to_string(limits.max_workgroup_invocations));
  }
  if (limits.shared_memory_bytes) add("shared " + std::to_string(limits.shared_memory_bytes / 1024) + " KiB");
  if (limits.max_buffer_bytes) {
    add("max buffer " + std::to_string(limits.max_buffer_bytes / (1024 * 1024)) + " MiB");
  }
  add("subgroup " + (limits.subgroup_size ? std::to_string(limits.subgroup_size) : std::string("none")));
  add("fp64 " + yes_no(limits.fp64));
  add("int64 atomics " + yes_no(limits.int64_atomics));
  add("device timestamps " + yes_no(limits.device_timestamps));
  return text;
}

std::vector<BackendStatus> probe_backends() {
  BackendStatus cpu;
  cpu.backend = BackendKind::cpu;
  cpu.available = true;
  cpu.devices.push_back(detail::cpu_device_info());
  return {cpu, detail::probe_vulkan(), detail::probe_opencl()};
}

}  // namespace kartograf::compute
