#version 450
// Voxel downsampling, pass 4 of 6: thread t walks its points in order and numbers the voxels
// whose first point it meets from its scanned offset on: output voxel v is the v-th voxel in the
// order of first points. Writes the voxel number per slot and the key per voxel.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer PointSlots { int point_slots[]; };
layout(std430, binding = 1) readonly buffer First { uint first[]; };
layout(std430, binding = 2) readonly buffer Counts { uint counts[]; };  // scanned offsets
layout(std430, binding = 3) readonly buffer Keys { uint64_t keys[]; };
layout(std430, binding = 4) writeonly buffer VoxelOfSlot { uint voxel_of_slot[]; };
layout(std430, binding = 5) writeonly buffer VoxelKeys { uint64_t voxel_keys[]; };

layout(push_constant) uniform Params {
  uint point_count;
  uint chunk;
} params;

#include "voxel_first.glsl"

void main() {
  const uint t = gl_GlobalInvocationID.x;
  const uint begin = min(t * params.chunk, params.point_count);
  const uint end = min(begin + params.chunk, params.point_count);
  uint voxel = counts[t];
  for (uint i = begin; i < end; ++i) {
    if (!is_first_of_voxel(i)) continue;
    const uint slot = uint(point_slots[i]);
    voxel_of_slot[slot] = voxel;
    voxel_keys[voxel] = keys[slot];
    ++voxel;
  }
}
