// ICP's sums over correspondences (rules in include/kartograf/registration/icp_sums.hpp): per pair
// (p' = R p + t, q), the terms of the point-to-point cross-covariance and of the point-to-plane
// normal equations, weighted by the caller's weight times the robust kernel's weight of the
// residual (include/kartograf/registration/robust_kernel.hpp). Per-pair arithmetic is in double:
// residuals near convergence are millimetres on coordinates of metres, which float would resolve to
// ~1e-4. Each work-group (CPU: each chunk) sums its pairs into one row; kernels/reduce_rows/ adds
// the rows.
#ifndef KARTOGRAF_KERNELS_ICP_SUMS_H
#define KARTOGRAF_KERNELS_ICP_SUMS_H
#include "kernels/reduce_rows/reduce_rows.h"
#include "shaders/prelude.h"

#define KG_ICP_SUMS_LOCAL_X KG_REDUCTION_GROUP

// frame[]: the doubles the host writes for one reduction.
#define KG_ICP_FRAME_ROTATION 0       // R, 3x3 row-major
#define KG_ICP_FRAME_TRANSLATION 9    // t
#define KG_ICP_FRAME_SOURCE_PIVOT 12  // point-to-point: the source pivot; point-to-plane: the pivot
#define KG_ICP_FRAME_TARGET_PIVOT 15  // point-to-point only
#define KG_ICP_FRAME_MAX_DISTANCE_SQ 18
#define KG_ICP_FRAME_ROBUST_SCALE 19
#define KG_ICP_FRAME_VALUES 20

// A point-to-point row, with a = p' - source pivot, b = q - target pivot, w the pair's weight.
#define KG_ICP_POINT_PAIRS 0
#define KG_ICP_POINT_WEIGHT_SUM 1
#define KG_ICP_POINT_SUM_A 2                      // 3 values: sum w a
#define KG_ICP_POINT_SUM_B 5                      // 3 values: sum w b
#define KG_ICP_POINT_SUM_AB 8                     // 9 values: sum w a b^T, row-major
#define KG_ICP_POINT_SQUARED_ERROR 17             // sum w |p' - q|^2
#define KG_ICP_POINT_UNWEIGHTED_SQUARED_ERROR 18  // sum |p' - q|^2
#define KG_ICP_POINT_CONSIDERED 19                // valid source points not left out by selection
#define KG_ICP_POINT_SUM_AA 20                    // 6 values: sum w a a^T, upper triangle row-major
#define KG_ICP_POINT_SUMS 26

// A point-to-plane row, with J = [(p' - pivot) x n, n] and r = (p' - q) . n.
#define KG_ICP_PLANE_PAIRS 0
#define KG_ICP_PLANE_WEIGHT_SUM 1
#define KG_ICP_PLANE_JTJ 2             // 21 values: sum w J^T J, upper triangle row-major
#define KG_ICP_PLANE_JTR 23            // 6 values: sum w J^T r
#define KG_ICP_PLANE_SQUARED_ERROR 29  // sum w r^2
#define KG_ICP_PLANE_UNWEIGHTED_SQUARED_ERROR 30  // sum r^2
#define KG_ICP_PLANE_CONSIDERED 31
#define KG_ICP_PLANE_SUMS 32

// Robust kernels (RobustKernel in robust_kernel.hpp).
#define KG_ROBUST_NONE 0u
#define KG_ROBUST_HUBER 1u
#define KG_ROBUST_TUKEY 2u

// Correspondence entries below this (kNotSelected) were left out by point selection.
#define KG_ICP_NO_MATCH (-1)

KG_RULES_BEGIN

KG_PARAMS_BEGIN(IcpSumsParams)
KG_PARAM(uint, pair_count)  // source points
KG_PARAM(uint, target_count)
KG_PARAM(uint, has_correspondences)  // 0: pair i is (source[i], target[i])
KG_PARAM(uint, has_weights)
KG_PARAM(uint, robust_kernel)  // KG_ROBUST_*
KG_PARAMS_END(IcpSumsParams)

