// The Vulkan wrappers of kernels/icp_sums/icp_sums.h: one row of sums per work-group.
// icp_point_to_plane.comp defines KG_ICP_WITH_NORMALS (the target normals are then binding 2);
// icp_point_to_point.comp does not.
#extension GL_GOOGLE_include_directive : require
#include "kernels/icp_sums/icp_sums.h"  // GLSL: declares the invocation's row, sums[]

#ifdef KG_ICP_WITH_NORMALS
#define KG_ICP_NORMAL_BINDINGS 1
#define KG_ICP_ROW_CONSIDERED KG_ICP_PLANE_CONSIDERED
#define KG_ICP_ROW_SUMS KG_ICP_PLANE_SUMS
#else
#define KG_ICP_NORMAL_BINDINGS 0
#define KG_ICP_ROW_CONSIDERED KG_ICP_POINT_CONSIDERED
#define KG_ICP_ROW_SUMS KG_ICP_POINT_SUMS
#endif

layout(local_size_x = KG_ICP_SUMS_LOCAL_X) in;

layout(std430, binding = 0) readonly buffer Source { vec4 source[]; };
layout(std430, binding = 1) readonly buffer Target { vec4 target[]; };
#ifdef KG_ICP_WITH_NORMALS
layout(std430, binding = 2) readonly buffer TargetNormals { vec4 target_normals[]; };
#endif
layout(std430, binding = 2 + KG_ICP_NORMAL_BINDINGS) readonly buffer Correspondences {
  int correspondences[];
};
layout(std430, binding = 3 + KG_ICP_NORMAL_BINDINGS) readonly buffer Weights { float weights[]; };
layout(std430, binding = 4 + KG_ICP_NORMAL_BINDINGS) readonly buffer Frame { double frame_values[]; };
layout(std430, binding = 5 + KG_ICP_NORMAL_BINDINGS) writeonly buffer Partials { double partials[]; };
KG_PUSH_PARAMS(IcpSumsParams);

#include "kernels/work_group/group_sums.h"

// Source point i's pair, when it has one that counts; `considered` counts i when it is valid and
// selected (as load_pair in icp_sums.cl and icp_sums_cpu.cpp).
bool load_pair(uint i, IcpFrame frame, inout double considered, out IcpPair pair) {
  int entry = int(i);
  if (params.has_correspondences != 0u) entry = correspondences[i];
  if (!icp_is_selected(entry)) return false;
  const vec4 p = source[i];
  if (kg_isnan(p.x)) return false;
  considered += 1.0;
  const int j = icp_target_of(entry, params);
  if (j < 0) return false;
  double weight = 1.0;
  if (params.has_weights != 0u) weight = double(weights[i]);
  if (!(weight > 0.0)) return false;
  const vec4 q = target[j];
  if (kg_isnan(q.x)) return false;
  pair = icp_pair(p, q, uint(j), weight, frame);
  return icp_pair_in_range(pair, frame);
}

void main() {
  for (uint k = 0; k < KG_MAX_SUMS; ++k) sums[k] = 0.0;
  const IcpFrame frame = KG_ICP_READ_FRAME(frame_values);
  double considered = 0.0;
  const uint stride = gl_NumWorkGroups.x * KG_ICP_SUMS_LOCAL_X;
  for (uint i = gl_GlobalInvocationID.x; i < params.pair_count; i += stride) {
    IcpPair pair;
    if (!load_pair(i, frame, considered, pair)) continue;
#ifdef KG_ICP_WITH_NORMALS
    const vec4 normal = target_normals[pair.target_index];
    if (!kg_isnan(normal.x)) icp_add_point_to_plane(KG_ACCUMULATOR_ARG(sums) pair, normal, frame, params.robust_kernel);
#else
    icp_add_point_to_point(KG_ACCUMULATOR_ARG(sums) pair, frame, params.robust_kernel);
#endif
  }
  sums[KG_ICP_ROW_CONSIDERED] = considered;
  kg_store_group_sums(KG_BUFFER_ARG(partials) KG_SHARED_ARG(shared_sums) sums, KG_ICP_ROW_SUMS);
}
