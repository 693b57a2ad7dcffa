#version 450
// Vulkan wrapper of kernels/esdf/esdf3.h, the mark pass: one cell of a touched block per item.
#extension GL_GOOGLE_include_directive : require
#include "kernels/tsdf/tsdf_voxel.h"

layout(std430, binding = 0) readonly buffer Blocks { uint blocks[]; };
layout(std430, binding = 1) readonly buffer BlockKeys { uint64_t block_keys[]; };
layout(std430, binding = 2) readonly buffer Voxels { TsdfVoxel voxels[]; };
layout(std430, binding = 3) buffer Marks { uint marks[]; };

#define KG_ESDF3_MARK_PASS
#include "kernels/esdf/esdf3.h"

layout(local_size_x = KG_ESDF_LOCAL_X) in;
KG_PUSH_PARAMS(Esdf3Params);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  const uint side = 8u / params.cell_voxels;
  const uint cells = side * side * side;
  const uint block = blocks[i / cells];
  const int at = esdf3_mark_cell(block_keys[block], i % cells, params);
  if (at >= 0) marks[at] = esdf3_cell_mark(block, i % cells, params);
}
