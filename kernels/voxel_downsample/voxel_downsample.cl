// OpenCL wrapper of kernels/voxel_downsample/voxel_downsample.h (the six passes).
#include "kernels/voxel_downsample/voxel_downsample.h"

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
// Each lane scans a contiguous part, lane 0 scans the lanes' part sums.
__kernel void voxel_downsample_scan(__global uint* counts, const VoxelScanParams params) {
  __local uint part_offsets[KG_VOXEL_DOWNSAMPLE_LOCAL_X];
  const uint lane = get_local_id(0);
  const uint part = params.thread_count / KG_VOXEL_DOWNSAMPLE_LOCAL_X;
  const uint base = lane * part;
  uint sum = 0u;
  for (uint j = 0u; j < part; ++j) sum += counts[base + j];
  part_offsets[lane] = sum;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lane == 0u) {
    uint running = 0u;
    for (uint l = 0u; l < KG_VOXEL_DOWNSAMPLE_LOCAL_X; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = running;
      running += value;
    }
    counts[params.thread_count] = running;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  uint offset = part_offsets[lane];
  for (uint j = 0u; j < part; ++j) {
    const uint value = counts[base + j];
    counts[base + j] = offset;
    offset += value;
  }
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
