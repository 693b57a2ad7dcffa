#version 450
// Parallel Lab region growing, pass 5 of 6: roots get consecutive labels in scan order, starting
// at their block's offset.
#extension GL_GOOGLE_include_directive : require
#include "region_grow.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Parent { uint parent[]; };
layout(std430, binding = 1) readonly buffer BlockCounts { uint block_offsets[]; };
layout(std430, binding = 2) writeonly buffer Labels { uint labels[]; };

void main() {
  const uint block = gl_GlobalInvocationID.x;
  if (block >= params.block_count) return;
  const uint begin = min(block * KG_PIXELS_PER_BLOCK, params.pixel_count);
  const uint end = min(begin + KG_PIXELS_PER_BLOCK, params.pixel_count);
  uint next = block_offsets[block];
  for (uint i = begin; i < end; ++i) {
    if (parent[i] == i) labels[i] = next++;
  }
}
