// The first pass of a two-pass reduction: each invocation has summed its share of the items into
// `sums`; the work-group adds those in shared memory (a fixed-order tree, so results do not vary
// from run to run) and writes one row of `sum_count` doubles per work-group to `partials`.
// The including shader declares `partials` (a double[] buffer) before including this file.
#include "kernels/reduce_rows/reduce_rows.h"  // KG_REDUCTION_GROUP, KG_MAX_SUMS
shared double shared_sums[KG_MAX_SUMS][KG_REDUCTION_GROUP];

void store_group_sums(double sums[KG_MAX_SUMS], uint sum_count) {
  const uint lane = gl_LocalInvocationID.x;
  for (uint k = 0; k < sum_count; ++k) shared_sums[k][lane] = sums[k];
  barrier();
  for (uint stride = KG_REDUCTION_GROUP / 2; stride > 0; stride >>= 1) {
    if (lane < stride) {
      for (uint k = 0; k < sum_count; ++k) shared_sums[k][lane] += shared_sums[k][lane + stride];
    }
    barrier();
  }
  if (lane < sum_count) partials[gl_WorkGroupID.x * sum_count + lane] = shared_sums[lane][0];
}
