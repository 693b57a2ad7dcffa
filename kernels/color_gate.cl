// Colour gate: differences + partial sums, then the gate; see shaders/color_gate_*.comp and
// include/kartograf/registration/color_gate.hpp.
typedef struct {
  uint pair_count;
  uint target_count;
} ColorGateDifferenceParams;

typedef struct {
  uint pair_count;
  uint use_hue;
  uint use_saturation;
  float mean_factor;
} ColorGateApplyParams;

inline uint kg_pair_color_differences(uint i, __global const uint* source_colors,
                                      __global const uint* target_colors,
                                      __global const int* correspondences,
                                      __global const ushort* table, uint target_count) {
  const int j = correspondences[i];
  if (j < 0 || (uint)j >= target_count) return 0u;
  const uint a = table[source_colors[i] & 0xffffffu];
  const uint b = table[target_colors[j] & 0xffffffu];
  const uint ds = (uint)abs((int)(a >> 8) - (int)(b >> 8));
  const uint ha = a & 0xffu;
  const uint hb = b & 0xffu;
  if (ha == 255u || hb == 255u) return 1u | (ds << 16);  // a grey colour: saturation only
  const uint d = (uint)abs((int)ha - (int)hb);
  return 3u | (min(d, 255u - d) << 8) | (ds << 16);
}

__kernel void color_gate_differences(__global const uint* source_colors,
                                     __global const uint* target_colors,
                                     __global const int* correspondences,
                                     __global const ushort* table, __global uint* differences,
                                     __global double* partials,
                                     const ColorGateDifferenceParams params) {
  __local double shared_sums[KG_MAX_SUMS * KG_REDUCTION_GROUP];
  double sums[4] = {0.0, 0.0, 0.0, 0.0};
  const uint stride = get_num_groups(0) * KG_REDUCTION_GROUP;
  for (uint i = get_global_id(0); i < params.pair_count; i += stride) {
    const uint d = kg_pair_color_differences(i, source_colors, target_colors, correspondences, table,
                                             params.target_count);
    differences[i] = d;
    if ((d & 1u) == 0u) continue;
    sums[0] += 1.0;
    sums[1] += (double)(d >> 16);
    if ((d & 2u) != 0u) {
      sums[2] += 1.0;
      sums[3] += (double)((d >> 8) & 0xffu);
    }
  }
  kg_store_group_sums(sums, 4, shared_sums, partials);
}

__kernel void color_gate_apply(__global const uint* differences, __global const double* sums,
                               __global int* correspondences, __global uint* rejected,
                               const ColorGateApplyParams params) {
  const uint i = get_global_id(0);
  if (i >= params.pair_count) return;
  const uint d = differences[i];
  if ((d & 1u) == 0u) return;
  const double factor = (double)params.mean_factor;
  const bool saturation_far =
      params.use_saturation != 0u && (double)(d >> 16) * sums[0] > factor * sums[1];
  const bool hue_far = params.use_hue != 0u && (d & 2u) != 0u &&
                       (double)((d >> 8) & 0xffu) * sums[2] > factor * sums[3];
  if (saturation_far || hue_far) {
    correspondences[i] = -1;
    atomic_inc(&rejected[0]);
  }
}
