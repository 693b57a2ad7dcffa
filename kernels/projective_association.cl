// Projective data association; rules in include/kartograf/registration/projective_association.hpp.
// Writes one entry per source point: the target pixel index, -1 (no match) or -2 (not selected).
typedef struct {
  uint source_count;
  uint source_width;  // 0: unorganized source
  uint target_width;
  uint target_height;
  uint subsample;
  uint use_normals;
  uint search_radius;
} ProjectiveAssociationParams;

// Float arithmetic, each product and sum in one fixed order, no fused multiply-adds (see the .comp).
inline float3 kg_rotate(__global const float* frame, float3 p) {
#pragma OPENCL FP_CONTRACT OFF
  return (float3)(frame[0] * p.x + frame[1] * p.y + frame[2] * p.z,
                  frame[3] * p.x + frame[4] * p.y + frame[5] * p.z,
                  frame[6] * p.x + frame[7] * p.y + frame[8] * p.z);
}

inline int kg_associate(uint i, __global const float4* source, __global const float4* source_normals,
                        __global const float4* target, __global const float4* target_normals,
                        __global const float* frame, const ProjectiveAssociationParams* params) {
#pragma OPENCL FP_CONTRACT OFF
  const uint row = params->source_width == 0 ? 0 : i / params->source_width;
  if ((i + row) % params->subsample != 0) return -2;
  const float4 p = source[i];
  if (!kg_is_valid_point(p)) return -1;
  const float3 moved = kg_rotate(frame, p.xyz) + (float3)(frame[9], frame[10], frame[11]);
  if (!(moved.z > 0.0f)) return -1;
  const float u = floor(frame[12] * moved.x / moved.z + frame[14] + 0.5f);
  const float v = floor(frame[13] * moved.y / moved.z + frame[15] + 0.5f);
  const int r = (int)params->search_radius;
  // Pixels outside the image are skipped below; bound first so the conversion cannot overflow.
  if (!(u >= (float)(-r) && v >= (float)(-r) && u < (float)(params->target_width + r) &&
        v < (float)(params->target_height + r))) {
    return -1;
  }
  float3 rotated_normal = (float3)(0.0f);
  if (params->use_normals != 0) {
    const float4 np = source_normals[i];
    if (!kg_is_valid_point(np)) return -1;
    rotated_normal = kg_rotate(frame, np.xyz);
  }
  int best = -1;
  float best_distance_sq = frame[16];  // max distance^2: farther candidates never win
  for (int dv = -r; dv <= r; ++dv) {
    for (int du = -r; du <= r; ++du) {
      const int x = (int)u + du;
      const int y = (int)v + dv;
      if (x < 0 || y < 0 || x >= (int)params->target_width || y >= (int)params->target_height) continue;
      const uint j = (uint)y * params->target_width + (uint)x;
      const float4 q = target[j];
      if (!kg_is_valid_point(q)) continue;
      const float3 d = moved - q.xyz;
      const float distance_sq = d.x * d.x + d.y * d.y + d.z * d.z;
      if (!(distance_sq <= best_distance_sq) || (best >= 0 && distance_sq == best_distance_sq)) continue;
      if (params->use_normals != 0) {
        const float4 nq = target_normals[j];
        const float cosine = rotated_normal.x * nq.x + rotated_normal.y * nq.y + rotated_normal.z * nq.z;
        if (!kg_is_valid_point(nq) || !(cosine >= frame[17])) continue;
      }
      best = (int)j;
      best_distance_sq = distance_sq;
    }
  }
  return best;
}

__kernel void projective_association(__global const float4* source, __global const float4* source_normals,
                                     __global const float4* target, __global const float4* target_normals,
                                     __global const float* frame, __global int* correspondences,
                                     const ProjectiveAssociationParams params) {
  const uint i = get_global_id(0);
  if (i >= params.source_count) return;
  correspondences[i] = kg_associate(i, source, source_normals, target, target_normals, frame, &params);
}
