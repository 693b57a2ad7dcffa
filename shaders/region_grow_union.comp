#version 450
// Parallel Lab region growing, pass 2 of 6: each pixel unites with its connected up-left, up and
// up-right neighbours (left ones are joined by pass 1) (union-find, min-linking by atomicMin: every parent has a smaller
// index than its child, so a component's root ends as its smallest pixel index).
#extension GL_GOOGLE_include_directive : require
#include "region_grow.glsl"

layout(local_size_x = 256) in;

layout(std430, binding = 0) readonly buffer Lab { vec4 lab[]; };
layout(std430, binding = 1) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 2) coherent buffer Parent { uint parent[]; };

// Follows parents to the root, then points `start` straight at it: atomicMin, as parents only
// ever decrease and a plain store could undo a concurrent link.
uint find_root(uint start) {
  uint i = start;
  uint p = parent[i];
  while (p != i) {
    i = p;
    p = parent[i];
  }
  if (i != start) atomicMin(parent[start], i);
  return i;
}

// Playne & Hawick's atomic union: link the larger root under the smaller; if it stopped being a
// root meanwhile, atomicMin returns its new parent and the union goes on from there.
void unite(uint a, uint b) {
  for (;;) {
    a = find_root(a);
    b = find_root(b);
    if (a == b) return;
    if (a > b) {
      const uint t = a;
      a = b;
      b = t;
    }
    const uint old = atomicMin(parent[b], a);
    if (old == b) return;
    b = old;
  }
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.pixel_count || parent[i] == KG_NO_LABEL) return;
  const uint x = i % params.width, y = i / params.width;
  const vec4 lab_i = lab[i], point_i = points[i];
  if (y == 0u) return;
  for (int dx = -1; dx <= 1; ++dx) {
    const int nx = int(x) + dx;
    if (nx < 0 || nx >= int(params.width)) continue;
    const uint j = (y - 1u) * params.width + uint(nx);
    if (parent[j] == KG_NO_LABEL) continue;  // invalid pixels never change
    if (connected(lab_i, point_i, lab[j], points[j])) unite(i, j);
  }
}
