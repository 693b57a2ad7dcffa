// The second pass of every two-pass reduction; see shaders/reduce_rows.comp.
typedef struct {
  uint row_count;
  uint column_count;
} ReduceRowsParams;

__kernel void reduce_rows(__global const double* rows, __global double* result,
                          const ReduceRowsParams params) {
  __local double shared_sums[KG_MAX_SUMS * KG_REDUCTION_GROUP];
  double sums[KG_MAX_SUMS];
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  for (uint row = get_local_id(0); row < params.row_count; row += KG_REDUCTION_GROUP) {
    for (uint k = 0; k < params.column_count; ++k) sums[k] += rows[row * params.column_count + k];
  }
  kg_store_group_sums(sums, params.column_count, shared_sums, result);
}
