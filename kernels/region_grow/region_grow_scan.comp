#version 450
// Vulkan wrapper of kernels/region_grow/region_grow.h, pass 2 of 4: one work-group turns the
// segment counts per tile into exclusive prefix sums in place (kernels/work_group/group_scan.h)
// and writes the segment count to the status.
#extension GL_GOOGLE_include_directive : require
#include "kernels/region_grow/region_grow.h"

layout(local_size_x = KG_REGION_GROW_SCAN_LOCAL_X) in;

layout(std430, binding = 0) buffer TileCounts { uint scan_values[]; };  // the tile counts
layout(std430, binding = 1) buffer Status { uint status[]; };
KG_PUSH_PARAMS(RegionGrowParams);

#include "kernels/work_group/group_scan.h"
#if KG_REGION_GROW_SCAN_LOCAL_X != KG_GROUP_SCAN_LANES
#error "the scan pass is one work-group of the scan's lanes"
#endif

void main() {
  const uint total = kg_group_exclusive_scan(
      KG_BUFFER_ARG(scan_values) KG_SHARED_ARG(part_offsets) params.padded_tile_count);
  if (KG_LANE == 0u) status[KG_REGION_GROW_SEGMENT_COUNT] = total;
}
