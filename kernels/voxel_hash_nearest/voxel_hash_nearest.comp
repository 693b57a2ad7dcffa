#version 450
// Vulkan wrapper of kernels/voxel_hash_nearest/voxel_hash_nearest.h.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Source { vec4 source[]; };
layout(std430, binding = 1) readonly buffer SourceNormals { vec4 source_normals[]; };  // optional
layout(std430, binding = 2) readonly buffer TargetNormals { vec4 target_normals[]; };  // optional
layout(std430, binding = 3) readonly buffer CellKeys { uint64_t cell_keys[]; };        // per slot
layout(std430, binding = 4) readonly buffer CellRanges { uvec2 cell_ranges[]; };       // first, count
layout(std430, binding = 5) readonly buffer CellPoints { vec4 cell_points[]; };        // by cell
layout(std430, binding = 6) readonly buffer CellIndices { uint cell_indices[]; };
layout(std430, binding = 7) readonly buffer Frame { double frame[]; };  // KG_NEAREST_FRAME_*
layout(std430, binding = 8) writeonly buffer Correspondences { int correspondences[]; };

// After the buffers: the rule reads them.
#include "kernels/voxel_hash_nearest/voxel_hash_nearest.h"

layout(local_size_x = KG_VOXEL_HASH_NEAREST_LOCAL_X) in;
KG_PUSH_PARAMS(VoxelHashNearestParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.source_count) return;
  correspondences[i] = voxel_hash_nearest_item(i, params);
}
