#version 450
// Vulkan wrapper of kernels/voxel_downsample/voxel_downsample.h, pass 6 (finalize).
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer VoxelKeys { uint64_t voxel_keys[]; };
layout(std430, binding = 1) readonly buffer Sums { int64_t sums[]; };
layout(std430, binding = 2) writeonly buffer OutPoints { vec4 out_points[]; };
layout(std430, binding = 3) writeonly buffer OutNormals { vec4 out_normals[]; };  // optional
layout(std430, binding = 4) writeonly buffer OutColors { uint out_colors[]; };    // optional

// After the buffers: the rule reads and writes them.
#define KG_VOXEL_FINALIZE_PASS
#include "kernels/voxel_downsample/voxel_downsample.h"

layout(local_size_x = KG_VOXEL_DOWNSAMPLE_LOCAL_X) in;
KG_PUSH_PARAMS(VoxelSumParams);

void main() {
  const uint v = gl_GlobalInvocationID.x;
  if (v < params.count) voxel_finalize(v, params);
}
