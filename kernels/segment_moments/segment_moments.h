// Per-label moments as 64-bit fixed-point sums (contract in
// include/kartograf/geometry/segment_moments.hpp): every valid labelled point adds, per label, its
// count and the terms of d and d d^T (d = p - origin, in double), each rounded half to even to a
// multiple of 2^-k. Integer sums are exact and order-independent, so every backend (atomics on the
// devices, a sequential loop on the CPU) returns the same sums.
#ifndef KARTOGRAF_KERNELS_SEGMENT_MOMENTS_H
#define KARTOGRAF_KERNELS_SEGMENT_MOMENTS_H
#include "shaders/prelude.h"

#define KG_SEGMENT_MOMENTS_LOCAL_X 256

// Per label: [0] count, [1..3] sum d, [4..9] sum d d^T upper triangle (xx xy xz yy yz zz).
#define KG_SEGMENT_MOMENT_VALUES 10u
// The status counters.
#define KG_SEGMENT_MOMENTS_TOO_FAR 0u    // points beyond max_offset
#define KG_SEGMENT_MOMENTS_BAD_LABEL 1u  // labels >= label_count (other than no label)

// What a point does.
#define KG_SEGMENT_MOMENT_SKIP 0u  // no label or no point
#define KG_SEGMENT_MOMENT_ADD 1u
#define KG_SEGMENT_MOMENT_BAD_LABEL 2u
#define KG_SEGMENT_MOMENT_TOO_FAR 3u

KG_RULES_BEGIN

KG_PARAMS_BEGIN(SegmentMomentsParams)
KG_PARAM(uint, point_count)
KG_PARAM(uint, label_count)
KG_PARAM(float, origin_x)
KG_PARAM(float, origin_y)
KG_PARAM(float, origin_z)
KG_PARAM(float, max_offset)
KG_PARAM(float, first_scale)   // 2^k1: fixed-point scale of sum d
KG_PARAM(float, second_scale)  // 2^k2: fixed-point scale of sum d d^T
KG_PARAMS_END(SegmentMomentsParams)

KG_STRUCT_BEGIN(SegmentMomentOffset)
double x;
double y;
double z;
KG_STRUCT_END(SegmentMomentOffset)

KG_INLINE SegmentMomentOffset segment_moment_offset(float4 p, SegmentMomentsParams params) {
  SegmentMomentOffset d;
  d.x = KG_DOUBLE(p.x) - KG_DOUBLE(params.origin_x);
  d.y = KG_DOUBLE(p.y) - KG_DOUBLE(params.origin_y);
  d.z = KG_DOUBLE(p.z) - KG_DOUBLE(params.origin_z);
  return d;
}

KG_INLINE uint segment_moment_outcome(uint label, float4 p, SegmentMomentsParams params) {
  if (label == 0xffffffffu || kg_isnan(p.x)) return KG_SEGMENT_MOMENT_SKIP;
  if (label >= params.label_count) return KG_SEGMENT_MOMENT_BAD_LABEL;
  const SegmentMomentOffset d = segment_moment_offset(p, params);
  const double bound = KG_DOUBLE(params.max_offset);
  if (kg_fabs(d.x) > bound || kg_fabs(d.y) > bound || kg_fabs(d.z) > bound) {
    return KG_SEGMENT_MOMENT_TOO_FAR;
  }
  return KG_SEGMENT_MOMENT_ADD;
}

// The fixed-point term of value `slot` (0..9, as the label's values) for the offset d.
KG_INLINE int64_t segment_moment_term(SegmentMomentOffset d, uint slot,
                                      SegmentMomentsParams params) {
  const double s1 = KG_DOUBLE(params.first_scale);
  const double s2 = KG_DOUBLE(params.second_scale);
  switch (slot) {
    case 0u:
      return KG_INT64(1);
    case 1u:
      return kg_round_even_int64(d.x * s1);
    case 2u:
      return kg_round_even_int64(d.y * s1);
    case 3u:
      return kg_round_even_int64(d.z * s1);
    case 4u:
      return kg_round_even_int64(d.x * d.x * s2);
    case 5u:
      return kg_round_even_int64(d.x * d.y * s2);
    case 6u:
      return kg_round_even_int64(d.x * d.z * s2);
    case 7u:
      return kg_round_even_int64(d.y * d.y * s2);
    case 8u:
      return kg_round_even_int64(d.y * d.z * s2);
    default:
      return kg_round_even_int64(d.z * d.z * s2);
  }
}

KG_RULES_END

#endif
