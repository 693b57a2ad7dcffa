#version 450
// Vulkan wrapper of kernels/esdf/esdf3.h, the seed pass: one cell of the box per item.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Marks { uint marks[]; };
layout(std430, binding = 1) writeonly buffer Squared { int64_t squared[]; };

#include "kernels/esdf/esdf3.h"

layout(local_size_x = KG_ESDF_LOCAL_X) in;
KG_PUSH_PARAMS(Esdf3Params);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  const uint at = esdf3_box_cell(i, params.box_x, params.box_y, params.box_z, params.box_dims_x,
                                 params.box_dims_y, params);
  squared[i] = esdf3_seed_value(marks[at]);
}
