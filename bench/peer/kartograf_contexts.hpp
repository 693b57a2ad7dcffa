#pragma once
// Kartograf's compute contexts for the peer benchmark: the CPU backend, and every device backend
// the machine offers (here CPU-hosted drivers: lavapipe, PoCL), shared by the registration and
// plane parts so that both label device rows the same way.
#include <memory>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"

namespace kartograf::peer {

using ContextPtr = std::shared_ptr<const compute::Context>;

ContextPtr make_context(compute::BackendChoice backend);

struct DeviceContext {
  ContextPtr context;
  std::string label;  // "vulkan: llvmpipe (LLVM 15.0.6, 256 bits)"
};
// The available Vulkan and OpenCL backends, each on its best device.
std::vector<DeviceContext> device_contexts();

}  // namespace kartograf::peer