KG_STRUCT_BEGIN(IcpFrame)
double3 rotation_x;  // R's rows
double3 rotation_y;
double3 rotation_z;
double3 translation;
double3 source_pivot;
double3 target_pivot;
double max_distance_sq;
double robust_scale;
KG_STRUCT_END(IcpFrame)

KG_STRUCT_BEGIN(IcpPair)
double3 moved;   // R p + t
double3 target;  // q
double distance_sq;
double weight;  // the caller's
uint target_index;
KG_STRUCT_END(IcpPair)

KG_INLINE IcpFrame icp_frame(double3 rotation_x, double3 rotation_y, double3 rotation_z,
                             double3 translation, double3 source_pivot, double3 target_pivot,
                             double max_distance_sq, double robust_scale) {
  IcpFrame f;
  f.rotation_x = rotation_x;
  f.rotation_y = rotation_y;
  f.rotation_z = rotation_z;
  f.translation = translation;
  f.source_pivot = source_pivot;
  f.target_pivot = target_pivot;
  f.max_distance_sq = max_distance_sq;
  f.robust_scale = robust_scale;
  return f;
}

// The frame from frame[] (a buffer in GLSL, a pointer in OpenCL C and C++).
#define KG_ICP_FRAME_VALUE3(frame, slot) \
  KG_DOUBLE3(frame[slot], frame[(slot) + 1], frame[(slot) + 2])
#define KG_ICP_READ_FRAME(frame)                                   \
  icp_frame(KG_ICP_FRAME_VALUE3(frame, KG_ICP_FRAME_ROTATION),     \
            KG_ICP_FRAME_VALUE3(frame, KG_ICP_FRAME_ROTATION + 3), \
            KG_ICP_FRAME_VALUE3(frame, KG_ICP_FRAME_ROTATION + 6), \
            KG_ICP_FRAME_VALUE3(frame, KG_ICP_FRAME_TRANSLATION),  \
            KG_ICP_FRAME_VALUE3(frame, KG_ICP_FRAME_SOURCE_PIVOT), \
            KG_ICP_FRAME_VALUE3(frame, KG_ICP_FRAME_TARGET_PIVOT), \
            frame[KG_ICP_FRAME_MAX_DISTANCE_SQ], frame[KG_ICP_FRAME_ROBUST_SCALE])

// The weight of a residual under robust kernel `kind` (KG_ROBUST_*) with scale c.
KG_INLINE double robust_kernel_weight(uint kind, double c, double residual) {
  const double r = kg_fabs(residual);
  if (kind == KG_ROBUST_HUBER) return r <= c ? 1.0 : c / r;
  if (kind == KG_ROBUST_TUKEY) {
    if (!(r < c)) return 0.0;
    const double u = r / c;
    const double s = 1.0 - u * u;
    return s * s;
  }
  return 1.0;
}

// Whether source point i counts towards the fitness denominator, given that it is valid: not left
// out by selection. `entry` is correspondences[i], or i without that buffer.
KG_INLINE bool icp_is_selected(int entry) {
  return entry >= KG_ICP_NO_MATCH;
}

// The target index of the entry, or -1 when it names no target point.
KG_INLINE int icp_target_of(int entry, IcpSumsParams p) {
  return entry >= 0 && KG_UINT(entry) < p.target_count ? entry : -1;
}

// Valid source point p, valid target point q = target[target_index], the caller's weight (> 0).
KG_FORCE_INLINE IcpPair icp_pair(float4 p, float4 q, uint target_index, double weight, IcpFrame f) {
  const double px = KG_DOUBLE(p.x), py = KG_DOUBLE(p.y), pz = KG_DOUBLE(p.z);
  IcpPair pair;
  pair.moved =
      KG_DOUBLE3(f.rotation_x.x * px + f.rotation_x.y * py + f.rotation_x.z * pz + f.translation.x,
                 f.rotation_y.x * px + f.rotation_y.y * py + f.rotation_y.z * pz + f.translation.y,
                 f.rotation_z.x * px + f.rotation_z.y * py + f.rotation_z.z * pz + f.translation.z);
  pair.target = KG_DOUBLE3(KG_DOUBLE(q.x), KG_DOUBLE(q.y), KG_DOUBLE(q.z));
  const double3 d = pair.moved - pair.target;
  pair.distance_sq = dot(d, d);
  pair.weight = weight;
  pair.target_index = target_index;
  return pair;
}

