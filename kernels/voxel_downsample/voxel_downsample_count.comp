#version 450
// Vulkan wrapper of kernels/voxel_downsample/voxel_downsample.h, pass 2 (count).
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer PointSlots { int point_slots[]; };
layout(std430, binding = 1) readonly buffer First { uint first[]; };
layout(std430, binding = 2) writeonly buffer Counts { uint counts[]; };

// After the buffers: the rule reads them.
#define KG_VOXEL_ORDER_PASS
#include "kernels/voxel_downsample/voxel_downsample.h"

layout(local_size_x = KG_VOXEL_DOWNSAMPLE_LOCAL_X) in;
KG_PUSH_PARAMS(VoxelChunkParams);

void main() {
  const uint t = gl_GlobalInvocationID.x;
  counts[t] = voxel_count_first_points(t, params);
}
