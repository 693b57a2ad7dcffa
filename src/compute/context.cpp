#include "kartograf/compute/context.hpp"

#include <cstdlib>
#include <string>

#include "compute/device.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute {

namespace {

const char* env(const char* name) {
  const char* value = std::getenv(name);
  return (value && *value) ? value : nullptr;
}

// A GPU device of `backend` that `automatic` would take, if any.
std::optional<int> best_gpu(const BackendStatus& status) {
  std::optional<int> best;
  int usable_index = 0;
  for (const DeviceInfo& device : status.devices) {
    if (!device.usable) continue;
    if (device.type == DeviceType::discrete_gpu) return usable_index;
    if (device.type == DeviceType::integrated_gpu && !best) best = usable_index;
    ++usable_index;
  }
  return best;
}

}  // namespace

ContextOptions ContextOptions::from_environment() {
  ContextOptions options;
  if (const char* backend = env("KARTOGRAF_BACKEND")) {
    options.backend = parse_backend_choice(backend, "KARTOGRAF_BACKEND");
  }
  if (const char* index = env("KARTOGRAF_DEVICE")) {
    char* end = nullptr;
    const long value = std::strtol(index, &end, 10);
    require(end && *end == '\0' && value >= 0,
            std::string("KARTOGRAF_DEVICE: expected a device index >= 0, got '") + index + "'");
    options.device_index = static_cast<int>(value);
  }
  if (const char* validation = env("KARTOGRAF_VULKAN_VALIDATION")) {
    options.vulkan_validation = std::string(validation) != "0";
  }
  return options;
}

Context::Context() : cpu_info_(detail::cpu_device_info()) {}

Context::Context(const ContextOptions& options) : Context() {
  switch (options.backend) {
    case BackendChoice::cpu:
      break;
    case BackendChoice::vulkan:
      device_ = detail::create_vulkan_device(options);
      break;
    case BackendChoice::opencl:
      device_ = detail::create_opencl_device(options);
      break;
    case BackendChoice::automatic: {
      // CPU-hosted drivers (lavapipe, PoCL) are for correctness, not speed: only a GPU beats the
      // CPU reference, so automatic takes a GPU or nothing.
      ContextOptions chosen = options;
      if (auto index = best_gpu(detail::probe_vulkan())) {
        chosen.device_index = *index;
        device_ = detail::create_vulkan_device(chosen);
      } else if (auto cl_index = best_gpu(detail::probe_opencl())) {
        chosen.device_index = *cl_index;
        device_ = detail::create_opencl_device(chosen);
      }
      break;
    }
  }
}

Context Context::from_environment() { return Context(ContextOptions::from_environment()); }
Context Context::cpu() {
  ContextOptions options;
  options.backend = BackendChoice::cpu;
  return Context(options);
}

Context::Context(Context&&) noexcept = default;
Context& Context::operator=(Context&&) noexcept = default;
Context::~Context() = default;

BackendKind Context::backend() const { return device_ ? device_->info().backend : BackendKind::cpu; }
const DeviceInfo& Context::device_info() const { return device_ ? device_->info() : cpu_info_; }

void Context::finish() const {
  if (device_) device_->finish();
}
void Context::build_all_kernels() const {
  if (device_) device_->build_all_kernels();
}
std::uint64_t Context::validation_errors() const {
  return device_ ? device_->validation_errors() : 0;
}
bool Context::validation_active() const { return device_ && device_->validation_active(); }

}  // namespace kartograf::compute
