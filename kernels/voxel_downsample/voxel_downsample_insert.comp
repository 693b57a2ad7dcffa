#version 450
// Vulkan wrapper of kernels/voxel_downsample/voxel_downsample.h, pass 1 (insert).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Normals { vec4 normals[]; };  // optional
layout(std430, binding = 2) buffer Keys { uint64_t keys[]; };
layout(std430, binding = 3) buffer First { uint first[]; };
layout(std430, binding = 4) writeonly buffer PointSlots { int point_slots[]; };
layout(std430, binding = 5) buffer Status { uint status[]; };  // KG_VOXEL_STATUS_*

// After the buffers: the rule reads and writes them.
#define KG_VOXEL_INSERT_PASS
#define KG_VOXEL_HASH_INSERT
#include "kernels/voxel_downsample/voxel_downsample.h"

layout(local_size_x = KG_VOXEL_DOWNSAMPLE_LOCAL_X) in;
KG_PUSH_PARAMS(VoxelInsertParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.point_count) return;
  const vec4 n = params.has_normals != 0u ? normals[i] : KG_INVALID_POINT;
  point_slots[i] = voxel_insert_point(i, points[i], n, params);
}
