#version 450
// Vulkan wrapper of kernels/reduce_rows/reduce_rows.h. One work-group per column: each invocation
// adds every KG_REDUCTION_GROUP-th row in order, then a fixed-order tree adds the invocations'
// sums. (One work-group for all columns, with a private array indexed at run time, spilled to
// local memory and took ~30 us a call on an H100: half of the ICP's device time.)
#extension GL_GOOGLE_include_directive : require
#include "kernels/reduce_rows/reduce_rows.h"

layout(local_size_x = KG_REDUCE_ROWS_LOCAL_X) in;

layout(std430, binding = 0) readonly buffer Rows { double rows[]; };
layout(std430, binding = 1) writeonly buffer Result { double result[]; };  // one row
KG_PUSH_PARAMS(ReduceRowsParams);

shared double column_sums[KG_REDUCE_ROWS_LOCAL_X];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint column = gl_WorkGroupID.x;
  double sum = 0.0;
  for (uint row = lane; row < params.row_count; row += KG_REDUCE_ROWS_LOCAL_X) {
    sum += rows[row * params.column_count + column];
  }
  column_sums[lane] = sum;
  barrier();
  for (uint stride = KG_REDUCE_ROWS_LOCAL_X / 2; stride > 0; stride >>= 1) {
    if (lane < stride) column_sums[lane] += column_sums[lane + stride];
    barrier();
  }
  if (lane == 0) result[column] = column_sums[0];
}
