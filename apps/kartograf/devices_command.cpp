#include <ostream>

#include "commands.hpp"

namespace kartograf::cli {

namespace {

std::string memory_mib(std::uint64_t bytes) {
  if (bytes == 0) return "unknown";
  return std::to_string(bytes / (1024 * 1024)) + " MiB";
}

void print_device(std::ostream& out, const compute::DeviceInfo& device, int usable_index) {
  // Indices count usable devices only: the numbering KARTOGRAF_DEVICE uses.
  if (device.usable) {
    out << "  [" << usable_index << "] " << device.name << "\n";
  } else {
    out << "  [-] " << device.name << "\n";
  }
  out << "      type:           " << compute::to_string(device.type) << "\n"
      << "      api:            " << device.api_version << "\n"
      << "      driver:         " << device.driver << "\n"
      << "      memory:         " << memory_mib(device.memory_bytes) << "\n"
      << "      unified memory: " << (device.unified_memory ? "yes" : "no") << "\n"
      << "      limits:         " << compute::describe(device.limits) << "\n";
  if (!device.usable) out << "      not usable:     " << device.unusable_reason << "\n";
}

}  // namespace

int run_devices_command(std::ostream& out) {
  for (const compute::BackendStatus& backend : compute::probe_backends()) {
    out << compute::to_string(backend.backend) << ": ";
    if (!backend.available) {
      out << "unavailable: " << backend.reason << "\n";
      continue;
    }
    out << "available, " << backend.devices.size()
        << (backend.devices.size() == 1 ? " device\n" : " devices\n");
    int usable_index = 0;
    for (const compute::DeviceInfo& device : backend.devices) {
      print_device(out, device, usable_index);
      if (device.usable) ++usable_index;
    }
  }
  return 0;
}

void print_backend_summary(std::ostream& out, const std::vector<compute::BackendStatus>& backends) {
  for (const compute::BackendStatus& backend : backends) {
    out << "  " << compute::to_string(backend.backend) << ": ";
    if (!backend.available) {
      out << "unavailable: " << backend.reason << "\n";
      continue;
    }
    out << "available";
    if (backend.devices.empty()) out << ", no devices";
    for (std::size_t i = 0; i < backend.devices.size(); ++i) {
      const compute::DeviceInfo& device = backend.devices[i];
      out << (i == 0 ? ": " : "; ") << device.name << " [" << compute::to_string(device.type)
          << (device.usable ? "" : ", not usable") << "]";
    }
    out << "\n";
  }
}

}  // namespace kartograf::cli
