// Organized normals from 4-neighbours; rules in include/kartograf/geometry/normals.hpp.
typedef struct {
  uint width;
  uint height;
  float max_depth_jump;
} NormalParams;

inline float4 kg_point_at(__global const float4* points, int x, int y, const NormalParams* params) {
  if (x < 0 || y < 0 || x >= (int)params->width || y >= (int)params->height) return KG_INVALID_POINT;
  return points[(uint)y * params->width + (uint)x];
}

inline bool kg_usable(float4 neighbour, float4 centre, float max_depth_jump) {
  return kg_is_valid_point(neighbour) && fabs(neighbour.z - centre.z) <= max_depth_jump * centre.z;
}

// Tangent along one axis; w = 0 when there is none.
inline float4 kg_tangent(float4 before, float4 centre, float4 after, float max_depth_jump) {
  const bool has_before = kg_usable(before, centre, max_depth_jump);
  const bool has_after = kg_usable(after, centre, max_depth_jump);
  if (has_before && has_after) return (float4)(after.xyz - before.xyz, 1.0f);
  if (has_after) return (float4)(after.xyz - centre.xyz, 1.0f);
  if (has_before) return (float4)(centre.xyz - before.xyz, 1.0f);
  return (float4)(0.0f);
}

__kernel void normals(__global const float4* points, __global float4* normals,
                      const NormalParams params) {
  const int x = get_global_id(0);
  const int y = get_global_id(1);
  if (x >= (int)params.width || y >= (int)params.height) return;
  const uint index = (uint)y * params.width + (uint)x;
  const float4 centre = points[index];
  float4 normal = KG_INVALID_POINT;
  if (kg_is_valid_point(centre)) {
    const float4 along_x = kg_tangent(kg_point_at(points, x - 1, y, &params), centre,
                                      kg_point_at(points, x + 1, y, &params), params.max_depth_jump);
    const float4 along_y = kg_tangent(kg_point_at(points, x, y - 1, &params), centre,
                                      kg_point_at(points, x, y + 1, &params), params.max_depth_jump);
    if (along_x.w != 0.0f && along_y.w != 0.0f) {
      float3 n = cross(along_x.xyz, along_y.xyz);
      const float length_sq = dot(n, n);
      const float scale_sq = dot(along_x.xyz, along_x.xyz) * dot(along_y.xyz, along_y.xyz);
      if (length_sq > 1e-12f * scale_sq) {
        n *= rsqrt(length_sq);
        if (dot(n, centre.xyz) > 0.0f) n = -n;
        normal = (float4)(n, 0.0f);
      }
    }
  }
  normals[index] = normal;
}
