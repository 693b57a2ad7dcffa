// The robot's height band from the TSDF (rules in include/kartograf/mapping/tsdf_slice.hpp), one
// work item per voxel of the pool: an observed voxel (weight >= min_weight) within one voxel in
// front of a surface or behind it (tsdf < near) is surface; in a frame whose z points up
// (level = R world + t), a surface voxel between band_min and band_max above floor_z marks its
// grid cell occupied (2), one within floor_tolerance of floor_z marks it free (1). A cell keeps the
// largest mark (occupied over free over unknown, 0).
#ifndef KARTOGRAF_KERNELS_TSDF_BAND_H
#define KARTOGRAF_KERNELS_TSDF_BAND_H
#include "kernels/tsdf/tsdf.h"
#include "kernels/tsdf/tsdf_voxel.h"

#define KG_TSDF_BAND_FREE 1u
#define KG_TSDF_BAND_OCCUPIED 2u

KG_RULES_BEGIN

KG_PARAMS_BEGIN(TsdfBandParams)
KG_TSDF_RIGID_PARAMS  // world to level
KG_PARAM(float, voxel_size)
KG_PARAM(float, near)  // voxel_size / truncation: one voxel in tsdf units
KG_PARAM(float, min_weight)
KG_PARAM(float, floor_z)
KG_PARAM(float, floor_tolerance)
KG_PARAM(float, band_min)
KG_PARAM(float, band_max)
KG_PARAM(float, origin_x)  // the grid's lower-left corner in the level frame
KG_PARAM(float, origin_y)
KG_PARAM(float, inverse_resolution)
KG_PARAM(uint, cols)
KG_PARAM(uint, rows)
KG_PARAM(uint, count)  // voxels: blocks x 512
KG_PARAMS_END(TsdfBandParams)

KG_STRUCT_BEGIN(TsdfBandMark)
int cell;    // -1: the voxel marks no cell
uint state;  // KG_TSDF_BAND_FREE or KG_TSDF_BAND_OCCUPIED
KG_STRUCT_END(TsdfBandMark)

// The mark of voxel `slot` (x fastest) of the block with this key.
KG_INLINE TsdfBandMark tsdf_band_mark(TsdfVoxel v, uint64_t key, uint slot, TsdfBandParams p) {
  TsdfBandMark mark;
  mark.cell = -1;
  mark.state = 0u;
  if (v.weight < p.min_weight || v.tsdf >= p.near) return mark;
  const int vx = tsdf_key_axis(key, 0u) * KG_TSDF_BLOCK_SIDE + KG_INT(slot & 7u);
  const int vy = tsdf_key_axis(key, 21u) * KG_TSDF_BLOCK_SIDE + KG_INT((slot >> 3u) & 7u);
  const int vz = tsdf_key_axis(key, 42u) * KG_TSDF_BLOCK_SIDE + KG_INT(slot >> 6u);
  const float3 w =
      KG_FLOAT3(KG_FLOAT(vx) + 0.5f, KG_FLOAT(vy) + 0.5f, KG_FLOAT(vz) + 0.5f) * p.voxel_size;
  const float lx = p.r00 * w.x + p.r01 * w.y + p.r02 * w.z + p.tx;
  const float ly = p.r10 * w.x + p.r11 * w.y + p.r12 * w.z + p.ty;
  const float lz = p.r20 * w.x + p.r21 * w.y + p.r22 * w.z + p.tz;
  const float h = lz - p.floor_z;
  const bool in_band = h >= p.band_min && h <= p.band_max;
  const bool on_floor = kg_fabs(h) <= p.floor_tolerance;
  if (!in_band && !on_floor) return mark;
  const float cx = floor((lx - p.origin_x) * p.inverse_resolution);
  const float cy = floor((ly - p.origin_y) * p.inverse_resolution);
  if (!(cx >= 0.0f && cy >= 0.0f && cx < KG_FLOAT(p.cols) && cy < KG_FLOAT(p.rows))) return mark;
  // Row 0 is the top (largest y), as OccupancyGrid's images are.
  mark.cell = (KG_INT(p.rows) - 1 - KG_INT(cy)) * KG_INT(p.cols) + KG_INT(cx);
  mark.state = in_band ? KG_TSDF_BAND_OCCUPIED : KG_TSDF_BAND_FREE;
  return mark;
}

KG_RULES_END

#endif
