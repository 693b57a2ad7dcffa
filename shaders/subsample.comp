#version 450
// Uniform 1-in-k subsampling of an unorganized cloud: output m is input m * k; contract in
// include/kartograf/geometry/subsample.hpp.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Normals { vec4 normals[]; };  // optional
layout(std430, binding = 2) readonly buffer Colors { uint colors[]; };    // optional
layout(std430, binding = 3) writeonly buffer OutPoints { vec4 out_points[]; };
layout(std430, binding = 4) writeonly buffer OutNormals { vec4 out_normals[]; };
layout(std430, binding = 5) writeonly buffer OutColors { uint out_colors[]; };

layout(push_constant) uniform Params {
  uint out_count;
  uint k;
  uint has_normals;
  uint has_colors;
} params;

void main() {
  const uint m = gl_GlobalInvocationID.x;
  if (m >= params.out_count) return;
  const uint i = m * params.k;
  out_points[m] = points[i];
  if (params.has_normals != 0u) out_normals[m] = normals[i];
  if (params.has_colors != 0u) out_colors[m] = colors[i];
}
