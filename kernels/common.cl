// Prepended to every Kartograf OpenCL kernel file (all are built as one program).
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable

#define KG_INVALID_POINT ((float4)(NAN, NAN, NAN, NAN))
#include "kernels/reduce_rows/reduce_rows.h"  // KG_REDUCTION_GROUP, KG_MAX_SUMS

inline bool kg_is_valid_point(float4 p) { return !isnan(p.x); }

// Adds value as a 64-bit fixed-point integer (value * scale, rounded to nearest even) with an
// atomic: integer addition is exact and associative, so the sum does not depend on the order.
inline void kg_add_fixed(__global long* sums, uint slot, double value, double scale) {
  atom_add(&sums[slot], convert_long_rte(value * scale));
}

// The first pass of a two-pass reduction: each work-item has summed its share into `sums`; the
// work-group adds those in local memory (a fixed-order tree: results do not vary from run to run)
// and writes one row of `sum_count` doubles per work-group to `partials`.
inline void kg_store_group_sums(const double* sums, uint sum_count, __local double* shared_sums,
                                __global double* partials) {
  const uint lane = get_local_id(0);
  for (uint k = 0; k < sum_count; ++k) shared_sums[k * KG_REDUCTION_GROUP + lane] = sums[k];
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = KG_REDUCTION_GROUP / 2; stride > 0; stride >>= 1) {
    if (lane < stride) {
      for (uint k = 0; k < sum_count; ++k) {
        shared_sums[k * KG_REDUCTION_GROUP + lane] += shared_sums[k * KG_REDUCTION_GROUP + lane + stride];
      }
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (lane < sum_count) {
    partials[get_group_id(0) * sum_count + lane] = shared_sums[lane * KG_REDUCTION_GROUP];
  }
}
