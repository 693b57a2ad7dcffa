// OpenCL wrapper of kernels/subsample/subsample.h.
#include "kernels/subsample/subsample.h"

__kernel void subsample(__global const float4* points, __global const float4* normals,
                        __global const uint* colors, __global float4* out_points,
                        __global float4* out_normals, __global uint* out_colors,
                        const SubsampleParams params) {
  const uint m = get_global_id(0);
  if (m >= params.out_count) return;
  const uint i = subsample_source_index(m, params);
  out_points[m] = points[i];
  if (params.has_normals != 0u) out_normals[m] = normals[i];
  if (params.has_colors != 0u) out_colors[m] = colors[i];
}
