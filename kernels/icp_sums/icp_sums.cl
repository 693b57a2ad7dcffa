// OpenCL wrapper of kernels/icp_sums/icp_sums.h: the point-to-point and point-to-plane sums, one
// row per work-group (kg_store_group_sums, kernels/work_group/group_sums.h).
#include "kernels/icp_sums/icp_sums.h"
#include "kernels/work_group/group_sums.h"

// Source point i's pair, when it has one that counts; `considered` counts i when it is valid and
// selected (as load_pair in icp_sums.glsl and icp_sums_cpu.cpp). The frame is read here, for each
// pair that gets this far, not once before the loop: held across the loop, its 20 doubles cost the
// registers that kept NVIDIA's OpenCL sums ~50 % slower (docs/benchmarks.md, issue 22).
KG_FORCE_INLINE bool icp_load_pair(uint i, __global const float4* source,
                                   __global const float4* target,
                                   __global const int* correspondences,
                                   __global const float* weights,
                                   __global const double* frame_values, IcpSumsParams params,
                                   double* considered, IcpFrame* frame, IcpPair* pair) {
  const int entry = params.has_correspondences != 0u ? correspondences[i] : (int)i;
  if (!icp_is_selected(entry)) return false;
  const float4 p = source[i];
  if (kg_isnan(p.x)) return false;
  *considered += 1.0;
  const int j = icp_target_of(entry, params);
  if (j < 0) return false;
  const double weight = params.has_weights != 0u ? (double)weights[i] : 1.0;
  if (!(weight > 0.0)) return false;
  const float4 q = target[j];
  if (kg_isnan(q.x)) return false;
  *frame = KG_ICP_READ_FRAME(frame_values);
  *pair = icp_pair(p, q, (uint)j, weight, *frame);
  return icp_pair_in_range(*pair, *frame);
}

// Both kernels' body, inlined into each with a constant `with_normals` (point-to-plane: the target
// normals are read) so that each kernel holds only its own accumulation.
KG_FORCE_INLINE void icp_sum_pairs(__global const float4* source, __global const float4* target,
                                   __global const float4* target_normals,
                                   __global const int* correspondences,
                                   __global const float* weights,
                                   __global const double* frame_values, __global double* partials,
                                   IcpSumsParams params, __local double* shared_sums,
                                   const bool with_normals) {
  double sums[KG_MAX_SUMS];
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  double considered = 0.0;
  const uint stride = get_num_groups(0) * KG_ICP_SUMS_LOCAL_X;
  for (uint i = get_global_id(0); i < params.pair_count; i += stride) {
    IcpFrame frame;
    IcpPair pair;
    if (!icp_load_pair(i, source, target, correspondences, weights, frame_values, params,
                       &considered, &frame, &pair)) {
      continue;
    }
    if (!with_normals) {
      icp_add_point_to_point(KG_ACCUMULATOR_ARG(sums) pair, frame, params.robust_kernel);
      continue;
    }
    const float4 normal = target_normals[pair.target_index];
    if (!kg_isnan(normal.x)) icp_add_point_to_plane(KG_ACCUMULATOR_ARG(sums) pair, normal, frame, params.robust_kernel);
  }
  if (!with_normals) {
    sums[KG_ICP_POINT_CONSIDERED] = considered;
    kg_store_group_sums(partials, shared_sums, sums, KG_ICP_POINT_SUMS);
  } else {
    sums[KG_ICP_PLANE_CONSIDERED] = considered;
    kg_store_group_sums(partials, shared_sums, sums, KG_ICP_PLANE_SUMS);
  }
}

__kernel void icp_point_to_point(__global const float4* source, __global const float4* target,
                                 __global const int* correspondences, __global const float* weights,
                                 __global const double* frame_values, __global double* partials,
                                 const IcpSumsParams params) {
  __local double shared_sums[KG_GROUP_SUMS_SHARED];
  icp_sum_pairs(source, target, 0, correspondences, weights, frame_values, partials, params,
                shared_sums, false);
}

__kernel void icp_point_to_plane(__global const float4* source, __global const float4* target,
                                 __global const float4* target_normals,
                                 __global const int* correspondences, __global const float* weights,
                                 __global const double* frame_values, __global double* partials,
                                 const IcpSumsParams params) {
  __local double shared_sums[KG_GROUP_SUMS_SHARED];
  icp_sum_pairs(source, target, target_normals, correspondences, weights, frame_values, partials,
                params, shared_sums, true);
}
