// OpenCL wrapper of kernels/color_gate/color_gate.h: the differences pass (a row reduction's
// first pass) and the gate.
#include "kernels/color_gate/color_gate.h"
#include "kernels/work_group/group_sums.h"

__kernel void color_gate_differences(__global const uint* source_colors,
                                     __global const uint* target_colors,
                                     __global const int* correspondences,
                                     __global const ushort* table, __global uint* differences,
                                     __global double* partials,
                                     const ColorGateDifferencesParams params) {
  __local double shared_sums[KG_GROUP_SUMS_SHARED];
  double sums[KG_COLOR_GATE_SUMS] = {0.0, 0.0, 0.0, 0.0};
  const uint stride = get_num_groups(0) * KG_COLOR_GATE_DIFFERENCES_LOCAL_X;
  for (uint i = get_global_id(0); i < params.pair_count; i += stride) {
    const uint d = color_gate_entry_differences(source_colors, target_colors, correspondences,
                                                table, i, params);
    differences[i] = d;
    for (uint k = 0; k < KG_COLOR_GATE_SUMS; ++k) sums[k] += (double)color_gate_sum_term(d, k);
  }
  kg_store_group_sums(partials, shared_sums, sums, KG_COLOR_GATE_SUMS);
}

__kernel void color_gate_apply(__global const uint* differences, __global const double* sums,
                               __global int* correspondences, __global uint* rejected,
                               const ColorGateApplyParams params) {
  const uint i = get_global_id(0);
  if (i >= params.pair_count) return;
  if (color_gate_rejects(differences[i], sums[0], sums[1], sums[2], sums[3], params)) {
    correspondences[i] = -1;
    atomic_inc(&rejected[0]);
  }
}
