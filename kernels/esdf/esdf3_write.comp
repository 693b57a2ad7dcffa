#version 450
// Vulkan wrapper of kernels/esdf/esdf3.h, the write pass: one cell of the inner box per item.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Squared { int64_t squared[]; };
layout(std430, binding = 1) buffer Distances { float distances[]; };

#include "kernels/esdf/esdf3.h"

layout(local_size_x = KG_ESDF_LOCAL_X) in;
KG_PUSH_PARAMS(Esdf3Params);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  const uint at = esdf3_box_cell(i, params.box_x, params.box_y, params.box_z, params.box_dims_x,
                                 params.box_dims_y, params);
  distances[at] = esdf3_distance(squared[esdf3_outer_index(i, params)], params);
}
