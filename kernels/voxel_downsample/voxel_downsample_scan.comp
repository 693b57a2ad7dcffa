#version 450
// Vulkan wrapper of kernels/voxel_downsample/voxel_downsample.h, pass 3 (scan): one work-group
// turns counts[0..thread_count) into exclusive prefix sums in place and writes the total to
// counts[thread_count]. Each lane scans a contiguous part, lane 0 scans the lanes' part sums.
#extension GL_GOOGLE_include_directive : require
#include "kernels/voxel_downsample/voxel_downsample.h"

layout(std430, binding = 0) buffer Counts { uint counts[]; };

layout(local_size_x = KG_VOXEL_DOWNSAMPLE_LOCAL_X) in;
KG_PUSH_PARAMS(VoxelScanParams);

shared uint part_offsets[KG_VOXEL_DOWNSAMPLE_LOCAL_X];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint part = params.thread_count / KG_VOXEL_DOWNSAMPLE_LOCAL_X;
  const uint base = lane * part;
  uint sum = 0u;
  for (uint j = 0u; j < part; ++j) sum += counts[base + j];
  part_offsets[lane] = sum;
  barrier();
  if (lane == 0u) {
    uint running = 0u;
    for (uint l = 0u; l < KG_VOXEL_DOWNSAMPLE_LOCAL_X; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = running;
      running += value;
    }
    counts[params.thread_count] = running;
  }
  barrier();
  uint offset = part_offsets[lane];
  for (uint j = 0u; j < part; ++j) {
    const uint value = counts[base + j];
    counts[base + j] = offset;
    offset += value;
  }
}
