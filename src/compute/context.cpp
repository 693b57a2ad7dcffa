#include "kartograf/compute/context.hpp"

#include <cstdlib>
#include <string>

#include "compute/cpu/cpu_device.hpp"
#include "compute/device.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute {

namespace {

const char* env(const char* name) {
  const char* value = std::getenv(name);
  return (value && *value) ? value : nullptr;
}

// The usable GPU of a backend that `automatic` would take, if any.
std::optional<int> best_gpu(const BackendStatus& status) {
  std::vector<const DeviceInfo*> usable;
  for (const DeviceInfo& device : status.devices) {
    if (device.usable) usable.push_back(&device);
  }
  if (usable.empty()) return std::nullopt;
  const std::size_t index = detail::choose_device(usable, ContextParams{}, to_string(status.backend));
  if (!usable[index]->is_gpu()) return std::nullopt;
  return static_cast<int>(index);
}

// The CPU backend has one device; an index other than 0 is an Error.
std::shared_ptr<detail::Device> cpu_device(const ContextParams& options) {
  auto device = detail::create_cpu_device();
  detail::choose_device({&device->info()}, options, "cpu");
  return device;
}

}  // namespace

namespace detail {
std::size_t choose_device(const std::vector<const DeviceInfo*>& usable, const ContextParams& options,
                          std::string_view backend) {
  if (options.device_index) {
    if (*options.device_index < 0 || *options.device_index >= static_cast<int>(usable.size())) {
      std::string devices;
      for (std::size_t i = 0; i < usable.size(); ++i) {
        devices += (i == 0 ? " [" : ", [") + std::to_string(i) + "] " + usable[i]->name;
      }
      throw Error(options.device_index_source + "=" + std::to_string(*options.device_index) +
                  ": no such device; the " + std::string(backend) + " backend has " +
                  std::to_string(usable.size()) + " usable device(s):" + devices +
                  " (see `kartograf devices`)");
    }
    return static_cast<std::size_t>(*options.device_index);
  }
  for (DeviceType preferred : {DeviceType::discrete_gpu, DeviceType::integrated_gpu}) {
    for (std::size_t i = 0; i < usable.size(); ++i) {
      if (usable[i]->type == preferred) return i;
    }
  }
  return 0;
}
}  // namespace detail

ContextParams ContextParams::from_environment() {
  ContextParams options;
  if (const char* backend = env("KARTOGRAF_BACKEND")) {
    options.backend = parse_backend_choice(backend, "KARTOGRAF_BACKEND");
  }
  options.read_device_environment();
  return options;
}

void ContextParams::read_device_environment() {
  if (const char* index = env("KARTOGRAF_DEVICE")) {
    const std::string text = index;
    // Digits only (no sign, blanks or suffix), and few enough to be an int.
    const bool digits =
        text.size() <= 9 && text.find_first_not_of("0123456789") == std::string::npos;
    require(digits, "KARTOGRAF_DEVICE='" + text +
                        "': expected a device index (0, 1, ...; `kartograf devices` lists them)");
    device_index = std::stoi(text);
    device_index_source = "KARTOGRAF_DEVICE";
  }
  if (const char* validation = env("KARTOGRAF_VULKAN_VALIDATION")) {
    vulkan_validation = std::string(validation) != "0";
  }
}

Context::Context(const ContextParams& options) {
  switch (options.backend) {
    case BackendChoice::cpu:
      device_ = cpu_device(options);
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
      // A device index given applies to the backend taken.
      ContextParams chosen = options;
      if (auto index = best_gpu(detail::probe_vulkan())) {
        chosen.device_index = options.device_index.value_or(*index);
        device_ = detail::create_vulkan_device(chosen);
      } else if (auto cl_index = best_gpu(detail::probe_opencl())) {
        chosen.device_index = options.device_index.value_or(*cl_index);
        device_ = detail::create_opencl_device(chosen);
      } else {
        device_ = cpu_device(options);
      }
      break;
    }
  }
}

Context Context::from_environment() { return Context(ContextParams::from_environment()); }
Context Context::cpu() {
  ContextParams options;
  options.backend = BackendChoice::cpu;
  return Context(options);
}

Context::Context(Context&&) noexcept = default;
Context& Context::operator=(Context&&) noexcept = default;
Context::~Context() = default;

// A moved-from Context has no device; using one is a programming error the accessors report.
detail::Device& Context::checked_device() const {
  require(device_ != nullptr, "compute context: used after it was moved from");
  return *device_;
}

BackendKind Context::backend() const { return checked_device().info().backend; }
const DeviceInfo& Context::device_info() const { return checked_device().info(); }
void Context::finish() const { checked_device().finish(); }
void Context::build_all_kernels() const { checked_device().build_all_kernels(); }
std::uint64_t Context::validation_errors() const { return checked_device().validation_errors(); }
bool Context::validation_active() const { return checked_device().validation_active(); }
std::vector<DeviceTiming> Context::take_device_timings() const {
  return checked_device().take_device_timings();
}

}  // namespace kartograf::compute
