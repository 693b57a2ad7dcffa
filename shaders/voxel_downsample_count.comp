#version 450
// Voxel downsampling, pass 2 of 6: thread t counts the first points of voxels among points
// [t * chunk, (t + 1) * chunk), the input of the scan that orders voxels by their first point.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer PointSlots { int point_slots[]; };
layout(std430, binding = 1) readonly buffer First { uint first[]; };
layout(std430, binding = 2) writeonly buffer Counts { uint counts[]; };

layout(push_constant) uniform Params {
  uint point_count;
  uint chunk;
} params;

#include "voxel_first.glsl"

void main() {
  const uint t = gl_GlobalInvocationID.x;
  const uint begin = min(t * params.chunk, params.point_count);
  const uint end = min(begin + params.chunk, params.point_count);
  uint count = 0u;
  for (uint i = begin; i < end; ++i) count += is_first_of_voxel(i) ? 1u : 0u;
  counts[t] = count;
}
