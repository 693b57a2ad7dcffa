// OpenCL wrapper of kernels/pyramid_downsample/pyramid_downsample.h.
#include "kernels/pyramid_downsample/pyramid_downsample.h"

__kernel void pyramid_downsample(__global const float4* fine_points, __global const uint* fine_colors,
                                 __global float4* coarse_points, __global uint* coarse_colors,
                                 const PyramidDownsampleParams params) {
  const uint x = get_global_id(0);
  const uint y = get_global_id(1);
  if (x >= params.coarse_width || y >= params.coarse_height) return;
  const uint i0 = 2 * y * params.fine_width + 2 * x;
  const uint i2 = i0 + params.fine_width;
  const float4 p0 = fine_points[i0], p1 = fine_points[i0 + 1];
  const float4 p2 = fine_points[i2], p3 = fine_points[i2 + 1];
  const uint members = pyramid_block_members(p0, p1, p2, p3, params.max_depth_jump);
  const uint index = y * params.coarse_width + x;
  coarse_points[index] = pyramid_block_point(p0, p1, p2, p3, members);
  if (params.has_colors == 0) return;
  coarse_colors[index] = pyramid_block_color(fine_colors[i0], fine_colors[i0 + 1], fine_colors[i2],
                                             fine_colors[i2 + 1], members);
}
