// Projective data association (rules in include/kartograf/registration/projective_association.hpp):
// source point i, moved into the target's frame, projects to a target pixel; its match is the
// nearest valid target point within search_radius pixels of it and max_distance of the moved point
// (ties: the first in row-major order) whose normal is within the normal gate. One entry per
// source point: the target pixel index, KG_ASSOCIATION_NO_MATCH or KG_ASSOCIATION_NOT_SELECTED.
// Float arithmetic (single precision is what GPUs are fast at): the pixel is off by ~1e-4 of a
// pixel and the gates by ~1 um at 5 m. Each product and sum is spelled out in one fixed order with
// no fused multiply-adds, so every backend rounds the same way.
#ifndef KARTOGRAF_KERNELS_PROJECTIVE_ASSOCIATION_H
#define KARTOGRAF_KERNELS_PROJECTIVE_ASSOCIATION_H
#include "kernels/correspondence/selection.h"
#include "shaders/prelude.h"

#define KG_PROJECTIVE_ASSOCIATION_LOCAL_X 64
#define KG_ASSOCIATION_NO_MATCH (-1)
#define KG_ASSOCIATION_NOT_SELECTED (-2)

// The frame buffer's floats: R (row-major 3x3), t, the target camera, the two gates.
#define KG_ASSOCIATION_FRAME_R 0
#define KG_ASSOCIATION_FRAME_T 9
#define KG_ASSOCIATION_FRAME_FX 12
#define KG_ASSOCIATION_FRAME_FY 13
#define KG_ASSOCIATION_FRAME_CX 14
#define KG_ASSOCIATION_FRAME_CY 15
#define KG_ASSOCIATION_FRAME_MAX_DISTANCE_SQ 16
#define KG_ASSOCIATION_FRAME_MIN_COSINE 17
#define KG_ASSOCIATION_FRAME_VALUES 18

KG_RULES_BEGIN

KG_PARAMS_BEGIN(ProjectiveAssociationParams)
KG_PARAM(uint, source_count)
KG_PARAM(uint, source_width)  // 0: unorganized source
KG_PARAM(uint, target_width)
KG_PARAM(uint, target_height)
KG_PARAM(uint, subsample)
KG_PARAM(uint, use_normals)  // 0: the normal buffers are absent
KG_PARAM(uint, search_radius)
KG_PARAMS_END(ProjectiveAssociationParams)

// The frame's rotation (at KG_ASSOCIATION_FRAME_R) times v, without fused multiply-adds.
KG_INLINE float3 projective_rotate(KG_BUFFER_PARAM(const float, frame) float3 v) {
#if defined(__OPENCL_C_VERSION__)
#pragma OPENCL FP_CONTRACT OFF
#endif
  KG_PRECISE const float3 r = KG_FLOAT3(frame[0] * v.x + frame[1] * v.y + frame[2] * v.z,
                                        frame[3] * v.x + frame[4] * v.y + frame[5] * v.z,
                                        frame[6] * v.x + frame[7] * v.y + frame[8] * v.z);
  return r;
}

// The nearest gated target point within the search window around pixel (column, row).
KG_INLINE int projective_best_target(KG_BUFFER_PARAM(const float4, target)
                                         KG_BUFFER_PARAM(const float4, target_normals)
                                             KG_BUFFER_PARAM(const float, frame) float3 moved,
                                     float3 rotated_normal, int column, int row,
                                     ProjectiveAssociationParams p) {
#if defined(__OPENCL_C_VERSION__)
#pragma OPENCL FP_CONTRACT OFF
#endif
  const int r = KG_INT(p.search_radius);
  const int width = KG_INT(p.target_width);
  const int height = KG_INT(p.target_height);
  int best = KG_ASSOCIATION_NO_MATCH;
  float best_distance_sq = frame[KG_ASSOCIATION_FRAME_MAX_DISTANCE_SQ];  // farther never wins
  for (int y = max(0, row - r); y <= min(height - 1, row + r); ++y) {
    for (int x = max(0, column - r); x <= min(width - 1, column + r); ++x) {
      const uint j = KG_UINT(y) * p.target_width + KG_UINT(x);
      const float4 q = target[j];
      if (kg_isnan(q.x)) continue;
      KG_PRECISE const float dx = moved.x - q.x;
      KG_PRECISE const float dy = moved.y - q.y;
      KG_PRECISE const float dz = moved.z - q.z;
      KG_PRECISE const float distance_sq = dx * dx + dy * dy + dz * dz;
      if (!(distance_sq <= best_distance_sq) || (best >= 0 && distance_sq == best_distance_sq)) {
        continue;
      }
      if (p.use_normals != 0u) {
        const float4 nq = target_normals[j];
        KG_PRECISE const float cosine =
            rotated_normal.x * nq.x + rotated_normal.y * nq.y + rotated_normal.z * nq.z;
        if (kg_isnan(nq.x) || !(cosine >= frame[KG_ASSOCIATION_FRAME_MIN_COSINE])) continue;
      }
      best = KG_INT(j);
      best_distance_sq = distance_sq;
    }
  }
  return best;
}

// The match of selected source point p (with normal n when use_normals).
KG_INLINE int projective_associate(KG_BUFFER_PARAM(const float4, target)
                                       KG_BUFFER_PARAM(const float4, target_normals)
                                           KG_BUFFER_PARAM(const float, frame) float4 p,
                                   float4 n, ProjectiveAssociationParams params) {
#if defined(__OPENCL_C_VERSION__)
#pragma OPENCL FP_CONTRACT OFF
#endif
  if (kg_isnan(p.x)) return KG_ASSOCIATION_NO_MATCH;
  const float3 r = projective_rotate(KG_BUFFER_ARG(frame) kg_xyz(p));
  KG_PRECISE const float3 moved =
      KG_FLOAT3(r.x + frame[KG_ASSOCIATION_FRAME_T], r.y + frame[KG_ASSOCIATION_FRAME_T + 1],
                r.z + frame[KG_ASSOCIATION_FRAME_T + 2]);
  if (!(moved.z > 0.0f)) return KG_ASSOCIATION_NO_MATCH;
  KG_PRECISE const float u = floor(frame[KG_ASSOCIATION_FRAME_FX] * moved.x / moved.z +
                                   frame[KG_ASSOCIATION_FRAME_CX] + 0.5f);
  KG_PRECISE const float v = floor(frame[KG_ASSOCIATION_FRAME_FY] * moved.y / moved.z +
                                   frame[KG_ASSOCIATION_FRAME_CY] + 0.5f);
  const int radius = KG_INT(params.search_radius);
  // Pixels outside the image are skipped in the search; bound first so that the conversion to
  // int cannot overflow.
  if (!(u >= KG_FLOAT(-radius) && v >= KG_FLOAT(-radius) &&
        u < KG_FLOAT(KG_INT(params.target_width) + radius) &&
        v < KG_FLOAT(KG_INT(params.target_height) + radius))) {
    return KG_ASSOCIATION_NO_MATCH;
  }
  float3 rotated_normal = KG_FLOAT3(0.0f, 0.0f, 0.0f);
  if (params.use_normals != 0u) {
    if (kg_isnan(n.x)) return KG_ASSOCIATION_NO_MATCH;
    rotated_normal = projective_rotate(KG_BUFFER_ARG(frame) kg_xyz(n));
  }
  return projective_best_target(KG_BUFFER_ARG(target) KG_BUFFER_ARG(target_normals)
                                    KG_BUFFER_ARG(frame) moved,
                                rotated_normal, KG_INT(u), KG_INT(v), params);
}

KG_RULES_END

#endif
