#version 450
// Vulkan wrapper of kernels/region_grow/region_grow.h, pass 2 of 4: one work-group turns the
// segment counts per tile into exclusive prefix sums in place (each lane a contiguous part, lane
// 0 the 64 part sums) and writes the segment count to the status.
#extension GL_GOOGLE_include_directive : require
#include "kernels/region_grow/region_grow.h"

layout(local_size_x = KG_REGION_GROW_SCAN_LOCAL_X) in;

layout(std430, binding = 0) buffer TileCounts { uint tile_counts[]; };
layout(std430, binding = 1) buffer Status { uint status[]; };
KG_PUSH_PARAMS(RegionGrowParams);

shared uint part_offsets[KG_REGION_GROW_SCAN_LOCAL_X];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint part = params.padded_tile_count / KG_REGION_GROW_SCAN_LOCAL_X;
  const uint base = lane * part;
  uint sum = 0u;
  for (uint j = 0u; j < part; ++j) sum += tile_counts[base + j];
  part_offsets[lane] = sum;
  barrier();
  if (lane == 0u) {
    uint running = 0u;
    for (uint l = 0u; l < KG_REGION_GROW_SCAN_LOCAL_X; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = running;
      running += value;
    }
    status[KG_REGION_GROW_SEGMENT_COUNT] = running;
  }
  barrier();
  uint offset = part_offsets[lane];
  for (uint j = 0u; j < part; ++j) {
    const uint value = tile_counts[base + j];
    tile_counts[base + j] = offset;
    offset += value;
  }
}
