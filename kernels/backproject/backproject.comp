#version 450
// Vulkan wrapper of kernels/backproject/backproject.h.
#extension GL_GOOGLE_include_directive : require
#include "kernels/backproject/backproject.h"

layout(local_size_x = KG_BACKPROJECT_LOCAL_X, local_size_y = KG_BACKPROJECT_LOCAL_Y) in;

layout(std430, binding = 0) readonly buffer Depth { uint depth_pairs[]; };  // two uint16 per word
layout(std430, binding = 1) readonly buffer Factors { float factors[]; };   // columns, then rows
layout(std430, binding = 2) writeonly buffer Points { vec4 points[]; };
KG_PUSH_PARAMS(BackprojectParams);

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= params.width || pixel.y >= params.height) return;
  const uint index = pixel.y * params.width + pixel.x;
  const uint d = (depth_pairs[index >> 1] >> ((index & 1u) * 16u)) & 0xffffu;
  points[index] =
      backproject_depth(d, factors[pixel.x], factors[params.width + pixel.y], params);
}
