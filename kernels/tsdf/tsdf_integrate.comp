#version 450
// Vulkan wrapper of kernels/tsdf/tsdf.h, pass 3 (integrate).
#extension GL_GOOGLE_include_directive : require
#include "kernels/tsdf/tsdf_voxel.h"

layout(std430, binding = 0) readonly buffer Depth { uint depth_pairs[]; };  // two uint16 per word
layout(std430, binding = 1) readonly buffer Colors { uint colors[]; };      // optional
layout(std430, binding = 2) readonly buffer Active { uint active_blocks[]; };
layout(std430, binding = 3) readonly buffer BlockKeys { uint64_t block_keys[]; };
layout(std430, binding = 4) buffer Voxels { TsdfVoxel voxels[]; };

#define KG_TSDF_INTEGRATE_PASS
#include "kernels/tsdf/tsdf.h"

layout(local_size_x = KG_TSDF_LOCAL_X) in;
KG_PUSH_PARAMS(TsdfParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  const TsdfVoxelView view = tsdf_voxel_view(i, params);
  if (view.pixel < 0) return;
  const uint index = uint(view.pixel);
  const uint d = (depth_pairs[index >> 1] >> ((index & 1u) * 16u)) & 0xffffu;
  if (!tsdf_fuses(d, view.z, params)) return;
  const uint color = params.has_color != 0u ? colors[index] : 0u;
  voxels[view.voxel] = tsdf_fuse(voxels[view.voxel], d, view.z, color, params);
}
