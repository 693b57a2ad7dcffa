// CPU wrapper of kernels/voxel_hash_nearest/voxel_hash_nearest.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/voxel_hash_nearest/voxel_hash_nearest.h"

namespace kartograf::kernels {

namespace {

void voxel_hash_nearest(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<VoxelHashNearestParams>();
  const auto* source = call.buffer<const float4>(0);
  const auto* source_normals = call.buffer<const float4>(1);
  const auto* target_normals = call.buffer<const float4>(2);
  const auto* cell_keys = call.buffer<const uint64_t>(3);
  const auto* cell_ranges = call.buffer<const uint2>(4);
  const auto* cell_points = call.buffer<const float4>(5);
  const auto* cell_indices = call.buffer<const uint>(6);
  const auto* frame = call.buffer<const double>(7);
  auto* correspondences = call.buffer<int>(8);
  compute::detail::for_each_item(call, [&](uint i) {
    if (i >= params.source_count) return;
    correspondences[i] =
        voxel_hash_nearest_item(source, source_normals, target_normals, cell_keys, cell_ranges,
                                cell_points, cell_indices, frame, i, params);
  });
}

}  // namespace

void register_voxel_hash_nearest_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("voxel_hash_nearest", voxel_hash_nearest);
}

}  // namespace kartograf::kernels
