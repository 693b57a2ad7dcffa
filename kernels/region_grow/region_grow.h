// Tiled Lab region growing (contract in include/kartograf/segmentation/region_growing.hpp): each
// tile is grown on its own with the paper's stack over 8-neighbours, numbering its segments from 0
// in the scan order of their seeds; then the tile counts are scanned and every label gets its
// tile's offset. A pixel joins a segment of n pixels with Lab code sum S when |n c - S|^2 <
// (T n)^2 (exact integers), and is reached only across a continuous depth. Measuring, each segment
// also sums its codes and its points' moments about an origin (double, in the order it grew) into
// the slot (tile, segment) of a statistics buffer, gathered in label order by the last pass.
#ifndef KARTOGRAF_KERNELS_REGION_GROW_H
#define KARTOGRAF_KERNELS_REGION_GROW_H
#include "shaders/prelude.h"

#define KG_REGION_GROW_TILES_LOCAL_X 64  // one tile per work-item
#define KG_REGION_GROW_SCAN_LOCAL_X 64   // one work-group; a lane per 1/64 of the tiles
#define KG_REGION_GROW_OFFSETS_LOCAL_X 256
#define KG_REGION_GROW_STATISTICS_LOCAL_X 256

#define KG_NO_LABEL 0xffffffffu
// The status words: [0] the segment count (written by the scan), [1] stack overflows (a bug).
#define KG_REGION_GROW_SEGMENT_COUNT 0u
#define KG_REGION_GROW_OVERFLOWS 1u
// Doubles per segment: count, Lab code sums (3), then sum d (3) and sum d d^T (xx xy xz yy yz zz)
// with d = p - origin.
#define KG_REGION_GROW_STATISTICS 13u

KG_RULES_BEGIN

KG_PARAMS_BEGIN(RegionGrowParams)
KG_PARAM(uint, width)
KG_PARAM(uint, height)
KG_PARAM(uint, tile_size)
KG_PARAM(uint, tiles_x)
KG_PARAM(uint, tile_count)
KG_PARAM(uint, padded_tile_count)  // a multiple of 64 (the scan's lanes)
KG_PARAM(uint, stack_stride)       // device stack entries per tile: 8 tile_size^2 + 1
KG_PARAM(uint, threshold_code)     // the threshold in 1/64 Lab units
KG_PARAM(float, depth_ratio)       // 0: no depth test
KG_PARAM(uint, measure)            // 1: per-segment statistics
KG_PARAM(uint, slots_per_tile)     // statistics slots per tile: its largest pixel count
KG_PARAM(float, origin_x)          // the moments' origin
KG_PARAM(float, origin_y)
KG_PARAM(float, origin_z)
KG_PARAMS_END(RegionGrowParams)

// A pixel takes part when it has a colour and a point.
KG_INLINE bool region_grow_valid(int lab_valid, float4 point) {
  return lab_valid != 0 && !kg_isnan(point.x);
}

// Whether the pixel with Lab codes (l, a, b) joins the segment of `count` pixels with code sums
// (sum_l, sum_a, sum_b): the seed always does (distance 0 to its own colour). kg_wide_int holds
// threshold_sq count^2 (int64 up to 4096 pixels, the largest device tile).
KG_WIDE_INT_TEMPLATE
KG_INLINE bool region_grow_joins(int64_t count, int64_t sum_l, int64_t sum_a, int64_t sum_b, int l,
                                 int a, int b, kg_wide_int threshold_sq) {
  if (count == KG_INT64(0)) return true;
  const kg_wide_int dl = count * KG_INT64(l) - sum_l;
  const kg_wide_int da = count * KG_INT64(a) - sum_a;
  const kg_wide_int db = count * KG_INT64(b) - sum_b;
  return dl * dl + da * da + db * db < threshold_sq * count * count;
}

// Whether growing from a pixel at `depth` to a neighbour at neighbour_depth crosses a depth jump
// (exact double values of the float depths).
KG_INLINE bool region_grow_depth_breaks(double depth, float neighbour_depth, float depth_ratio) {
  const double ratio = KG_DOUBLE(depth_ratio);
  return ratio > 0.0 && kg_fabs(KG_DOUBLE(neighbour_depth) - depth) > ratio * depth;
}

// The 8 neighbours in scan order (the order they are pushed): k = 0..7 skips the centre.
KG_INLINE int region_grow_neighbour_dx(int k) {
  return (k < 4 ? k : k + 1) % 3 - 1;
}
KG_INLINE int region_grow_neighbour_dy(int k) {
  return (k < 4 ? k : k + 1) / 3 - 1;
}

// A segment's moments about the origin, summed in the order it grows.
KG_STRUCT_BEGIN(RegionMoments)
double x;
double y;
double z;
double xx;
double xy;
double xz;
double yy;
double yz;
double zz;
KG_STRUCT_END(RegionMoments)

KG_INLINE RegionMoments region_moments_zero() {
  RegionMoments m;
  m.x = 0.0, m.y = 0.0, m.z = 0.0;
  m.xx = 0.0, m.xy = 0.0, m.xz = 0.0, m.yy = 0.0, m.yz = 0.0, m.zz = 0.0;
  return m;
}

KG_INLINE RegionMoments region_moments_add(RegionMoments m, float4 p, RegionGrowParams params) {
  const double dx = KG_DOUBLE(p.x) - KG_DOUBLE(params.origin_x);
  const double dy = KG_DOUBLE(p.y) - KG_DOUBLE(params.origin_y);
  const double dz = KG_DOUBLE(p.z) - KG_DOUBLE(params.origin_z);
  m.x += dx, m.y += dy, m.z += dz;
  m.xx += dx * dx, m.xy += dx * dy, m.xz += dx * dz;
  m.yy += dy * dy, m.yz += dy * dz, m.zz += dz * dz;
  return m;
}

// Statistic `value` (0..KG_REGION_GROW_STATISTICS-1) of a segment.
KG_INLINE double region_statistic(uint value, int64_t count, int64_t sum_l, int64_t sum_a,
                                  int64_t sum_b, RegionMoments m) {
  switch (value) {
    case 0u:
      return KG_DOUBLE(count);
    case 1u:
      return KG_DOUBLE(sum_l);
    case 2u:
      return KG_DOUBLE(sum_a);
    case 3u:
      return KG_DOUBLE(sum_b);
    case 4u:
      return m.x;
    case 5u:
      return m.y;
    case 6u:
      return m.z;
    case 7u:
      return m.xx;
    case 8u:
      return m.xy;
    case 9u:
      return m.xz;
    case 10u:
      return m.yy;
    case 11u:
      return m.yz;
    default:
      return m.zz;
  }
}

// Where the statistics of segment `segment` (numbered within tile t) are kept until the last pass.
KG_INLINE uint region_statistics_slot(uint t, uint segment, RegionGrowParams params) {
  return (t * params.slots_per_tile + segment) * KG_REGION_GROW_STATISTICS;
}

KG_RULES_END

#endif
