#version 450
// Simulated laser scans by integer sphere tracing: rules in include/kartograf/rooms/
// laser_features.hpp, the operation in rooms/laser_scan_device.hpp, the loop as in
// src/rooms/laser_beam.hpp.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Skips { int skips[]; };            // padded grid
layout(std430, binding = 1) readonly buffer Directions { ivec2 directions[]; };  // 1/65536 cell
layout(std430, binding = 2) readonly buffer Cells { ivec2 cells[]; };            // (col, row)
layout(std430, binding = 3) writeonly buffer Steps { int steps[]; };           // cells x beams

layout(push_constant) uniform Params {
  uint item_count;
  uint items_per_cell;
  uint beams;
  uint beams_per_item;
  int map_width;
  int map_height;
  int max_steps;
} params;

void main() {
  // A 1-D grid of items folded into x and y (at most 65535 groups per dimension).
  const uint item = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x) +
                    gl_GlobalInvocationID.x;
  if (item >= params.item_count) return;
  const uint cell = item / params.items_per_cell;
  const uint first_beam = (item % params.items_per_cell) * params.beams_per_item;
  const uint end_beam = min(first_beam + params.beams_per_item, params.beams);
  const ivec2 c = cells[cell];
  // Cells outside the map never reach here (the host checks); they would give zeros.
  const bool inside = c.x >= 0 && c.y >= 0 && c.x < params.map_width && c.y < params.map_height;
  const int stride = params.map_width + 2;
  const int x0 = (c.x + 1) * 65536 + 32768, y0 = (c.y + 1) * 65536 + 32768;
  for (uint k = first_beam; k < end_beam; ++k) {
    const ivec2 direction = directions[k];
    int step = 0;
    while (inside && step < params.max_steps) {
      const int x = (x0 + step * direction.x) >> 16, y = (y0 + step * direction.y) >> 16;
      const int skip = skips[y * stride + x];
      if (skip == 0) break;
      step += skip;
    }
    steps[cell * params.beams + k] = min(step, params.max_steps);
  }
}
