// Prepended to every Kartograf OpenCL kernel file (all are built as one program): the extensions
// every kernel needs and the work-group reduction the ICP sums and the colour gate share.
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable

#include "kernels/reduce_rows/reduce_rows.h"  // KG_REDUCTION_GROUP, KG_MAX_SUMS

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
