#version 450
// Vulkan wrapper of kernels/color_gate/color_gate.h, first pass: each entry's packed differences
// and one row of partial sums per work-group (a row reduction's first pass).
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer SourceColors { uint source_colors[]; };
layout(std430, binding = 1) readonly buffer TargetColors { uint target_colors[]; };
layout(std430, binding = 2) readonly buffer Correspondences { int correspondences[]; };
layout(std430, binding = 3) readonly buffer Table { uint table[]; };  // 2-byte entries, 2 per word
layout(std430, binding = 4) writeonly buffer Differences { uint differences[]; };
layout(std430, binding = 5) writeonly buffer Partials { double partials[]; };

// After the buffers: the rule reads them.
#define KG_COLOR_GATE_DIFFERENCES_BUFFERS
#include "kernels/color_gate/color_gate.h"

layout(local_size_x = KG_COLOR_GATE_DIFFERENCES_LOCAL_X) in;
KG_PUSH_PARAMS(ColorGateDifferencesParams);

#include "kernels/work_group/group_sums.h"

void main() {
  double sums[KG_MAX_SUMS];
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  const uint stride = gl_NumWorkGroups.x * KG_COLOR_GATE_DIFFERENCES_LOCAL_X;
  for (uint i = gl_GlobalInvocationID.x; i < params.pair_count; i += stride) {
    const uint d = color_gate_entry_differences(i, params);
    differences[i] = d;
    for (uint k = 0; k < KG_COLOR_GATE_SUMS; ++k) sums[k] += double(color_gate_sum_term(d, k));
  }
  kg_store_group_sums(KG_BUFFER_ARG(partials) KG_SHARED_ARG(shared_sums) sums, KG_COLOR_GATE_SUMS);
}
