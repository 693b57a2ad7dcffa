// OpenCL wrapper of kernels/voxel_hash_nearest/voxel_hash_nearest.h.
#include "kernels/voxel_hash_nearest/voxel_hash_nearest.h"

__kernel void voxel_hash_nearest(__global const float4* source, __global const float4* source_normals,
                                 __global const float4* target_normals,
                                 __global const ulong* cell_keys, __global const uint2* cell_ranges,
                                 __global const float4* cell_points,
                                 __global const uint* cell_indices, __global const double* frame,
                                 __global int* correspondences, const VoxelHashNearestParams params) {
  const uint i = get_global_id(0);
  if (i >= params.source_count) return;
  correspondences[i] =
      voxel_hash_nearest_item(source, source_normals, target_normals, cell_keys, cell_ranges,
                              cell_points, cell_indices, frame, i, params);
}
