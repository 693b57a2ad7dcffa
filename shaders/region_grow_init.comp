#version 450
// Parallel Lab region growing, pass 1 of 6: one invocation per row links each valid pixel to
// the first pixel of its run of left-joined pixels (the run's root), so that pass 2 starts from
// shallow trees and only needs the upper neighbours.
#extension GL_GOOGLE_include_directive : require
#include "region_grow.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Lab { vec4 lab[]; };
layout(std430, binding = 1) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 2) writeonly buffer Parent { uint parent[]; };

void main() {
  const uint y = gl_GlobalInvocationID.x;
  if (y >= params.height) return;
  uint run_start = KG_NO_LABEL;
  bool previous_valid = false;
  vec4 previous_lab = vec4(0.0), previous_point = vec4(0.0);
  for (uint i = y * params.width; i < (y + 1u) * params.width; ++i) {
    const vec4 lab_i = lab[i], point_i = points[i];
    const bool valid = is_valid_pixel(lab_i, point_i);
    if (!valid) {
      parent[i] = KG_NO_LABEL;
    } else {
      if (!previous_valid || !connected(lab_i, point_i, previous_lab, previous_point)) run_start = i;
      parent[i] = run_start;
    }
    previous_valid = valid;
    previous_lab = lab_i;
    previous_point = point_i;
  }
}
