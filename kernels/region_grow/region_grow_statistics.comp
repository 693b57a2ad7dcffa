#version 450
// Vulkan wrapper of kernels/region_grow/region_grow.h, pass 4 of 4 (measuring only): each slot
// of a segment that exists moves its statistics to the segment's place in label order.
#extension GL_GOOGLE_include_directive : require
#include "kernels/region_grow/region_grow.h"

layout(local_size_x = KG_REGION_GROW_STATISTICS_LOCAL_X) in;

layout(std430, binding = 0) readonly buffer TileOffsets { uint tile_offsets[]; };
layout(std430, binding = 1) readonly buffer Status { uint status[]; };
layout(std430, binding = 2) readonly buffer Slots { double slots[]; };
layout(std430, binding = 3) writeonly buffer Statistics { double statistics[]; };
KG_PUSH_PARAMS(RegionGrowParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.tile_count * params.slots_per_tile) return;
  const uint t = i / params.slots_per_tile, segment = i % params.slots_per_tile;
  const uint first = tile_offsets[t];
  const uint end = t + 1u < params.tile_count ? tile_offsets[t + 1u]
                                              : status[KG_REGION_GROW_SEGMENT_COUNT];
  if (first + segment >= end) return;
  const uint slot = region_statistics_slot(t, segment, params);
  const uint target = (first + segment) * KG_REGION_GROW_STATISTICS;
  for (uint v = 0u; v < KG_REGION_GROW_STATISTICS; ++v) statistics[target + v] = slots[slot + v];
}
