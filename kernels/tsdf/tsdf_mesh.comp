#version 450
// Vulkan wrapper of kernels/tsdf/tsdf_mesh.h: one cell per item.
#extension GL_GOOGLE_include_directive : require
#include "kernels/tsdf/tsdf_voxel.h"

layout(std430, binding = 0) readonly buffer Keys { uint64_t keys[]; };
layout(std430, binding = 1) readonly buffer SlotBlocks { uint slot_blocks[]; };
layout(std430, binding = 2) readonly buffer BlockKeys { uint64_t block_keys[]; };
layout(std430, binding = 3) readonly buffer Voxels { TsdfVoxel voxels[]; };
layout(std430, binding = 4) buffer Status { uint status[]; };  // [0]: triangles wanted
layout(std430, binding = 5) writeonly buffer Order { uint order[]; };
layout(std430, binding = 6) writeonly buffer EdgeKeys { uint64_t edge_keys[]; };
layout(std430, binding = 7) writeonly buffer Points { float points[]; };
layout(std430, binding = 8) writeonly buffer Colors { uint colors[]; };

#define KG_VOXEL_HASH_FIND
#define KG_TSDF_MESH_PASS
#include "kernels/tsdf/tsdf_mesh.h"

layout(local_size_x = KG_TSDF_LOCAL_X) in;
KG_PUSH_PARAMS(TsdfMeshParams);

void main() {
  const uint cell = gl_GlobalInvocationID.x;
  if (cell >= params.count) return;
  tsdf_mesh_cell(cell, params);
}
