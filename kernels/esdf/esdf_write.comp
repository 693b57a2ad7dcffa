#version 450
// Vulkan wrapper of kernels/esdf/esdf.h, the write pass: one cell per item.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Squared { int64_t squared[]; };
layout(std430, binding = 1) readonly buffer Cells { uint cells[]; };
layout(std430, binding = 2) buffer Esdf { float esdf[]; };

#include "kernels/esdf/esdf.h"

layout(local_size_x = KG_ESDF_LOCAL_X) in;
KG_PUSH_PARAMS(EsdfParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  esdf[i] = esdf_value(squared[i], esdf[i], cells[i], params);
}
