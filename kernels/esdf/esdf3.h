// The 3-D ESDF of a TSDF (rules in include/kartograf/mapping/esdf_volume.hpp) on the device: a
// dense grid of cells, each cell_voxels^3 TSDF voxels (1, 2, 4 or 8 a side, so that cells nest in
// blocks), holding a mark (occupied or not) and a distance. An update
//   mark      every cell of the blocks the TSDF touched since the last update: occupied where one
//             of its voxels is surface (observed, weight >= min_weight, tsdf < near: within one
//             voxel in front of a surface or behind it), else not; cells of other blocks keep their
//             marks;
//   seed      every cell of a box around those blocks: squared distance 0 where occupied, else
//   none; envelope  (kernels/esdf/esdf.h) along x, then y, then z over the box: exact squared
//   distances
//             to the box's occupied cells;
//   write     every cell of the inner box (the box less max_distance on each side, or the grid's
//             edge): resolution x sqrt(squared distance), at most max_distance.
// A cell's distance, capped at max_distance, depends only on the marks within max_distance of it,
// so the inner box holds every cell a changed mark can move, and the box every mark those cells
// depend on: the update gives what the whole grid's transform would.
#ifndef KARTOGRAF_KERNELS_ESDF3_H
#define KARTOGRAF_KERNELS_ESDF3_H
#include "kernels/esdf/esdf.h"
#include "kernels/tsdf/tsdf.h"
#include "kernels/tsdf/tsdf_voxel.h"

#define KG_ESDF3_OCCUPIED 1u

KG_RULES_BEGIN

KG_PARAMS_BEGIN(Esdf3Params)
KG_PARAM(uint, count)        // mark: blocks x cells per block; seed: box cells; write: inner cells
KG_PARAM(uint, cell_voxels)  // voxels per cell side: 1, 2, 4 or 8
KG_PARAM(float, near)        // voxel_size / truncation: one voxel in tsdf units
KG_PARAM(float, min_weight)
KG_PARAM(int, first_x)  // the grid's first cell, in cells from the world's origin
KG_PARAM(int, first_y)
KG_PARAM(int, first_z)
KG_PARAM(uint, dims_x)  // the grid's cells per axis
KG_PARAM(uint, dims_y)
KG_PARAM(uint, dims_z)
KG_PARAM(uint, box_x)  // seed: the box's first cell in the grid; write: the inner box's
KG_PARAM(uint, box_y)
KG_PARAM(uint, box_z)
KG_PARAM(uint, box_dims_x)  // the box's cells per axis (write: the inner box's)
KG_PARAM(uint, box_dims_y)
KG_PARAM(uint, box_dims_z)
KG_PARAM(uint, outer_x)  // write: the (outer) box's first cell and cells per axis
KG_PARAM(uint, outer_y)
KG_PARAM(uint, outer_z)
KG_PARAM(uint, outer_dims_x)
KG_PARAM(uint, outer_dims_y)
KG_PARAM(float, resolution)  // metres per cell
KG_PARAM(float, max_distance)
KG_PARAMS_END(Esdf3Params)

// The grid index of cell i of a box (x fastest), the box's first cell at (bx, by, bz).
KG_INLINE uint esdf3_box_cell(uint i, uint bx, uint by, uint bz, uint dims_x, uint dims_y,
                              Esdf3Params p) {
  const uint x = bx + i % dims_x;
  const uint y = by + (i / dims_x) % dims_y;
  const uint z = bz + i / (dims_x * dims_y);
  return (z * p.dims_y + y) * p.dims_x + x;
}

// ---- mark: the grid index of cell `cell` of a block (x fastest, (8 / cell_voxels)^3 cells),
// or -1 where it lies outside the grid.
KG_INLINE int esdf3_mark_cell(uint64_t key, uint cell, Esdf3Params p) {
  const uint side = KG_UINT(KG_TSDF_BLOCK_SIDE) / p.cell_voxels;
  const int x = tsdf_key_axis(key, 0u) * KG_INT(side) + KG_INT(cell % side) - p.first_x;
  const int y = tsdf_key_axis(key, 21u) * KG_INT(side) + KG_INT((cell / side) % side) - p.first_y;
  const int z = tsdf_key_axis(key, 42u) * KG_INT(side) + KG_INT(cell / (side * side)) - p.first_z;
  if (x < 0 || y < 0 || z < 0 || x >= KG_INT(p.dims_x) || y >= KG_INT(p.dims_y) ||
      z >= KG_INT(p.dims_z))
    return -1;
  return (z * KG_INT(p.dims_y) + y) * KG_INT(p.dims_x) + x;
}

// The slot in its block of voxel k (x fastest) of the block's cell `cell`.
KG_INLINE uint esdf3_cell_voxel(uint cell, uint k, Esdf3Params p) {
  const uint side = KG_UINT(KG_TSDF_BLOCK_SIDE) / p.cell_voxels;
  const uint s = p.cell_voxels;
  const uint x = (cell % side) * s + k % s;
  const uint y = ((cell / side) % side) * s + (k / s) % s;
  const uint z = (cell / (side * side)) * s + k / (s * s);
  return (z * 8u + y) * 8u + x;
}

KG_INLINE bool esdf3_is_surface(TsdfVoxel v, Esdf3Params p) {
  return v.weight >= p.min_weight && v.tsdf < p.near;
}

// The mark of cell `cell` of the block at pool index `block`. The shader declares `voxels`.
#if !defined(VULKAN) || defined(KG_ESDF3_MARK_PASS)
KG_INLINE uint esdf3_cell_mark(KG_BUFFER_PARAM(const TsdfVoxel, voxels) uint block, uint cell,
                               Esdf3Params p) {
  const uint n = p.cell_voxels * p.cell_voxels * p.cell_voxels;
  for (uint k = 0u; k < n; ++k) {
    const TsdfVoxel v = voxels[block * KG_TSDF_BLOCK_VOXELS + esdf3_cell_voxel(cell, k, p)];
    if (esdf3_is_surface(v, p)) return KG_ESDF3_OCCUPIED;
  }
  return 0u;
}
#endif

// ---- seed: one cell's squared distance before the line passes.
KG_INLINE int64_t esdf3_seed_value(uint mark) {
  return mark == KG_ESDF3_OCCUPIED ? KG_INT64(0) : KG_ESDF_NONE;
}

// ---- write: cell i of the inner box: its index in the (outer) box's line buffers.
KG_INLINE uint esdf3_outer_index(uint i, Esdf3Params p) {
  const uint x = p.box_x + i % p.box_dims_x - p.outer_x;
  const uint y = p.box_y + (i / p.box_dims_x) % p.box_dims_y - p.outer_y;
  const uint z = p.box_z + i / (p.box_dims_x * p.box_dims_y) - p.outer_z;
  return (z * p.outer_dims_y + y) * p.outer_dims_x + x;
}

KG_INLINE float esdf3_distance(int64_t squared, Esdf3Params p) {
  if (squared < KG_INT64(0)) return p.max_distance;
  return min(p.max_distance, p.resolution * sqrt(KG_FLOAT(squared)));
}

KG_RULES_END

#endif
