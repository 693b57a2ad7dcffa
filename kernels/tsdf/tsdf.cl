// OpenCL wrapper of kernels/tsdf/tsdf.h.
#include "kernels/tsdf/tsdf.h"
#include "kernels/tsdf/tsdf_band.h"
#include "kernels/tsdf/tsdf_mesh.h"

__kernel void tsdf_touch(__global const ushort* depth, __global ulong* keys, __global uint* stamps,
                         __global uint* status, const TsdfParams params) {
  const uint x = get_global_id(0) * params.step;
  const uint y = get_global_id(1) * params.step;
  if (x >= params.width || y >= params.height) return;
  tsdf_touch_pixel(keys, stamps, status, x, y, depth[y * params.width + x], params);
}

__kernel void tsdf_assign(__global const ulong* keys, __global uint* slot_blocks,
                          __global ulong* block_keys, __global const uint* stamps,
                          __global uint* active_blocks, __global uint* status,
                          const TsdfParams params) {
  const uint slot = get_global_id(0);
  if (slot >= params.count) return;
  tsdf_assign_slot(keys, slot_blocks, block_keys, stamps, active_blocks, status, slot, params);
}

__kernel void tsdf_integrate(__global const ushort* depth, __global const uint* colors,
                             __global const uint* active_blocks, __global const ulong* block_keys,
                             __global TsdfVoxel* voxels, const TsdfParams params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  const TsdfVoxelView view = tsdf_voxel_view(active_blocks, block_keys, i, params);
  if (view.pixel < 0 || !tsdf_fuses(depth[view.pixel], view.z, params)) return;
  const uint color = params.has_color != 0u ? colors[view.pixel] : 0u;
  voxels[view.voxel] = tsdf_fuse(voxels[view.voxel], depth[view.pixel], view.z, color, params);
}

__kernel void tsdf_raycast(__global const ulong* keys, __global const uint* slot_blocks,
                           __global const TsdfVoxel* voxels, __global float4* points,
                           __global uint* colors, __global const uint* ranges,
                           const TsdfParams params) {
  const uint x = get_global_id(0);
  const uint y = get_global_id(1);
  if (x >= params.width || y >= params.height) return;
  const uint index = y * params.width + x;
  const float min_depth = (float)params.min_units * params.metres_per_unit;
  const float max_depth = (float)params.max_units * params.metres_per_unit;
  const TsdfDepthSpan span = tsdf_ray_span(ranges, x, y, min_depth, max_depth, params);
  const float4 p = tsdf_cast_ray(keys, slot_blocks, voxels, x, y, span.near, span.far, params);
  points[index] = p;
  if (params.has_color != 0u) colors[index] = tsdf_color_at(keys, slot_blocks, voxels, p, params);
}

__kernel void tsdf_range(__global const ulong* block_keys, __global uint* ranges,
                         const TsdfParams params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  tsdf_range_block(ranges, block_keys[i], params);
}

__kernel void tsdf_band(__global const ulong* block_keys, __global const TsdfVoxel* voxels,
                        __global uint* cells, const TsdfBandParams params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  const TsdfBandMark mark = tsdf_band_mark(voxels[i], block_keys[i / KG_TSDF_BLOCK_VOXELS],
                                           i % KG_TSDF_BLOCK_VOXELS, params);
  if (mark.cell >= 0) kg_atomic_max_u32(cells, (uint)mark.cell, mark.state);
}

__kernel void tsdf_mesh(__global const ulong* keys, __global const uint* slot_blocks,
                        __global const ulong* block_keys, __global const TsdfVoxel* voxels,
                        __global uint* status, __global uint* order, __global ulong* edge_keys,
                        __global float* points, __global uint* colors,
                        const TsdfMeshParams params) {
  const uint cell = get_global_id(0);
  if (cell >= params.count) return;
  tsdf_mesh_cell(keys, slot_blocks, block_keys, voxels, status, order, edge_keys, points, colors,
                 cell, params);
}
