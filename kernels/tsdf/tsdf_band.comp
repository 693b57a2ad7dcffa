#version 450
// Vulkan wrapper of kernels/tsdf/tsdf_band.h: each voxel of the pool marks its cell of the band.
#extension GL_GOOGLE_include_directive : require
#include "kernels/tsdf/tsdf_voxel.h"

layout(std430, binding = 0) readonly buffer BlockKeys { uint64_t block_keys[]; };
layout(std430, binding = 1) readonly buffer Voxels { TsdfVoxel voxels[]; };
layout(std430, binding = 2) buffer Cells { uint cells[]; };

#include "kernels/tsdf/tsdf_band.h"

layout(local_size_x = KG_TSDF_LOCAL_X) in;
KG_PUSH_PARAMS(TsdfBandParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  const TsdfBandMark mark =
      tsdf_band_mark(voxels[i], block_keys[i / KG_TSDF_BLOCK_VOXELS], i % KG_TSDF_BLOCK_VOXELS, params);
  if (mark.cell >= 0) atomicMax(cells[mark.cell], mark.state);
}
