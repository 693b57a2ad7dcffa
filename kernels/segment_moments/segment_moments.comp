#version 450
// Vulkan wrapper of kernels/segment_moments/segment_moments.h: one point per invocation, its
// terms added with 64-bit atomics.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_int64 : require
#include "kernels/segment_moments/segment_moments.h"

layout(local_size_x = KG_SEGMENT_MOMENTS_LOCAL_X) in;

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Labels { uint labels[]; };
layout(std430, binding = 2) buffer Moments { int64_t moments[]; };
layout(std430, binding = 3) buffer Status { uint status[]; };
KG_PUSH_PARAMS(SegmentMomentsParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.point_count) return;
  const uint label = labels[i];
  const vec4 p = points[i];
  const uint outcome = segment_moment_outcome(label, p, params);
  if (outcome == KG_SEGMENT_MOMENT_BAD_LABEL) atomicAdd(status[KG_SEGMENT_MOMENTS_BAD_LABEL], 1u);
  if (outcome == KG_SEGMENT_MOMENT_TOO_FAR) atomicAdd(status[KG_SEGMENT_MOMENTS_TOO_FAR], 1u);
  if (outcome != KG_SEGMENT_MOMENT_ADD) return;
  const SegmentMomentOffset d = segment_moment_offset(p, params);
  const uint base = label * KG_SEGMENT_MOMENT_VALUES;
  for (uint slot = 0u; slot < KG_SEGMENT_MOMENT_VALUES; ++slot) {
    atomicAdd(moments[base + slot], segment_moment_term(d, slot, params));
  }
}
