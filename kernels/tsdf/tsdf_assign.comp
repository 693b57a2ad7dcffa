#version 450
// Vulkan wrapper of kernels/tsdf/tsdf.h, pass 2 (assign).
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Keys { uint64_t keys[]; };
layout(std430, binding = 1) buffer SlotBlocks { uint slot_blocks[]; };
layout(std430, binding = 2) writeonly buffer BlockKeys { uint64_t block_keys[]; };
layout(std430, binding = 3) readonly buffer Stamps { uint stamps[]; };
layout(std430, binding = 4) writeonly buffer Active { uint active_blocks[]; };
layout(std430, binding = 5) buffer Status { uint status[]; };  // KG_TSDF_STATUS_*

#define KG_TSDF_ASSIGN_PASS
#include "kernels/tsdf/tsdf.h"

layout(local_size_x = KG_TSDF_LOCAL_X) in;
KG_PUSH_PARAMS(TsdfParams);

void main() {
  const uint slot = gl_GlobalInvocationID.x;
  if (slot >= params.count) return;
  tsdf_assign_slot(slot, params);
}
