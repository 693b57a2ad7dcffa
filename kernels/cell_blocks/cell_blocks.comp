#version 450
// Vulkan wrapper of kernels/cell_blocks/cell_blocks.h: one block per invocation.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Colours { uint colours[]; };
layout(std430, binding = 2) writeonly buffer Sums { float sums[]; };
layout(std430, binding = 3) writeonly buffer Counts { uint counts[]; };
layout(std430, binding = 4) buffer Masks { uint masks[]; };

#include "kernels/cell_blocks/cell_blocks.h"

layout(local_size_x = KG_CELL_BLOCKS_LOCAL_X) in;
KG_PUSH_PARAMS(CellBlocksParams);

void main() {
  const uint block = gl_GlobalInvocationID.x;
  if (block >= params.block_count) return;
  cell_block_measure(block, params);
}
