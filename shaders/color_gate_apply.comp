#version 450
// Colour gate, last pass: rejects the pairs whose difference exceeds mean_factor x the mean;
// rules in include/kartograf/registration/color_gate.hpp. dS * pairs > factor * sum dS is exact
// integer arithmetic in double (one rounding for factor != 1), so every backend decides alike.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Differences { uint differences[]; };
layout(std430, binding = 1) readonly buffer Sums { double sums[]; };  // pairs, sum dS, hue pairs, sum dH
layout(std430, binding = 2) buffer Correspondences { int correspondences[]; };
layout(std430, binding = 3) buffer Rejected { uint rejected[]; };

layout(push_constant) uniform Params {
  uint pair_count;
  uint use_hue;
  uint use_saturation;
  float mean_factor;
} params;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.pair_count) return;
  const uint d = differences[i];
  if ((d & 1u) == 0u) return;
  const double factor = double(params.mean_factor);
  const bool saturation_far =
      params.use_saturation != 0u && double(d >> 16) * sums[0] > factor * sums[1];
  const bool hue_far = params.use_hue != 0u && (d & 2u) != 0u &&
                       double((d >> 8) & 0xffu) * sums[2] > factor * sums[3];
  if (saturation_far || hue_far) {
    correspondences[i] = -1;
    atomicAdd(rejected[0], 1u);
  }
}
