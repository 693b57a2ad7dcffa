// Organized normals from the 4-neighbours (rules in include/kartograf/geometry/normals.hpp): one
// tangent per image axis from the usable neighbours, their cross product, unit length, facing the
// camera; all NaN where there is no tangent on an axis, the centre is invalid or the tangents are
// parallel.
#ifndef KARTOGRAF_KERNELS_NORMALS_H
#define KARTOGRAF_KERNELS_NORMALS_H
#include "shaders/prelude.h"

#define KG_NORMALS_LOCAL_X 16
#define KG_NORMALS_LOCAL_Y 16

KG_RULES_BEGIN

KG_PARAMS_BEGIN(NormalsParams)
KG_PARAM(uint, width)
KG_PARAM(uint, height)
KG_PARAM(float, max_depth_jump)  // relative to the centre's depth
KG_PARAMS_END(NormalsParams)

KG_INLINE bool normal_neighbour_usable(float4 neighbour, float4 centre, float max_depth_jump) {
  return !kg_isnan(neighbour.x) && kg_fabs(neighbour.z - centre.z) <= max_depth_jump * centre.z;
}

// The tangent along one axis in xyz; w = 1 when there is one, 0 when neither neighbour is usable.
KG_INLINE float4 normal_tangent(float4 before, float4 centre, float4 after, float max_depth_jump) {
  const bool has_before = normal_neighbour_usable(before, centre, max_depth_jump);
  const bool has_after = normal_neighbour_usable(after, centre, max_depth_jump);
  if (has_before && has_after) return KG_FLOAT4_XYZ_W(kg_xyz(after) - kg_xyz(before), 1.0f);
  if (has_after) return KG_FLOAT4_XYZ_W(kg_xyz(after) - kg_xyz(centre), 1.0f);
  if (has_before) return KG_FLOAT4_XYZ_W(kg_xyz(centre) - kg_xyz(before), 1.0f);
  return KG_FLOAT4(0.0f, 0.0f, 0.0f, 0.0f);
}

// The normal at `centre` from its left/right and up/down neighbours (all NaN outside the image).
KG_INLINE float4 normal_from_neighbours(float4 centre, float4 left, float4 right, float4 up,
                                        float4 down, NormalsParams p) {
  if (kg_isnan(centre.x)) return KG_INVALID_POINT;
  const float4 along_x = normal_tangent(left, centre, right, p.max_depth_jump);
  if (along_x.w == 0.0f) return KG_INVALID_POINT;
  const float4 along_y = normal_tangent(up, centre, down, p.max_depth_jump);
  if (along_y.w == 0.0f) return KG_INVALID_POINT;
  const float3 n = cross(kg_xyz(along_x), kg_xyz(along_y));
  const float length_sq = dot(n, n);
  // Relative to the tangents' lengths: parallel tangents give no normal at any scale.
  if (!(length_sq > 1e-12f * dot(kg_xyz(along_x), kg_xyz(along_x)) *
                        dot(kg_xyz(along_y), kg_xyz(along_y)))) {
    return KG_INVALID_POINT;
  }
  const float inverse_length = kg_rsqrt(length_sq);
  const float sign = dot(n, kg_xyz(centre)) > 0.0f ? -1.0f : 1.0f;
  return KG_FLOAT4(sign * n.x * inverse_length, sign * n.y * inverse_length,
                   sign * n.z * inverse_length, 0.0f);
}

KG_RULES_END

#endif
