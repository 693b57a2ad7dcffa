#version 450
// Vulkan wrapper of kernels/tsdf/tsdf.h, pass 1 (touch).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Depth { uint depth_pairs[]; };  // two uint16 per word
layout(std430, binding = 1) buffer Keys { uint64_t keys[]; };
layout(std430, binding = 2) buffer Stamps { uint stamps[]; };
layout(std430, binding = 3) buffer Status { uint status[]; };  // KG_TSDF_STATUS_*

// After the buffers: the rule reads and writes them.
#define KG_VOXEL_HASH_INSERT
#define KG_TSDF_TOUCH_PASS
#include "kernels/tsdf/tsdf.h"

layout(local_size_x = KG_TSDF_LOCAL_2D, local_size_y = KG_TSDF_LOCAL_2D) in;
KG_PUSH_PARAMS(TsdfParams);

void main() {
  const uint x = gl_GlobalInvocationID.x * params.step;
  const uint y = gl_GlobalInvocationID.y * params.step;
  if (x >= params.width || y >= params.height) return;
  const uint index = y * params.width + x;
  const uint d = (depth_pairs[index >> 1] >> ((index & 1u) * 16u)) & 0xffffu;
  tsdf_touch_pixel(x, y, d, params);
}
