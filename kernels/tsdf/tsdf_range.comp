#version 450
// Vulkan wrapper of kernels/tsdf/tsdf.h, the ray cast's tile ranges: one block per item.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer BlockKeys { uint64_t block_keys[]; };
layout(std430, binding = 1) buffer Ranges { uint ranges[]; };

#define KG_TSDF_RANGE_PASS
#include "kernels/tsdf/tsdf.h"

layout(local_size_x = KG_TSDF_LOCAL_X) in;
KG_PUSH_PARAMS(TsdfParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  tsdf_range_block(block_keys[i], params);
}
