#version 450
// Vulkan wrapper of kernels/normals/normals.h.
#extension GL_GOOGLE_include_directive : require
#include "kernels/normals/normals.h"

layout(local_size_x = KG_NORMALS_LOCAL_X, local_size_y = KG_NORMALS_LOCAL_Y) in;

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) writeonly buffer Normals { vec4 normals[]; };
KG_PUSH_PARAMS(NormalsParams);

vec4 point_at(int x, int y) {
  if (x < 0 || y < 0 || x >= int(params.width) || y >= int(params.height)) return KG_INVALID_POINT;
  return points[uint(y) * params.width + uint(x)];
}

void main() {
  const int x = int(gl_GlobalInvocationID.x);
  const int y = int(gl_GlobalInvocationID.y);
  if (x >= int(params.width) || y >= int(params.height)) return;
  normals[uint(y) * params.width + uint(x)] =
      normal_from_neighbours(point_at(x, y), point_at(x - 1, y), point_at(x + 1, y),
                             point_at(x, y - 1), point_at(x, y + 1), params);
}
