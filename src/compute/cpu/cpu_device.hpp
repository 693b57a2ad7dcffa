#pragma once
// The CPU backend as a Device: buffers are host memory, and a dispatch runs the kernel's CPU
// wrapper (registered by name, see cpu_kernel.hpp) over the backend's threads. Commands run at
// once, in issue order, so nothing is ever pending.
#include <memory>

#include "compute/device.hpp"

namespace kartograf::compute::detail {

std::shared_ptr<Device> create_cpu_device();

}  // namespace kartograf::compute::detail
