#version 450
// Voxel downsampling, pass 1 of 6 (src/geometry/voxel_downsample.cpp): each valid point inserts
// its voxel key into the hash table (compare-and-swap, linear probing), records its slot, and
// keeps the lowest point index per slot (as 0xffffffff - i with atomicMax, 0 = none yet). Also
// counts the errors the host reports: voxels out of range, a full table, non-unit normals.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_int64 : require
#include "common.glsl"
#include "voxel_hash.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Normals { vec4 normals[]; };  // optional
layout(std430, binding = 2) buffer Keys { uint64_t keys[]; };
layout(std430, binding = 3) buffer First { uint first[]; };
layout(std430, binding = 4) writeonly buffer PointSlots { int point_slots[]; };
// [0] voxels out of range, [1] table full, [2] normals with a component beyond +-2
layout(std430, binding = 5) buffer Status { uint status[]; };

layout(push_constant) uniform Params {
  uint point_count;
  uint capacity_log2;
  uint has_normals;
  float inverse_size;
} params;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.point_count) return;
  const vec4 p = points[i];
  int slot = -1;
  dvec3 voxel;
  if (is_valid_point(p) && params.has_normals != 0u) {
    const vec4 n = normals[i];
    if (is_valid_point(n) && !all(lessThanEqual(abs(n.xyz), vec3(2.0)))) atomicAdd(status[2], 1u);
  }
  if (is_valid_point(p)) {
    if (!voxel_of(dvec3(p.xyz) * double(params.inverse_size), voxel)) {
      atomicAdd(status[0], 1u);
    } else {
      const uint64_t key = voxel_key(voxel);
      const uint mask = (1u << params.capacity_log2) - 1u;
      uint s = voxel_slot(key, params.capacity_log2);
      for (uint probe = 0u; probe <= mask; ++probe) {
        const uint64_t found = atomicCompSwap(keys[s], 0ul, key);
        if (found == 0ul || found == key) {
          slot = int(s);
          break;
        }
        s = (s + 1u) & mask;
      }
      if (slot < 0) {
        atomicAdd(status[1], 1u);
      } else {
        atomicMax(first[slot], 0xffffffffu - i);
      }
    }
  }
  point_slots[i] = slot;
}
