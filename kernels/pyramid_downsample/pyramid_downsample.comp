#version 450
// Vulkan wrapper of kernels/pyramid_downsample/pyramid_downsample.h.
#extension GL_GOOGLE_include_directive : require
#include "kernels/pyramid_downsample/pyramid_downsample.h"

layout(local_size_x = KG_PYRAMID_DOWNSAMPLE_LOCAL_X,
       local_size_y = KG_PYRAMID_DOWNSAMPLE_LOCAL_Y) in;

layout(std430, binding = 0) readonly buffer FinePoints { vec4 fine_points[]; };
layout(std430, binding = 1) readonly buffer FineColors { uint fine_colors[]; };  // optional
layout(std430, binding = 2) writeonly buffer CoarsePoints { vec4 coarse_points[]; };
layout(std430, binding = 3) writeonly buffer CoarseColors { uint coarse_colors[]; };  // optional
KG_PUSH_PARAMS(PyramidDownsampleParams);

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= params.coarse_width || pixel.y >= params.coarse_height) return;
  const uint i0 = 2u * pixel.y * params.fine_width + 2u * pixel.x;
  const uint i2 = i0 + params.fine_width;
  const vec4 p0 = fine_points[i0], p1 = fine_points[i0 + 1u];
  const vec4 p2 = fine_points[i2], p3 = fine_points[i2 + 1u];
  const uint members = pyramid_block_members(p0, p1, p2, p3, params.max_depth_jump);
  const uint index = pixel.y * params.coarse_width + pixel.x;
  coarse_points[index] = pyramid_block_point(p0, p1, p2, p3, members);
  if (params.has_colors == 0u) return;
  coarse_colors[index] = pyramid_block_color(fine_colors[i0], fine_colors[i0 + 1u],
                                             fine_colors[i2], fine_colors[i2 + 1u], members);
}
