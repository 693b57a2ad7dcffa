// The second pass of every two-pass reduction, one work-group per column; see
// shaders/reduce_rows.comp.
typedef struct {
  uint row_count;
  uint column_count;
} ReduceRowsParams;

__kernel void reduce_rows(__global const double* rows, __global double* result,
                          const ReduceRowsParams params) {
  __local double column_sums[KG_REDUCTION_GROUP];
  const uint lane = get_local_id(0);
  const uint column = get_group_id(0);
  double sum = 0.0;
  for (uint row = lane; row < params.row_count; row += KG_REDUCTION_GROUP) {
    sum += rows[row * params.column_count + column];
  }
  column_sums[lane] = sum;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = KG_REDUCTION_GROUP / 2; stride > 0; stride >>= 1) {
    if (lane < stride) column_sums[lane] += column_sums[lane + stride];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (lane == 0) result[column] = column_sums[0];
}
