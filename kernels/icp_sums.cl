// ICP sums, first pass; see shaders/icp_point_to_point.comp and shaders/icp_point_to_plane.comp
// for the row layouts. Per-pair arithmetic is in double (millimetre residuals on metre coordinates).
// Rules in include/kartograf/registration/icp_sums.hpp, robust kernels in robust_kernel.hpp.
typedef struct {
  uint pair_count;
  uint target_count;
  uint has_correspondences;
  uint has_weights;
  uint robust_kernel;  // 0 none, 1 Huber, 2 Tukey
} IcpSumsParams;

typedef struct {
  double3 moved;
  double3 target;
  double distance_sq;
  double weight;
  uint target_index;
} KgPair;

inline bool kg_load_pair(uint i, __global const float4* source, __global const float4* target,
                         __global const int* correspondences, __global const float* weights,
                         __global const double* frame, const IcpSumsParams* params, KgPair* pair) {
  pair->weight = 1.0;
  pair->target_index = i;
  const float4 p = source[i];
  if (!kg_is_valid_point(p)) return false;
  if (params->has_correspondences != 0) {
    const int j = correspondences[i];
    if (j < 0 || (uint)j >= params->target_count) return false;
    pair->target_index = (uint)j;
  } else if (i >= params->target_count) {
    return false;
  }
  if (params->has_weights != 0) {
    pair->weight = (double)weights[i];
    if (!(pair->weight > 0.0)) return false;
  }
  const float4 q = target[pair->target_index];
  if (!kg_is_valid_point(q)) return false;
  const double3 ps = convert_double3(p.xyz);
  pair->moved = (double3)(frame[0] * ps.x + frame[1] * ps.y + frame[2] * ps.z + frame[9],
                          frame[3] * ps.x + frame[4] * ps.y + frame[5] * ps.z + frame[10],
                          frame[6] * ps.x + frame[7] * ps.y + frame[8] * ps.z + frame[11]);
  pair->target = convert_double3(q.xyz);
  const double3 d = pair->moved - pair->target;
  pair->distance_sq = dot(d, d);
  return pair->distance_sq <= frame[18];
}

// A valid source point whose entry is not kNotSelected (-2 or lower): the fitness denominator.
inline bool kg_is_considered(uint i, __global const float4* source, __global const int* correspondences,
                             const IcpSumsParams* params) {
  if (!kg_is_valid_point(source[i])) return false;
  return params->has_correspondences == 0 || correspondences[i] >= -1;
}

// The robust kernel's weight of a residual; frame[19] is its scale c.
inline double kg_robust_weight(double residual, __global const double* frame, const IcpSumsParams* params) {
  const double r = fabs(residual);
  const double c = frame[19];
  if (params->robust_kernel == 1) return r <= c ? 1.0 : c / r;  // Huber
  if (params->robust_kernel == 2) {                             // Tukey
    if (!(r < c)) return 0.0;
    const double u = r / c;
    const double s = 1.0 - u * u;
    return s * s;
  }
  return 1.0;
}

__kernel void icp_point_to_point(__global const float4* source, __global const float4* target,
                                 __global const int* correspondences, __global const float* weights,
                                 __global const double* frame, __global double* partials,
                                 const IcpSumsParams params) {
  __local double shared_sums[KG_MAX_SUMS * KG_REDUCTION_GROUP];
  double sums[KG_MAX_SUMS];
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  const double3 source_pivot = (double3)(frame[12], frame[13], frame[14]);
  const double3 target_pivot = (double3)(frame[15], frame[16], frame[17]);
  const uint stride = get_num_groups(0) * KG_REDUCTION_GROUP;
  for (uint i = get_global_id(0); i < params.pair_count; i += stride) {
    if (kg_is_considered(i, source, correspondences, &params)) sums[19] += 1.0;
    KgPair pair;
    if (!kg_load_pair(i, source, target, correspondences, weights, frame, &params, &pair)) continue;
    const double a[3] = {pair.moved.x - source_pivot.x, pair.moved.y - source_pivot.y,
                         pair.moved.z - source_pivot.z};
    const double b[3] = {pair.target.x - target_pivot.x, pair.target.y - target_pivot.y,
                         pair.target.z - target_pivot.z};
    const double w = pair.weight * kg_robust_weight(sqrt(pair.distance_sq), frame, &params);
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
  kg_store_group_sums(sums, 26, shared_sums, partials);
}

__kernel void icp_point_to_plane(__global const float4* source, __global const float4* target,
                                 __global const float4* target_normals,
                                 __global const int* correspondences, __global const float* weights,
                                 __global const double* frame, __global double* partials,
                                 const IcpSumsParams params) {
  __local double shared_sums[KG_MAX_SUMS * KG_REDUCTION_GROUP];
  double sums[KG_MAX_SUMS];
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  const double3 pivot = (double3)(frame[12], frame[13], frame[14]);
  const uint stride = get_num_groups(0) * KG_REDUCTION_GROUP;
  for (uint i = get_global_id(0); i < params.pair_count; i += stride) {
    if (kg_is_considered(i, source, correspondences, &params)) sums[31] += 1.0;
    KgPair pair;
    if (!kg_load_pair(i, source, target, correspondences, weights, frame, &params, &pair)) continue;
    const float4 normal = target_normals[pair.target_index];
    if (!kg_is_valid_point(normal)) continue;
    const double3 n = convert_double3(normal.xyz);
    const double3 arm = cross(pair.moved - pivot, n);
    const double j[6] = {arm.x, arm.y, arm.z, n.x, n.y, n.z};
    const double r = dot(pair.moved - pair.target, n);
    const double w = pair.weight * kg_robust_weight(r, frame, &params);
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
  kg_store_group_sums(sums, 32, shared_sums, partials);
}
