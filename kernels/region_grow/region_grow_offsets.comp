#version 450
// Vulkan wrapper of kernels/region_grow/region_grow.h, pass 3 of 4: every labelled pixel's
// tile-local segment number plus its tile's offset gives the segment's number in the image.
#extension GL_GOOGLE_include_directive : require
#include "kernels/region_grow/region_grow.h"

layout(local_size_x = KG_REGION_GROW_OFFSETS_LOCAL_X) in;

layout(std430, binding = 0) buffer Labels { uint labels[]; };
layout(std430, binding = 1) readonly buffer TileOffsets { uint tile_offsets[]; };
KG_PUSH_PARAMS(RegionGrowParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.width * params.height || labels[i] == KG_NO_LABEL) return;
  const uint x = i % params.width, y = i / params.width;
  labels[i] += tile_offsets[(y / params.tile_size) * params.tiles_x + x / params.tile_size];
}
