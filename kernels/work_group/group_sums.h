// The first pass of a two-pass reduction (kernels/reduce_rows/), device code: each lane has summed
// its share into `sums`; the work-group adds those in shared memory in a fixed tree order (results
// do not vary from run to run) and writes one row of `sum_count` values per work-group to
// partials[group * sum_count...]. The CPU writes its chunk rows instead (chunk_rows_cpu.hpp).
// GLSL: the shader declares the `partials` buffer (double[]) before including this file; OpenCL:
// the kernel declares `__local double shared_sums[KG_GROUP_SUMS_SHARED]`.
#ifndef KARTOGRAF_KERNELS_WORK_GROUP_GROUP_SUMS_H
#define KARTOGRAF_KERNELS_WORK_GROUP_GROUP_SUMS_H
#include "kernels/reduce_rows/reduce_rows.h"  // KG_REDUCTION_GROUP, KG_MAX_SUMS
#if defined(__cplusplus)
#error "work-group procedures are device code (GLSL, OpenCL C)"
#endif

#define KG_GROUP_SUMS_SHARED (KG_MAX_SUMS * KG_REDUCTION_GROUP)

KG_SHARED_STORAGE(double, shared_sums, KG_GROUP_SUMS_SHARED)

KG_INLINE void kg_store_group_sums(KG_BUFFER_PARAM(double, partials)
                                       KG_SHARED(double, shared_sums)
                                           KG_IN_ARRAY(double, sums, KG_MAX_SUMS),
                                   uint sum_count) {
  const uint lane = KG_LANE;
  for (uint k = 0u; k < sum_count; ++k) shared_sums[k * KG_REDUCTION_GROUP + lane] = sums[k];
  KG_GROUP_BARRIER();
  for (uint stride = KG_REDUCTION_GROUP / 2u; stride > 0u; stride >>= 1u) {
    if (lane < stride) {
      for (uint k = 0u; k < sum_count; ++k) {
        shared_sums[k * KG_REDUCTION_GROUP + lane] +=
            shared_sums[k * KG_REDUCTION_GROUP + lane + stride];
      }
    }
    KG_GROUP_BARRIER();
  }
  if (lane < sum_count) {
    partials[KG_GROUP * sum_count + lane] = shared_sums[lane * KG_REDUCTION_GROUP];
  }
}

#endif
