#version 450
// Tiled Lab region growing, pass 3 of 3: every labelled pixel's tile-local segment number plus
// its tile's offset gives the segment's number in the whole image.
#extension GL_GOOGLE_include_directive : require
#include "region_grow.glsl"

layout(local_size_x = 256) in;

layout(std430, binding = 0) buffer Labels { uint labels[]; };
layout(std430, binding = 1) readonly buffer TileCounts { uint tile_offsets[]; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.width * params.height || labels[i] == KG_NO_LABEL) return;
  const uint x = i % params.width, y = i / params.width;
  labels[i] += tile_offsets[(y / params.tile_size) * params.tiles_x + x / params.tile_size];
}
