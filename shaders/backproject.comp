#version 450
// Depth back-projection: 16-bit depth -> organized float4 points (x, y, z, 1), NaN where invalid.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

layout(std430, binding = 0) readonly buffer Depth { uint depth_pairs[]; };  // two uint16 per word
// (u - cx) / fx * metres_per_unit for each column, then (v - cy) / fy * metres_per_unit per row.
layout(std430, binding = 1) readonly buffer Factors { float factors[]; };
layout(std430, binding = 2) writeonly buffer Points { vec4 points[]; };

layout(push_constant) uniform Params {
  uint width;
  uint height;
  uint min_units;  // valid depth values are min_units..max_units (and never 0)
  uint max_units;
  float metres_per_unit;
} params;

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= params.width || pixel.y >= params.height) return;
  const uint index = pixel.y * params.width + pixel.x;
  const uint d = (depth_pairs[index >> 1] >> ((index & 1u) * 16u)) & 0xffffu;
  vec4 point = kInvalidPoint;
  if (d != 0u && d >= params.min_units && d <= params.max_units) {
    const float depth = float(d);
    point = vec4(depth * factors[pixel.x], depth * factors[params.width + pixel.y],
                 depth * params.metres_per_unit, 1.0);
  }
  points[index] = point;
}
