#version 450
// Vulkan wrapper of kernels/subsample/subsample.h.
#extension GL_GOOGLE_include_directive : require
#include "kernels/subsample/subsample.h"

layout(local_size_x = KG_SUBSAMPLE_LOCAL_X) in;

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Normals { vec4 normals[]; };  // optional
layout(std430, binding = 2) readonly buffer Colors { uint colors[]; };    // optional
layout(std430, binding = 3) writeonly buffer OutPoints { vec4 out_points[]; };
layout(std430, binding = 4) writeonly buffer OutNormals { vec4 out_normals[]; };
layout(std430, binding = 5) writeonly buffer OutColors { uint out_colors[]; };
KG_PUSH_PARAMS(SubsampleParams);

void main() {
  const uint m = gl_GlobalInvocationID.x;
  if (m >= params.out_count) return;
  const uint i = subsample_source_index(m, params);
  out_points[m] = points[i];
  if (params.has_normals != 0u) out_normals[m] = normals[i];
  if (params.has_colors != 0u) out_colors[m] = colors[i];
}
