#version 450
// Vulkan wrapper of kernels/tsdf/tsdf.h, ray casting.
#extension GL_GOOGLE_include_directive : require
#include "kernels/tsdf/tsdf_voxel.h"

layout(std430, binding = 0) readonly buffer Keys { uint64_t keys[]; };
layout(std430, binding = 1) readonly buffer SlotBlocks { uint slot_blocks[]; };
layout(std430, binding = 2) readonly buffer Voxels { TsdfVoxel voxels[]; };
layout(std430, binding = 3) writeonly buffer Points { vec4 points[]; };
layout(std430, binding = 4) writeonly buffer Colors { uint colors[]; };  // optional
layout(std430, binding = 5) readonly buffer Ranges { uint ranges[]; };    // the tiles' depths

#define KG_VOXEL_HASH_FIND
#define KG_TSDF_READ_PASS
#include "kernels/tsdf/tsdf.h"

layout(local_size_x = KG_TSDF_LOCAL_2D, local_size_y = KG_TSDF_LOCAL_2D) in;
KG_PUSH_PARAMS(TsdfParams);

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= params.width || pixel.y >= params.height) return;
  const uint index = pixel.y * params.width + pixel.x;
  const float min_depth = float(params.min_units) * params.metres_per_unit;
  const float max_depth = float(params.max_units) * params.metres_per_unit;
  const TsdfDepthSpan span = tsdf_ray_span(pixel.x, pixel.y, min_depth, max_depth, params);
  const vec4 p = tsdf_cast_ray(pixel.x, pixel.y, span.near, span.far, params);
  points[index] = p;
  if (params.has_color != 0u) colors[index] = tsdf_color_at(p, params);
}
