#version 450
// Vulkan wrapper of kernels/projective_association/projective_association.h.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Source { vec4 source[]; };
layout(std430, binding = 1) readonly buffer SourceNormals { vec4 source_normals[]; };  // optional
layout(std430, binding = 2) readonly buffer Target { vec4 target[]; };
layout(std430, binding = 3) readonly buffer TargetNormals { vec4 target_normals[]; };  // optional
layout(std430, binding = 4) readonly buffer Frame { float frame[]; };  // KG_ASSOCIATION_FRAME_*
layout(std430, binding = 5) writeonly buffer Correspondences { int correspondences[]; };

// After the buffers: the rule reads target, target_normals and frame.
#include "kernels/projective_association/projective_association.h"

layout(local_size_x = KG_PROJECTIVE_ASSOCIATION_LOCAL_X) in;
KG_PUSH_PARAMS(ProjectiveAssociationParams);

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.source_count) return;
  if (!correspondence_selected(i, params.source_width, params.subsample)) {
    correspondences[i] = KG_ASSOCIATION_NOT_SELECTED;
    return;
  }
  const vec4 normal = params.use_normals != 0u ? source_normals[i] : vec4(0.0);
  correspondences[i] = projective_associate(source[i], normal, params);
}