// Whether the pair counts: no farther apart than the maximum distance.
KG_INLINE bool icp_pair_in_range(IcpPair pair, IcpFrame f) {
  return pair.distance_sq <= f.max_distance_sq;
}

// A work-item's row of sums (GLSL: module scope; C, C++: the caller's array).
KG_ACCUMULATOR_STORAGE(double, sums, KG_MAX_SUMS)

// Adds a counted pair to a point-to-point row.
KG_FORCE_INLINE void icp_add_point_to_point(KG_ACCUMULATOR(double, sums, KG_MAX_SUMS) IcpPair pair,
                                            IcpFrame f, uint robust_kernel) {
  const double3 da = pair.moved - f.source_pivot;
  const double3 db = pair.target - f.target_pivot;
  const double a[3] = {da.x, da.y, da.z};
  const double b[3] = {db.x, db.y, db.z};
  // The square root only for a robust kernel: it was a third of the CPU loop's time without one.
  const double robust =
      robust_kernel == KG_ROBUST_NONE
          ? 1.0
          : robust_kernel_weight(robust_kernel, f.robust_scale, sqrt(pair.distance_sq));
  const double w = pair.weight * robust;
  sums[KG_ICP_POINT_PAIRS] += 1.0;
  sums[KG_ICP_POINT_WEIGHT_SUM] += w;
  for (int r = 0; r < 3; ++r) {
    sums[KG_ICP_POINT_SUM_A + r] += w * a[r];
    sums[KG_ICP_POINT_SUM_B + r] += w * b[r];
    for (int c = 0; c < 3; ++c) sums[KG_ICP_POINT_SUM_AB + 3 * r + c] += w * a[r] * b[c];
  }
  sums[KG_ICP_POINT_SQUARED_ERROR] += w * pair.distance_sq;
  sums[KG_ICP_POINT_UNWEIGHTED_SQUARED_ERROR] += pair.distance_sq;
  int slot = KG_ICP_POINT_SUM_AA;
  for (int r = 0; r < 3; ++r) {
    for (int c = r; c < 3; ++c) sums[slot++] += w * a[r] * a[c];
  }
}

// Adds a counted pair whose target normal is valid to a point-to-plane row.
KG_FORCE_INLINE void icp_add_point_to_plane(KG_ACCUMULATOR(double, sums, KG_MAX_SUMS) IcpPair pair,
                                            float4 normal, IcpFrame f, uint robust_kernel) {
  const double3 n = KG_DOUBLE3(KG_DOUBLE(normal.x), KG_DOUBLE(normal.y), KG_DOUBLE(normal.z));
  const double3 arm = cross(pair.moved - f.source_pivot, n);
  const double j[6] = {arm.x, arm.y, arm.z, n.x, n.y, n.z};
  const double r = dot(pair.moved - pair.target, n);
  const double w = pair.weight * robust_kernel_weight(robust_kernel, f.robust_scale, r);
  sums[KG_ICP_PLANE_PAIRS] += 1.0;
  sums[KG_ICP_PLANE_WEIGHT_SUM] += w;
  int slot = KG_ICP_PLANE_JTJ;
  for (int row = 0; row < 6; ++row) {
    const double weighted = w * j[row];
    for (int col = row; col < 6; ++col) sums[slot++] += weighted * j[col];
    sums[KG_ICP_PLANE_JTR + row] += weighted * r;
  }
  sums[KG_ICP_PLANE_SQUARED_ERROR] += w * r * r;
  sums[KG_ICP_PLANE_UNWEIGHTED_SQUARED_ERROR] += r * r;
}

KG_RULES_END

#endif
