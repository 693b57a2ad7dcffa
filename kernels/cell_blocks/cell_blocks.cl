// OpenCL wrapper of kernels/cell_blocks/cell_blocks.h: one block per work-item.
#include "kernels/cell_blocks/cell_blocks.h"

__kernel void cell_blocks(__global const float4* points, __global const uint* colours,
                          __global float* sums, __global uint* counts, __global uint* masks,
                          const CellBlocksParams params) {
  const uint block = get_global_id(0);
  if (block >= params.block_count) return;
  cell_block_measure(points, colours, sums, counts, masks, block, params);
}
