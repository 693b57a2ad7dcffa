#version 450
// Voxel downsampling, pass 5 of 6: every point adds its terms to its voxel's 64-bit fixed-point
// sums (integer atomics: exact, order-independent). Per voxel, `stride` int64: [0] count,
// [1..3] sum of the position within the voxel (fraction of p * inverse_size, in [0, 1)),
// with normals [4..6] sum n and [7] valid normals, then with colours the r, g, b sums.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_int64 : require
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Normals { vec4 normals[]; };  // optional
layout(std430, binding = 2) readonly buffer Colors { uint colors[]; };    // optional
layout(std430, binding = 3) readonly buffer PointSlots { int point_slots[]; };
layout(std430, binding = 4) readonly buffer VoxelOfSlot { uint voxel_of_slot[]; };
layout(std430, binding = 5) buffer Sums { int64_t sums[]; };

layout(push_constant) uniform Params {
  uint point_count;
  uint stride;
  uint has_normals;
  uint has_colors;
  float inverse_size;
  float position_scale;  // 2^k: fixed-point scale of the position sums
  float normal_scale;    // 2^k: fixed-point scale of the normal sums
} params;

void add(uint slot, double value, double scale) {
  atomicAdd(sums[slot], int64_t(roundEven(value * scale)));
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.point_count) return;
  const int slot = point_slots[i];
  if (slot < 0) return;
  const uint base = voxel_of_slot[slot] * params.stride;
  const dvec3 scaled = dvec3(points[i].xyz) * double(params.inverse_size);
  const dvec3 fraction = scaled - floor(scaled);  // exact: the product is exact in double
  const double position_scale = double(params.position_scale);
  atomicAdd(sums[base], int64_t(1));
  add(base + 1u, fraction.x, position_scale);
  add(base + 2u, fraction.y, position_scale);
  add(base + 3u, fraction.z, position_scale);
  if (params.has_normals != 0u) {
    const vec4 n = normals[i];
    // Normals beyond +-2 were counted by the insert pass (an error); skipping keeps sums bounded.
    if (is_valid_point(n) && all(lessThanEqual(abs(n.xyz), vec3(2.0)))) {
      const double normal_scale = double(params.normal_scale);
      add(base + 4u, double(n.x), normal_scale);
      add(base + 5u, double(n.y), normal_scale);
      add(base + 6u, double(n.z), normal_scale);
      atomicAdd(sums[base + 7u], int64_t(1));
    }
  }
  if (params.has_colors != 0u) {
    const uint c = colors[i];
    const uint color_base = base + (params.has_normals != 0u ? 8u : 4u);
    atomicAdd(sums[color_base], int64_t(c & 0xffu));
    atomicAdd(sums[color_base + 1u], int64_t((c >> 8) & 0xffu));
    atomicAdd(sums[color_base + 2u], int64_t((c >> 16) & 0xffu));
  }
}
