#version 450
// Parallel Lab region growing, pass 6 of 6: every other pixel takes its root's label (kNoLabel
// where invalid).
#extension GL_GOOGLE_include_directive : require
#include "region_grow.glsl"

layout(local_size_x = 256) in;

layout(std430, binding = 0) readonly buffer Parent { uint parent[]; };
layout(std430, binding = 1) buffer Labels { uint labels[]; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.pixel_count) return;
  uint p = parent[i];
  if (p == KG_NO_LABEL) {
    labels[i] = KG_NO_LABEL;
    return;
  }
  if (p == i) return;  // a root: numbered in pass 5
  uint root = i;
  while (p != root) {
    root = p;
    p = parent[root];
  }
  labels[i] = labels[root];
}
