#version 450
// One pyramid step: 2x2 blocks of points (and colours) -> one coarse pixel; rules in
// include/kartograf/registration/frame_pyramid.hpp.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

layout(std430, binding = 0) readonly buffer FinePoints { vec4 fine_points[]; };
layout(std430, binding = 1) readonly buffer FineColors { uint fine_colors[]; };  // optional
layout(std430, binding = 2) writeonly buffer CoarsePoints { vec4 coarse_points[]; };
layout(std430, binding = 3) writeonly buffer CoarseColors { uint coarse_colors[]; };  // optional

layout(push_constant) uniform Params {
  uint fine_width;
  uint coarse_width;
  uint coarse_height;
  uint has_colors;
  float max_depth_jump;
} params;

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= params.coarse_width || pixel.y >= params.coarse_height) return;
  uint block[4];
  const uint corner = 2u * pixel.y * params.fine_width + 2u * pixel.x;
  block[0] = corner;
  block[1] = corner + 1u;
  block[2] = corner + params.fine_width;
  block[3] = corner + params.fine_width + 1u;
  float z_min = 0.0;
  bool any = false;
  for (int k = 0; k < 4; ++k) {
    const vec4 p = fine_points[block[k]];
    if (is_valid_point(p) && (!any || p.z < z_min)) {
      z_min = p.z;
      any = true;
    }
  }
  vec4 point = kInvalidPoint;
  uint color = 0u;
  if (any) {
    vec3 sum = vec3(0.0);
    uvec3 color_sum = uvec3(0u);
    uint count = 0u;
    for (int k = 0; k < 4; ++k) {
      const vec4 p = fine_points[block[k]];
      if (!is_valid_point(p) || !(p.z - z_min <= params.max_depth_jump * z_min)) continue;
      sum += p.xyz;
      ++count;
      if (params.has_colors != 0u) {
        const uint c = fine_colors[block[k]];
        color_sum += uvec3(c & 0xffu, (c >> 8) & 0xffu, (c >> 16) & 0xffu);
      }
    }
    // Multiplying by a rounded reciprocal is exact IEEE everywhere; division need not be.
    const float inverse[5] = float[5](0.0, 1.0, 0.5, 0.333333343267, 0.25);
    point = vec4(sum * inverse[count], 1.0);
    const uvec3 mean = (color_sum + uvec3(count / 2u)) / count;
    color = mean.x | (mean.y << 8) | (mean.z << 16);
  }
  const uint index = pixel.y * params.coarse_width + pixel.x;
  coarse_points[index] = point;
  if (params.has_colors != 0u) coarse_colors[index] = color;
}
