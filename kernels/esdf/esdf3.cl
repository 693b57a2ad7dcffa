// OpenCL wrapper of kernels/esdf/esdf3.h.
#include "kernels/esdf/esdf3.h"

__kernel void esdf3_mark(__global const uint* blocks, __global const ulong* block_keys,
                         __global const TsdfVoxel* voxels, __global uint* marks,
                         const Esdf3Params params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  const uint cells = (8u / params.cell_voxels) * (8u / params.cell_voxels) * (8u / params.cell_voxels);
  const uint block = blocks[i / cells];
  const int at = esdf3_mark_cell(block_keys[block], i % cells, params);
  if (at >= 0) marks[at] = esdf3_cell_mark(voxels, block, i % cells, params);
}

__kernel void esdf3_seed(__global const uint* marks, __global long* squared,
                         const Esdf3Params params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  const uint at = esdf3_box_cell(i, params.box_x, params.box_y, params.box_z, params.box_dims_x,
                                 params.box_dims_y, params);
  squared[i] = esdf3_seed_value(marks[at]);
}

__kernel void esdf3_write(__global const long* squared, __global float* distances,
                          const Esdf3Params params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  const uint at = esdf3_box_cell(i, params.box_x, params.box_y, params.box_z, params.box_dims_x,
                                 params.box_dims_y, params);
  distances[at] = esdf3_distance(squared[esdf3_outer_index(i, params)], params);
}
