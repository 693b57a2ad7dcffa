#version 450
// Colour gate, first pass; rules in include/kartograf/registration/color_gate.hpp. Per source
// point: differences[i] = bit 0: a pair, bit 1: both colours have a hue, bits 8..15 dH,
// bits 16..23 dS (0 when not a pair). Partial row: [0] pairs, [1] sum dS, [2] hue pairs, [3] sum dH.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = KG_REDUCTION_GROUP) in;

layout(std430, binding = 0) readonly buffer SourceColors { uint source_colors[]; };
layout(std430, binding = 1) readonly buffer TargetColors { uint target_colors[]; };
layout(std430, binding = 2) readonly buffer Correspondences { int correspondences[]; };
layout(std430, binding = 3) readonly buffer Table { uint table[]; };  // 2-byte entries, 2 per word
layout(std430, binding = 4) writeonly buffer Differences { uint differences[]; };
layout(std430, binding = 5) writeonly buffer Partials { double partials[]; };

layout(push_constant) uniform Params {
  uint pair_count;
  uint target_count;
} params;

#include "reduction.glsl"

uint hsi_code(uint rgb) {
  const uint index = rgb & 0xffffffu;
  return (table[index >> 1] >> ((index & 1u) * 16u)) & 0xffffu;
}

uint pair_differences(uint i) {
  const int j = correspondences[i];
  if (j < 0 || uint(j) >= params.target_count) return 0u;
  const uint a = hsi_code(source_colors[i]);
  const uint b = hsi_code(target_colors[j]);
  const uint ds = uint(abs(int(a >> 8) - int(b >> 8)));
  const uint ha = a & 0xffu;
  const uint hb = b & 0xffu;
  if (ha == 255u || hb == 255u) return 1u | (ds << 16);  // a grey colour: saturation only
  const uint d = uint(abs(int(ha) - int(hb)));
  return 3u | (min(d, 255u - d) << 8) | (ds << 16);
}

void main() {
  double sums[KG_MAX_SUMS];
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  const uint stride = gl_NumWorkGroups.x * KG_REDUCTION_GROUP;
  for (uint i = gl_GlobalInvocationID.x; i < params.pair_count; i += stride) {
    const uint d = pair_differences(i);
    differences[i] = d;
    if ((d & 1u) == 0u) continue;
    sums[0] += 1.0;
    sums[1] += double(d >> 16);
    if ((d & 2u) != 0u) {
      sums[2] += 1.0;
      sums[3] += double((d >> 8) & 0xffu);
    }
  }
  store_group_sums(sums, 4);
}
