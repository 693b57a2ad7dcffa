// OpenCL wrapper of kernels/voxel_downsample/voxel_downsample.h (the six passes).
#include "kernels/voxel_downsample/voxel_downsample.h"
#include "kernels/work_group/group_scan.h"

__kernel void voxel_downsample_insert(__global const float4* points, __global const float4* normals,
                                      __global ulong* keys, __global uint* first,
                                      __global int* point_slots, __global uint* status,
                                      const VoxelInsertParams params) {
  const uint i = get_global_id(0);
  if (i >= params.point_count) return;
  const float4 n = params.has_normals != 0u ? normals[i] : KG_INVALID_POINT;
  point_slots[i] = voxel_insert_point(keys, first, status, i, points[i], n, params);
}

__kernel void voxel_downsample_count(__global const int* point_slots, __global const uint* first,
                                     __global uint* counts, const VoxelChunkParams params) {
  const uint t = get_global_id(0);
  counts[t] = voxel_count_first_points(point_slots, first, t, params);
}

// One work-group: exclusive prefix sums of counts[0..thread_count) in place, the total after them.
__kernel void voxel_downsample_scan(__global uint* counts, const VoxelScanParams params) {
  __local uint part_offsets[KG_GROUP_SCAN_LANES];
  const uint total = kg_group_exclusive_scan(counts, part_offsets, params.thread_count);
  if (get_local_id(0) == 0u) counts[params.thread_count] = total;
}

__kernel void voxel_downsample_assign(__global const int* point_slots, __global const uint* first,
                                      __global const uint* counts, __global const ulong* keys,
                                      __global uint* voxel_of_slot, __global ulong* voxel_keys,
                                      const VoxelChunkParams params) {
  voxel_assign_chunk(point_slots, first, counts, keys, voxel_of_slot, voxel_keys, get_global_id(0),
                     params);
}

__kernel void voxel_downsample_accumulate(__global const float4* points, __global const float4* normals,
                                          __global const uint* colors, __global const int* point_slots,
                                          __global const uint* voxel_of_slot, __global long* sums,
                                          const VoxelSumParams params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  const int slot = point_slots[i];
  if (slot < 0) return;
  long terms[KG_VOXEL_MAX_SUMS];
  voxel_point_terms_at(points, normals, colors, terms, i, params);
  const uint base = voxel_of_slot[slot] * params.stride;
  for (uint k = 0u; k < KG_VOXEL_MAX_SUMS; ++k) {  // unrolled: terms stays in registers
    if (k < params.stride && terms[k] != 0L) atom_add(&sums[base + k], terms[k]);
  }
}

__kernel void voxel_downsample_finalize(__global const ulong* voxel_keys, __global const long* sums,
                                        __global float4* out_points, __global float4* out_normals,
                                        __global uint* out_colors, const VoxelSumParams params) {
  const uint v = get_global_id(0);
  if (v < params.count) {
    voxel_finalize(voxel_keys, sums, out_points, out_normals, out_colors, v, params);
  }
}
