// Shared by the region_grow_*.comp shaders: the tiled Lab region growing of
// include/kartograf/segmentation/region_growing.hpp. The push-constant block mirrors
// RegionGrowKernelParams in src/segmentation/region_growing.cpp and kernels/region_grow.cl.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

#define KG_NO_LABEL 0xffffffffu

layout(push_constant) uniform Params {
  uint width;
  uint height;
  uint tile_size;
  uint tiles_x;
  uint tile_count;
  uint padded_tile_count;  // a multiple of 64 (the scan's lanes)
  uint stack_stride;       // stack entries per tile: 8 tile_size^2 + 1
  uint threshold_code;     // the threshold in 1/64 Lab units
  float depth_ratio;       // 0: no depth test
} params;
