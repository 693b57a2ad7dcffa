#version 450
// Vulkan wrapper of kernels/laser_scan/laser_scan.h.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Skips { int skips[]; };              // padded grid
layout(std430, binding = 1) readonly buffer Directions { ivec2 directions[]; };  // 1/65536 cell
layout(std430, binding = 2) readonly buffer Cells { ivec2 cells[]; };            // (col, row)
layout(std430, binding = 3) writeonly buffer Steps { int steps[]; };             // cells x beams

// After the buffers: the rule reads and writes them.
#include "kernels/laser_scan/laser_scan.h"

layout(local_size_x = KG_LASER_SCAN_LOCAL_X) in;
KG_PUSH_PARAMS(LaserScanParams);

void main() {
  // A 1-D grid of items folded into x and y (at most 65535 groups per dimension).
  const uint item = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x) +
                    gl_GlobalInvocationID.x;
  if (item >= params.item_count) return;
  laser_scan_item(item, params);
}
