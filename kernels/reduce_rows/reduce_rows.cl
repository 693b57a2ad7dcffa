// OpenCL wrapper of kernels/reduce_rows/reduce_rows.h, as kernels/reduce_rows/reduce_rows.comp.
#include "kernels/reduce_rows/reduce_rows.h"

__kernel void reduce_rows(__global const double* rows, __global double* result,
                          const ReduceRowsParams params) {
  __local double column_sums[KG_REDUCE_ROWS_LOCAL_X];
  const uint lane = get_local_id(0);
  const uint column = get_group_id(0);
  double sum = 0.0;
  for (uint row = lane; row < params.row_count; row += KG_REDUCE_ROWS_LOCAL_X) {
    sum += rows[row * params.column_count + column];
  }
  column_sums[lane] = sum;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = KG_REDUCE_ROWS_LOCAL_X / 2; stride > 0; stride >>= 1) {
    if (lane < stride) column_sums[lane] += column_sums[lane + stride];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (lane == 0) result[column] = column_sums[0];
}
