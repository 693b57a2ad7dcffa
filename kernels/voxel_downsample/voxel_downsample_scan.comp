#version 450
// Vulkan wrapper of kernels/voxel_downsample/voxel_downsample.h, pass 3 (scan): one work-group
// turns counts[0..thread_count) into exclusive prefix sums in place and writes the total to
// counts[thread_count] (kernels/work_group/group_scan.h).
#extension GL_GOOGLE_include_directive : require
#include "kernels/voxel_downsample/voxel_downsample.h"

layout(std430, binding = 0) buffer Counts { uint scan_values[]; };  // the counts

#include "kernels/work_group/group_scan.h"
#if KG_VOXEL_DOWNSAMPLE_LOCAL_X != KG_GROUP_SCAN_LANES
#error "the scan's work-group is the voxel passes' work-group"
#endif

layout(local_size_x = KG_VOXEL_DOWNSAMPLE_LOCAL_X) in;
KG_PUSH_PARAMS(VoxelScanParams);

void main() {
  const uint total = kg_group_exclusive_scan(KG_BUFFER_ARG(scan_values)
                                                 KG_SHARED_ARG(part_offsets) params.thread_count);
  if (KG_LANE == 0u) scan_values[params.thread_count] = total;
}
