#version 450
// Organized normals from 4-neighbours; rules in include/kartograf/geometry/normals.hpp.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) writeonly buffer Normals { vec4 normals[]; };

layout(push_constant) uniform Params {
  uint width;
  uint height;
  float max_depth_jump;
} params;

vec4 point_at(int x, int y) {
  if (x < 0 || y < 0 || x >= int(params.width) || y >= int(params.height)) return kInvalidPoint;
  return points[uint(y) * params.width + uint(x)];
}

bool usable(vec4 neighbour, vec4 centre) {
  return is_valid_point(neighbour) && abs(neighbour.z - centre.z) <= params.max_depth_jump * centre.z;
}

// Tangent along one axis from the neighbours before and after the centre; w = 0 when none.
vec4 tangent(vec4 before, vec4 centre, vec4 after) {
  const bool has_before = usable(before, centre);
  const bool has_after = usable(after, centre);
  if (has_before && has_after) return vec4(after.xyz - before.xyz, 1.0);
  if (has_after) return vec4(after.xyz - centre.xyz, 1.0);
  if (has_before) return vec4(centre.xyz - before.xyz, 1.0);
  return vec4(0.0);
}

void main() {
  const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (pixel.x >= int(params.width) || pixel.y >= int(params.height)) return;
  const uint index = uint(pixel.y) * params.width + uint(pixel.x);
  const vec4 centre = points[index];
  vec4 normal = kInvalidPoint;
  if (is_valid_point(centre)) {
    const vec4 along_x = tangent(point_at(pixel.x - 1, pixel.y), centre, point_at(pixel.x + 1, pixel.y));
    const vec4 along_y = tangent(point_at(pixel.x, pixel.y - 1), centre, point_at(pixel.x, pixel.y + 1));
    if (along_x.w != 0.0 && along_y.w != 0.0) {
      vec3 n = cross(along_x.xyz, along_y.xyz);
      const float length_sq = dot(n, n);
      const float scale_sq = dot(along_x.xyz, along_x.xyz) * dot(along_y.xyz, along_y.xyz);
      if (length_sq > 1e-12 * scale_sq) {
        n *= inversesqrt(length_sq);
        if (dot(n, centre.xyz) > 0.0) n = -n;
        normal = vec4(n, 0.0);
      }
    }
  }
  normals[index] = normal;
}
