#version 450
// Vulkan wrapper of kernels/voxel_downsample/voxel_downsample.h, pass 5 (accumulate).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Normals { vec4 normals[]; };  // optional
layout(std430, binding = 2) readonly buffer Colors { uint colors[]; };    // optional
layout(std430, binding = 3) readonly buffer PointSlots { int point_slots[]; };
layout(std430, binding = 4) readonly buffer VoxelOfSlot { uint voxel_of_slot[]; };
layout(std430, binding = 5) buffer Sums { int64_t sums[]; };

// After the buffers: the rule reads them (and declares the invocation's terms[]).
#define KG_VOXEL_ACCUMULATE_PASS
#include "kernels/voxel_downsample/voxel_downsample.h"

layout(local_size_x = KG_VOXEL_DOWNSAMPLE_LOCAL_X) in;
KG_PUSH_PARAMS(VoxelSumParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  const int slot = point_slots[i];
  if (slot < 0) return;
  voxel_point_terms_at(i, params);
  const uint base = voxel_of_slot[slot] * params.stride;
  for (uint k = 0u; k < KG_VOXEL_MAX_SUMS; ++k) {  // unrolled: terms stays in registers
    if (k < params.stride && terms[k] != 0l) atomicAdd(sums[base + k], terms[k]);
  }
}
