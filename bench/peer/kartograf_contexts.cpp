#include "kartograf_contexts.hpp"

#include "kartograf/compute/backend.hpp"

namespace kartograf::peer {

ContextPtr make_context(compute::BackendChoice backend) {
  compute::ContextParams options;
  options.backend = backend;
  return std::make_shared<const compute::Context>(options);
}

std::vector<DeviceContext> device_contexts() {
  std::vector<DeviceContext> contexts;
  for (const auto& status : compute::probe_backends()) {
    if (status.backend == compute::BackendKind::cpu || !status.available) continue;
    const auto choice = status.backend == compute::BackendKind::vulkan
                            ? compute::BackendChoice::vulkan
                            : compute::BackendChoice::opencl;
    ContextPtr context = make_context(choice);
    std::string label =
        std::string(compute::to_string(status.backend)) + ": " + context->device_info().name;
    contexts.push_back({std::move(context), std::move(label)});
  }
  return contexts;
}

}  // namespace kartograf::peer
