// One pyramid step (rules in include/kartograf/registration/frame_pyramid.hpp): the 2x2 block of
// fine pixels (x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1) -> one coarse pixel. The
// block's members are the valid points within max_depth_jump * z_min of its nearest depth z_min;
// the coarse point is their mean, the coarse colour their per-channel mean (rounded half up).
#ifndef KARTOGRAF_KERNELS_PYRAMID_DOWNSAMPLE_H
#define KARTOGRAF_KERNELS_PYRAMID_DOWNSAMPLE_H
#include "shaders/prelude.h"

#define KG_PYRAMID_DOWNSAMPLE_LOCAL_X 16
#define KG_PYRAMID_DOWNSAMPLE_LOCAL_Y 16

KG_RULES_BEGIN

KG_PARAMS_BEGIN(PyramidDownsampleParams)
KG_PARAM(uint, fine_width)
KG_PARAM(uint, coarse_width)
KG_PARAM(uint, coarse_height)
KG_PARAM(uint, has_colors)  // 0: the colour buffers are absent
KG_PARAM(float, max_depth_jump)
KG_PARAMS_END(PyramidDownsampleParams)

// Bit k set when block point k (row-major) is a member, bit 4 when the block has a valid point
// (without one, 0). A block with a valid point has members unless z_min <= 0.
KG_INLINE uint pyramid_block_members(float4 p0, float4 p1, float4 p2, float4 p3,
                                     float max_depth_jump) {
  float z_min = 0.0f;
  bool any = false;
  if (!kg_isnan(p0.x) && (!any || p0.z < z_min)) {
    z_min = p0.z;
    any = true;
  }
  if (!kg_isnan(p1.x) && (!any || p1.z < z_min)) {
    z_min = p1.z;
    any = true;
  }
  if (!kg_isnan(p2.x) && (!any || p2.z < z_min)) {
    z_min = p2.z;
    any = true;
  }
  if (!kg_isnan(p3.x) && (!any || p3.z < z_min)) {
    z_min = p3.z;
    any = true;
  }
  if (!any) return 0u;
  const float limit = max_depth_jump * z_min;
  uint members = 16u;
  if (!kg_isnan(p0.x) && p0.z - z_min <= limit) members |= 1u;
  if (!kg_isnan(p1.x) && p1.z - z_min <= limit) members |= 2u;
  if (!kg_isnan(p2.x) && p2.z - z_min <= limit) members |= 4u;
  if (!kg_isnan(p3.x) && p3.z - z_min <= limit) members |= 8u;
  return members;
}

KG_INLINE uint pyramid_member_count(uint members) {
  return (members & 1u) + ((members >> 1) & 1u) + ((members >> 2) & 1u) + ((members >> 3) & 1u);
}

// The rounded reciprocal of 1..4 (0 for 0): multiplication rounds identically everywhere,
// division need not.
KG_INLINE float pyramid_inverse_count(uint count) {
  return count == 1u   ? 1.0f
         : count == 2u ? 0.5f
         : count == 3u ? 0.333333343267f
         : count == 4u ? 0.25f
                       : 0.0f;
}

// The mean of the members, summed in float in row-major order; all NaN without a valid point.
KG_INLINE float4 pyramid_block_point(float4 p0, float4 p1, float4 p2, float4 p3, uint members) {
  if (members == 0u) return KG_INVALID_POINT;
  float3 sum = KG_FLOAT3(0.0f, 0.0f, 0.0f);
  if ((members & 1u) != 0u) sum = sum + kg_xyz(p0);
  if ((members & 2u) != 0u) sum = sum + kg_xyz(p1);
  if ((members & 4u) != 0u) sum = sum + kg_xyz(p2);
  if ((members & 8u) != 0u) sum = sum + kg_xyz(p3);
  return KG_FLOAT4_XYZ_W(sum * pyramid_inverse_count(pyramid_member_count(members)), 1.0f);
}

// One channel (at bit `shift`) of the members' packed colours, rounded half up.
KG_INLINE uint pyramid_channel_mean(uint c0, uint c1, uint c2, uint c3, uint members, uint shift) {
  uint sum = 0u;
  if ((members & 1u) != 0u) sum += (c0 >> shift) & 0xffu;
  if ((members & 2u) != 0u) sum += (c1 >> shift) & 0xffu;
  if ((members & 4u) != 0u) sum += (c2 >> shift) & 0xffu;
  if ((members & 8u) != 0u) sum += (c3 >> shift) & 0xffu;
  const uint count = pyramid_member_count(members);
  return (sum + count / 2u) / count;
}

// The members' mean colour (packed r | g << 8 | b << 16); 0 without members.
KG_INLINE uint pyramid_block_color(uint c0, uint c1, uint c2, uint c3, uint members) {
  if (pyramid_member_count(members) == 0u) return 0u;
  return pyramid_channel_mean(c0, c1, c2, c3, members, 0u) |
         (pyramid_channel_mean(c0, c1, c2, c3, members, 8u) << 8) |
         (pyramid_channel_mean(c0, c1, c2, c3, members, 16u) << 16);
}

KG_RULES_END

#endif
