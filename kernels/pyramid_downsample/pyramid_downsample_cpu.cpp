// CPU wrapper of kernels/pyramid_downsample/pyramid_downsample.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/pyramid_downsample/pyramid_downsample.h"

namespace kartograf::kernels {

namespace {

void pyramid_downsample(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<PyramidDownsampleParams>();
  const auto* fine_points = call.buffer<const float4>(0);
  const auto* fine_colors = call.buffer<const uint>(1);
  auto* coarse_points = call.buffer<float4>(2);
  auto* coarse_colors = call.buffer<uint>(3);
  const std::size_t fine_width = params.fine_width;
  compute::detail::for_each_chunk(
      params.coarse_height, std::size_t(params.coarse_width) * params.coarse_height,
      [&](std::size_t first, std::size_t last, std::size_t) {
        for (std::size_t y = first; y < last; ++y) {
          for (std::size_t x = 0; x < params.coarse_width; ++x) {
            const std::size_t i0 = 2 * y * fine_width + 2 * x;
            const std::size_t i2 = i0 + fine_width;
            const float4 p0 = fine_points[i0], p1 = fine_points[i0 + 1];
            const float4 p2 = fine_points[i2], p3 = fine_points[i2 + 1];
            const uint members = pyramid_block_members(p0, p1, p2, p3, params.max_depth_jump);
            const std::size_t index = y * params.coarse_width + x;
            coarse_points[index] = pyramid_block_point(p0, p1, p2, p3, members);
            if (params.has_colors == 0) continue;
            coarse_colors[index] =
                pyramid_block_color(fine_colors[i0], fine_colors[i0 + 1], fine_colors[i2],
                                    fine_colors[i2 + 1], members);
          }
        }
      });
}

}  // namespace

void register_pyramid_downsample_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("pyramid_downsample", pyramid_downsample);
}

}  // namespace kartograf::kernels
