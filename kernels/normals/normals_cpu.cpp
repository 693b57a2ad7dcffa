// CPU wrapper of kernels/normals/normals.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/normals/normals.h"

namespace kartograf::kernels {

namespace {

// One row: interior pixels read their neighbours directly, the border ones through `at` (NaN
// outside the image, as the shader's point_at).
template <class At>
void normals_row(const float4* points, int width, int height, int y, NormalsParams params,
                 const At& at, float4* out) {
  const float4* row = points + static_cast<std::size_t>(y) * params.width;
  const bool interior_row = y > 0 && y + 1 < height;
  const std::ptrdiff_t stride = width;
  for (int x = 0; x < width; ++x) {
    const float4 centre = row[x];
    if (kg_isnan(centre.x)) {  // the rule's first test, before any neighbour is read
      out[x] = KG_INVALID_POINT;
    } else if (interior_row && x > 0 && x + 1 < width) {
      out[x] = normal_from_neighbours(centre, row[x - 1], row[x + 1], row[x - stride],
                                      row[x + stride], params);
    } else {
      out[x] = normal_from_neighbours(centre, at(x - 1, y), at(x + 1, y), at(x, y - 1),
                                      at(x, y + 1), params);
    }
  }
}

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
          normals_row(points, width, height, y, params, at,
                      normals + static_cast<std::size_t>(y) * params.width);
        }
      });
}

}  // namespace

void register_normals_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("normals", normals);
}

}  // namespace kartograf::kernels
