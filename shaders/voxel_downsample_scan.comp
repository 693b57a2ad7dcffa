#version 450
// Voxel downsampling, pass 3 of 6: one work-group turns the per-thread counts[0..thread_count)
// into exclusive prefix sums in place and writes the total to counts[thread_count]. Each lane
// scans a contiguous part (thread_count is a multiple of 64), lane 0 scans the 64 part sums.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer Counts { uint counts[]; };

layout(push_constant) uniform Params {
  uint thread_count;
} params;

shared uint part_offsets[64];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint part = params.thread_count / 64u;
  const uint base = lane * part;
  uint sum = 0u;
  for (uint j = 0u; j < part; ++j) sum += counts[base + j];
  part_offsets[lane] = sum;
  barrier();
  if (lane == 0u) {
    uint running = 0u;
    for (uint l = 0u; l < 64u; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = running;
      running += value;
    }
    counts[params.thread_count] = running;
  }
  barrier();
  uint offset = part_offsets[lane];
  for (uint j = 0u; j < part; ++j) {
    const uint value = counts[base + j];
    counts[base + j] = offset;
    offset += value;
  }
}
