// OpenCL wrapper of kernels/segment_moments/segment_moments.h: one point per work-item, its terms
// added with 64-bit atomics.
#include "kernels/segment_moments/segment_moments.h"

__kernel void segment_moments(__global const float4* points, __global const uint* labels,
                              __global long* moments, __global uint* status,
                              const SegmentMomentsParams params) {
  const uint i = get_global_id(0);
  if (i >= params.point_count) return;
  const uint label = labels[i];
  const float4 p = points[i];
  const uint outcome = segment_moment_outcome(label, p, params);
  if (outcome == KG_SEGMENT_MOMENT_BAD_LABEL) atomic_inc(&status[KG_SEGMENT_MOMENTS_BAD_LABEL]);
  if (outcome == KG_SEGMENT_MOMENT_TOO_FAR) atomic_inc(&status[KG_SEGMENT_MOMENTS_TOO_FAR]);
  if (outcome != KG_SEGMENT_MOMENT_ADD) return;
  const SegmentMomentOffset d = segment_moment_offset(p, params);
  const uint base = label * KG_SEGMENT_MOMENT_VALUES;
  for (uint slot = 0; slot < KG_SEGMENT_MOMENT_VALUES; ++slot) {
    atom_add(&moments[base + slot], segment_moment_term(d, slot, params));
  }
}
