// CPU wrapper of kernels/backproject/backproject.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/backproject/backproject.h"

namespace kartograf::kernels {

namespace {

void backproject(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<BackprojectParams>();
  const auto* depth = call.buffer<const std::uint16_t>(0);
  const auto* factors = call.buffer<const float>(1);
  auto* points = call.buffer<float4>(2);
  // Rows in chunks.
  compute::detail::for_each_chunk(params.height, std::size_t(params.width) * params.height,
                                  [&](std::size_t first, std::size_t last, std::size_t) {
                                    // Copies the point stores cannot alias: the loop keeps them in
                                    // registers.
                                    const BackprojectParams p = params;
                                    const std::size_t width = p.width;
                                    const std::uint16_t* const in = depth;
                                    float4* const out = points;
                                    for (std::size_t y = first; y < last; ++y) {
                                      const std::size_t row = y * width;
                                      const float row_factor = factors[width + y];
                                      for (std::size_t x = 0; x < width; ++x) {
                                        out[row + x] = backproject_depth(in[row + x], factors[x],
                                                                         row_factor, p);
                                      }
                                    }
                                  });
}

}  // namespace

void register_backproject_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("backproject", backproject);
}

}  // namespace kartograf::kernels
