#version 450
// Point-to-plane ICP normal equations, first pass. Row layout (see src/registration/icp_sums.cpp):
// [0] pairs, [1] sum w, [2..22] J^T W J upper triangle row-major, [23..28] J^T W r,
// [29] sum w r^2, [30] sum r^2, [31] considered source points, with J = [(p' - pivot) x n, n],
// r = (p' - q) . n, w = caller weight x robust weight of r.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = KG_REDUCTION_GROUP) in;

layout(std430, binding = 0) readonly buffer Source { vec4 source[]; };
layout(std430, binding = 1) readonly buffer Target { vec4 target[]; };
layout(std430, binding = 2) readonly buffer TargetNormals { vec4 target_normals[]; };
layout(std430, binding = 3) readonly buffer Correspondences { int correspondences[]; };
layout(std430, binding = 4) readonly buffer Weights { float weights[]; };
// R (row-major 3x3), t, pivot, (unused 3), max squared distance, robust scale.
layout(std430, binding = 5) readonly buffer Frame { double frame[]; };
layout(std430, binding = 6) writeonly buffer Partials { double partials[]; };

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
  const dvec3 pivot = dvec3(frame[12], frame[13], frame[14]);
  const uint stride = gl_NumWorkGroups.x * KG_REDUCTION_GROUP;
  for (uint i = gl_GlobalInvocationID.x; i < params.pair_count; i += stride) {
    if (is_considered(i)) sums[31] += 1.0;
    Pair pair;
    if (!load_pair(i, pair)) continue;
    const vec4 normal = target_normals[pair.target_index];
    if (!is_valid_point(normal)) continue;
    const dvec3 n = dvec3(normal.xyz);
    const dvec3 arm = cross(pair.moved - pivot, n);
    double j[6] = double[6](arm.x, arm.y, arm.z, n.x, n.y, n.z);
    const double r = dot(pair.moved - pair.target, n);
    const double w = pair.weight * robust_weight(r);
    sums[0] += 1.0;
    sums[1] += w;
    uint slot = 2;
    for (int row = 0; row < 6; ++row) {
      for (int col = row; col < 6; ++col) sums[slot++] += w * j[row] * j[col];
    }
    for (int row = 0; row < 6; ++row) sums[23 + row] += w * j[row] * r;
    sums[29] += w * r * r;
    sums[30] += r * r;
  }
  store_group_sums(sums, 32);
}
