#version 450
// Vulkan wrapper of kernels/voxel_downsample/voxel_downsample.h, pass 4 (assign).
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer PointSlots { int point_slots[]; };
layout(std430, binding = 1) readonly buffer First { uint first[]; };
layout(std430, binding = 2) readonly buffer Counts { uint counts[]; };  // scanned offsets
layout(std430, binding = 3) readonly buffer Keys { uint64_t keys[]; };
layout(std430, binding = 4) writeonly buffer VoxelOfSlot { uint voxel_of_slot[]; };
layout(std430, binding = 5) writeonly buffer VoxelKeys { uint64_t voxel_keys[]; };

// After the buffers: the rule reads and writes them.
#define KG_VOXEL_ORDER_PASS
#define KG_VOXEL_ASSIGN_PASS
#include "kernels/voxel_downsample/voxel_downsample.h"

layout(local_size_x = KG_VOXEL_DOWNSAMPLE_LOCAL_X) in;
KG_PUSH_PARAMS(VoxelChunkParams);

void main() { voxel_assign_chunk(gl_GlobalInvocationID.x, params); }
