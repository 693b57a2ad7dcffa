// CPU wrapper of kernels/laser_scan/laser_scan.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/laser_scan/laser_scan.h"

namespace kartograf::kernels {

namespace {

void laser_scan(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<LaserScanParams>();
  const auto* skips = call.buffer<const int>(0);
  const auto* directions = call.buffer<const int2>(1);
  const auto* cells = call.buffer<const int2>(2);
  auto* steps = call.buffer<int>(3);
  compute::detail::for_each_chunk(
      params.item_count, std::size_t(params.item_count) * params.beams_per_item,
      [&](std::size_t first, std::size_t last, std::size_t) {
        for (std::size_t item = first; item < last; ++item) {
          laser_scan_item(skips, directions, cells, steps, static_cast<uint>(item), params);
        }
      });
}

}  // namespace

void register_laser_scan_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("laser_scan", laser_scan);
}

}  // namespace kartograf::kernels
