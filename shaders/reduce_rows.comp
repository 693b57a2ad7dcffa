#version 450
// The second pass of every two-pass reduction: `row_count` rows of `column_count` doubles are
// added into one row. One work-group per column: each invocation adds every 64th row in order,
// then a fixed-order tree adds the invocations' sums, so the result does not vary run to run.
// (One work-group for all columns, with a private array indexed at run time, spilled to local
// memory and took ~30 us a call on an H100: half of the ICP's device time.)
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = KG_REDUCTION_GROUP) in;

layout(std430, binding = 0) readonly buffer Rows { double rows[]; };
layout(std430, binding = 1) writeonly buffer Result { double result[]; };  // one row

layout(push_constant) uniform Params {
  uint row_count;
  uint column_count;
} params;

shared double column_sums[KG_REDUCTION_GROUP];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint column = gl_WorkGroupID.x;
  double sum = 0.0;
  for (uint row = lane; row < params.row_count; row += KG_REDUCTION_GROUP) {
    sum += rows[row * params.column_count + column];
  }
  column_sums[lane] = sum;
  barrier();
  for (uint stride = KG_REDUCTION_GROUP / 2; stride > 0; stride >>= 1) {
    if (lane < stride) column_sums[lane] += column_sums[lane + stride];
    barrier();
  }
  if (lane == 0) result[column] = column_sums[0];
}
