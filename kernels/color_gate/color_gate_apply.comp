#version 450
// Vulkan wrapper of kernels/color_gate/color_gate.h, last pass: rejects the pairs whose
// differences exceed mean_factor x the mean, and counts them.
#extension GL_GOOGLE_include_directive : require
#include "kernels/color_gate/color_gate.h"

layout(local_size_x = KG_COLOR_GATE_APPLY_LOCAL_X) in;

layout(std430, binding = 0) readonly buffer Differences { uint differences[]; };
layout(std430, binding = 1) readonly buffer Sums { double sums[]; };  // KG_COLOR_GATE_SUMS
layout(std430, binding = 2) buffer Correspondences { int correspondences[]; };
layout(std430, binding = 3) buffer Rejected { uint rejected[]; };
KG_PUSH_PARAMS(ColorGateApplyParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.pair_count) return;
  if (color_gate_rejects(differences[i], sums[0], sums[1], sums[2], sums[3], params)) {
    correspondences[i] = -1;
    atomicAdd(rejected[0], 1u);
  }
}
