#version 450
// Vulkan wrapper of kernels/esdf/esdf.h, the seed pass: one cell per item.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Cells { uint cells[]; };
layout(std430, binding = 1) writeonly buffer Squared { int64_t squared[]; };

#include "kernels/esdf/esdf.h"

layout(local_size_x = KG_ESDF_LOCAL_X) in;
KG_PUSH_PARAMS(EsdfParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  squared[i] = esdf_seed_value(cells[i], params);
}
