// CPU wrapper of kernels/normals/normals.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/normals/normals.h"

namespace kartograf::kernels {

namespace {

void normals(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<NormalsParams>();
  const auto* points = call.buffer<const float4>(0);
  auto* normals = call.buffer<float4>(1);
  const int width = static_cast<int>(params.width);
  const int height = static_cast<int>(params.height);
  const auto at = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= width || y >= height) return KG_INVALID_POINT;
    return points[static_cast<std::size_t>(y) * params.width + static_cast<std::size_t>(x)];
  };
  compute::detail::for_each_chunk(
      params.height, std::size_t(params.width) * params.height,
      [&](std::size_t first, std::size_t last, std::size_t) {
        for (int y = static_cast<int>(first); y < static_cast<int>(last); ++y) {
          for (int x = 0; x < width; ++x) {
            normals[static_cast<std::size_t>(y) * params.width + static_cast<std::size_t>(x)] =
                normal_from_neighbours(at(x, y), at(x - 1, y), at(x + 1, y), at(x, y - 1),
                                       at(x, y + 1), params);
          }
        }
      });
}

}  // namespace

void register_normals_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("normals", normals);
}

}  // namespace kartograf::kernels
