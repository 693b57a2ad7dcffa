// OpenCL wrapper of kernels/normals/normals.h.
#include "kernels/normals/normals.h"

inline float4 normals_point_at(__global const float4* points, int x, int y, NormalsParams params) {
  if (x < 0 || y < 0 || x >= (int)params.width || y >= (int)params.height) return KG_INVALID_POINT;
  return points[(uint)y * params.width + (uint)x];
}

__kernel void normals(__global const float4* points, __global float4* normals,
                      const NormalsParams params) {
  const int x = get_global_id(0);
  const int y = get_global_id(1);
  if (x >= (int)params.width || y >= (int)params.height) return;
  normals[(uint)y * params.width + (uint)x] = normal_from_neighbours(
      normals_point_at(points, x, y, params), normals_point_at(points, x - 1, y, params),
      normals_point_at(points, x + 1, y, params), normals_point_at(points, x, y - 1, params),
      normals_point_at(points, x, y + 1, params), params);
}
