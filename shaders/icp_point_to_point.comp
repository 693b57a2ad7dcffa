#version 450
// Point-to-point ICP sums, first pass. Layout of a row (see src/registration/icp_sums.cpp):
// [0] pairs, [1] sum w, [2..4] sum w a, [5..7] sum w b, [8..16] sum w a b^T (row-major),
// [17] sum w |p' - q|^2, [18] sum |p' - q|^2, [19] considered source points,
// [20..25] sum w a a^T (upper triangle, row-major), with p' = R p + t, a = p' - source_pivot,
// b = q - target_pivot, w = caller weight x robust weight of |p' - q|.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = KG_REDUCTION_GROUP) in;

layout(std430, binding = 0) readonly buffer Source { vec4 source[]; };
layout(std430, binding = 1) readonly buffer Target { vec4 target[]; };
layout(std430, binding = 2) readonly buffer Correspondences { int correspondences[]; };
layout(std430, binding = 3) readonly buffer Weights { float weights[]; };
// R (row-major 3x3), t, source pivot, target pivot, max squared distance, robust scale.
layout(std430, binding = 4) readonly buffer Frame { double frame[]; };
layout(std430, binding = 5) writeonly buffer Partials { double partials[]; };

layout(push_constant) uniform Params {
  uint pair_count;
  uint target_count;
  uint has_correspondences;
  uint has_weights;
  uint robust_kernel;  // 0 none, 1 Huber, 2 Tukey
} params;

#include "reduction.glsl"
#include "icp_pairs.glsl"

void main() {
  double sums[KG_MAX_SUMS];
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  const dvec3 source_pivot = dvec3(frame[12], frame[13], frame[14]);
  const dvec3 target_pivot = dvec3(frame[15], frame[16], frame[17]);
  const uint stride = gl_NumWorkGroups.x * KG_REDUCTION_GROUP;
  for (uint i = gl_GlobalInvocationID.x; i < params.pair_count; i += stride) {
    if (is_considered(i)) sums[19] += 1.0;
    Pair pair;
    if (!load_pair(i, pair)) continue;
    const dvec3 a = pair.moved - source_pivot;
    const dvec3 b = pair.target - target_pivot;
    const double w = pair.weight * robust_weight(sqrt(pair.distance_sq));
    sums[0] += 1.0;
    sums[1] += w;
    for (int r = 0; r < 3; ++r) {
      sums[2 + r] += w * a[r];
      sums[5 + r] += w * b[r];
      for (int c = 0; c < 3; ++c) sums[8 + 3 * r + c] += w * a[r] * b[c];
    }
    sums[17] += w * pair.distance_sq;
    sums[18] += pair.distance_sq;
    uint slot = 20;
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) sums[slot++] += w * a[r] * a[c];
    }
  }
  store_group_sums(sums, 26);
}
