#version 450
// Per-label moments as 64-bit fixed-point atomic sums; contract in
// include/kartograf/geometry/segment_moments.hpp. Per label, 10 int64:
// [0] count, [1..3] sum d, [4..9] sum d d^T upper triangle (xx xy xz yy yz zz), d = p - origin.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_int64 : require
#include "common.glsl"

layout(local_size_x = 256) in;

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Labels { uint labels[]; };
layout(std430, binding = 2) buffer Moments { int64_t moments[]; };
layout(std430, binding = 3) buffer Status { uint status[]; };  // [0] points too far, [1] bad labels

layout(push_constant) uniform Params {
  uint point_count;
  uint label_count;
  float origin_x;
  float origin_y;
  float origin_z;
  float max_offset;
  float first_scale;   // 2^k1: fixed-point scale of sum d
  float second_scale;  // 2^k2: fixed-point scale of sum d d^T
} params;

void add(uint slot, double value, double scale) {
  atomicAdd(moments[slot], int64_t(roundEven(value * scale)));
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.point_count) return;
  const uint label = labels[i];
  const vec4 p = points[i];
  if (label == 0xffffffffu || !is_valid_point(p)) return;
  if (label >= params.label_count) {
    atomicAdd(status[1], 1u);
    return;
  }
  const dvec3 d = dvec3(p.xyz) - dvec3(params.origin_x, params.origin_y, params.origin_z);
  if (any(greaterThan(abs(d), dvec3(params.max_offset)))) {
    atomicAdd(status[0], 1u);
    return;
  }
  const uint base = label * 10u;
  const double s1 = double(params.first_scale);
  const double s2 = double(params.second_scale);
  atomicAdd(moments[base], int64_t(1));
  add(base + 1u, d.x, s1);
  add(base + 2u, d.y, s1);
  add(base + 3u, d.z, s1);
  add(base + 4u, d.x * d.x, s2);
  add(base + 5u, d.x * d.y, s2);
  add(base + 6u, d.x * d.z, s2);
  add(base + 7u, d.y * d.y, s2);
  add(base + 8u, d.y * d.z, s2);
  add(base + 9u, d.z * d.z, s2);
}
