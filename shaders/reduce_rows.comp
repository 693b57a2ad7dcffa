#version 450
// The second pass of every two-pass reduction: one work-group adds `rows` rows of `columns`
// doubles into one row, in a fixed order.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = KG_REDUCTION_GROUP) in;

layout(std430, binding = 0) readonly buffer Rows { double rows[]; };
layout(std430, binding = 1) buffer Partials { double partials[]; };  // the single result row

layout(push_constant) uniform Params {
  uint row_count;
  uint column_count;
} params;

#include "reduction.glsl"

void main() {
  double sums[KG_MAX_SUMS];
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  for (uint row = gl_LocalInvocationID.x; row < params.row_count; row += KG_REDUCTION_GROUP) {
    for (uint k = 0; k < params.column_count; ++k) sums[k] += rows[row * params.column_count + k];
  }
  store_group_sums(sums, params.column_count);
}
