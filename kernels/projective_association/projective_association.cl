// OpenCL wrapper of kernels/projective_association/projective_association.h.
#include "kernels/projective_association/projective_association.h"

__kernel void projective_association(__global const float4* source,
                                     __global const float4* source_normals,
                                     __global const float4* target,
                                     __global const float4* target_normals,
                                     __global const float* frame, __global int* correspondences,
                                     const ProjectiveAssociationParams params) {
  const uint i = get_global_id(0);
  if (i >= params.source_count) return;
  if (!correspondence_selected(i, params.source_width, params.subsample)) {
    correspondences[i] = KG_ASSOCIATION_NOT_SELECTED;
    return;
  }
  const float4 normal = params.use_normals != 0u ? source_normals[i] : (float4)(0.0f);
  correspondences[i] =
      projective_associate(target, target_normals, frame, source[i], normal, params);
}
