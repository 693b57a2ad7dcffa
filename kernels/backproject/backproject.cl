// OpenCL wrapper of kernels/backproject/backproject.h.
#include "kernels/backproject/backproject.h"

__kernel void backproject(__global const ushort* depth, __global const float* factors,
                          __global float4* points, const BackprojectParams params) {
  const uint x = get_global_id(0);
  const uint y = get_global_id(1);
  if (x >= params.width || y >= params.height) return;
  const uint index = y * params.width + x;
  points[index] = backproject_depth(depth[index], factors[x], factors[params.width + y], params);
}
