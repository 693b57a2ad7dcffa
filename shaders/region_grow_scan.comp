#version 450
// Tiled Lab region growing, pass 2 of 3: one work-group turns the segment counts per tile into
// exclusive prefix sums in place (each lane a contiguous part, lane 0 the 64 part sums) and
// writes the segment count to status[0].
#extension GL_GOOGLE_include_directive : require
#include "region_grow.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer TileCounts { uint tile_counts[]; };
layout(std430, binding = 1) buffer Status { uint status[]; };

shared uint part_offsets[64];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint part = params.padded_tile_count / 64u;
  const uint base = lane * part;
  uint sum = 0u;
  for (uint j = 0u; j < part; ++j) sum += tile_counts[base + j];
  part_offsets[lane] = sum;
  barrier();
  if (lane == 0u) {
    uint running = 0u;
    for (uint l = 0u; l < 64u; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = running;
      running += value;
    }
    status[0] = running;
  }
  barrier();
  uint offset = part_offsets[lane];
  for (uint j = 0u; j < part; ++j) {
    const uint value = tile_counts[base + j];
    tile_counts[base + j] = offset;
    offset += value;
  }
}
