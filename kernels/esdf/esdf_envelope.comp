#version 450
// Vulkan wrapper of kernels/esdf/esdf.h, the line pass: one column or row per item.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer LineIn { int64_t line_in[]; };
layout(std430, binding = 1) writeonly buffer LineOut { int64_t line_out[]; };
layout(std430, binding = 2) buffer Apex { uint apex[]; };
layout(std430, binding = 3) buffer StartNum { int64_t start_num[]; };
layout(std430, binding = 4) buffer StartDen { int64_t start_den[]; };

#define KG_ESDF_ENVELOPE_PASS
#include "kernels/esdf/esdf.h"

layout(local_size_x = KG_ESDF_LOCAL_X) in;
KG_PUSH_PARAMS(EsdfParams);

void main() {
  const uint line = gl_GlobalInvocationID.x;
  if (line >= params.count) return;
  esdf_envelope_line(line, params);
}
