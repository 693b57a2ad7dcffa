// CPU wrapper of kernels/projective_association/projective_association.h: walks the selected
// points row by row (no modulo per point); chunks of rows run in parallel.
#include <algorithm>

#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/projective_association/projective_association.h"

namespace kartograf::kernels {

namespace {

void projective_association(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<ProjectiveAssociationParams>();
  const auto* source = call.buffer<const float4>(0);
  const auto* source_normals = call.buffer<const float4>(1);
  const auto* target = call.buffer<const float4>(2);
  const auto* target_normals = call.buffer<const float4>(3);
  const auto* frame = call.buffer<const float>(4);
  auto* out = call.buffer<int>(5);
  const std::size_t count = params.source_count;
  const std::size_t row_length = params.source_width == 0 ? count : params.source_width;
  const std::size_t rows = (count + row_length - 1) / row_length;
  const std::size_t k = params.subsample;
  const float4 no_normal{0.0f, 0.0f, 0.0f, 0.0f};
  compute::detail::for_each_chunk(
      rows, count, [&](std::size_t first, std::size_t last, std::size_t) {
        for (std::size_t row = first; row < last; ++row) {
          const std::size_t start = row * row_length;
          const std::size_t end = std::min(count, start + row_length);
          std::fill(out + start, out + end, KG_ASSOCIATION_NOT_SELECTED);
          // The first i >= start with (i + row) % k == 0 (correspondence_selected), then every k-th.
          for (std::size_t i = start + (k - (start + row) % k) % k; i < end; i += k) {
            const float4 normal = params.use_normals != 0 ? source_normals[i] : no_normal;
            out[i] = projective_associate(target, target_normals, frame, source[i], normal, params);
          }
        }
      });
}

}  // namespace

void register_projective_association_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("projective_association", projective_association);
}

}  // namespace kartograf::kernels
