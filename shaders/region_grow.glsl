// Shared by the region_grow_*.comp shaders (parallel Lab region growing; contract in
// include/kartograf/segmentation/parallel_region_growing.hpp). The push-constant block mirrors
// RegionGrowKernelParams in src/segmentation/parallel_region_growing.cpp and kernels/region_grow.cl.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

#define KG_NO_LABEL 0xffffffffu
#define KG_PIXELS_PER_BLOCK 256u

layout(push_constant) uniform Params {
  uint width;
  uint height;
  uint pixel_count;
  uint block_count;  // padded to a multiple of 64
  uint limit;        // connect when the quantised squared Lab distance < limit
  float depth_ratio;  // 0: no depth test
} params;

// Lab clamped to +-255 in 1/64 units, rounded half to even: exact integers (|code| < 2^14), so
// squared distances (< 3 * 2^30) are exact in 32 bits everywhere.
ivec3 quantised_lab(vec4 lab) {
  return ivec3(roundEven(clamp(lab.xyz, vec3(-255.0), vec3(255.0)) * 64.0));
}

bool is_valid_pixel(vec4 lab, vec4 point) {
  return is_valid_point(point) && !any(isnan(lab.xyz)) && !any(isinf(lab.xyz));
}

// The edge test of two valid pixels: exact integer Lab distance, exact double depth comparison.
bool connected(vec4 lab_a, vec4 point_a, vec4 lab_b, vec4 point_b) {
  const ivec3 d = quantised_lab(lab_a) - quantised_lab(lab_b);
  const uint distance_sq = uint(d.x * d.x) + uint(d.y * d.y) + uint(d.z * d.z);
  if (distance_sq >= params.limit) return false;
  if (params.depth_ratio == 0.0) return true;
  const double za = double(point_a.z), zb = double(point_b.z);
  return abs(za - zb) <= double(params.depth_ratio) * min(za, zb);
}
