#version 450
// Parallel Lab region growing, pass 3 of 6: roots per block of KG_PIXELS_PER_BLOCK pixels
// (blocks past the image, up to the padded block_count, count 0).
#extension GL_GOOGLE_include_directive : require
#include "region_grow.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Parent { uint parent[]; };
layout(std430, binding = 1) writeonly buffer BlockCounts { uint block_counts[]; };

void main() {
  const uint block = gl_GlobalInvocationID.x;
  if (block >= params.block_count) return;
  const uint begin = min(block * KG_PIXELS_PER_BLOCK, params.pixel_count);
  const uint end = min(begin + KG_PIXELS_PER_BLOCK, params.pixel_count);
  uint roots = 0u;
  for (uint i = begin; i < end; ++i) roots += parent[i] == i ? 1u : 0u;
  block_counts[block] = roots;
}
