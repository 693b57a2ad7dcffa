// Simulated laser scans by integer sphere tracing (rules in include/kartograf/rooms/
// laser_features.hpp; the operation in rooms/laser_scan_device.hpp). A beam walks from its cell's
// centre along its direction [1/65536 cells per step] through the padded grid of skips (how many
// steps are surely free from each cell; 0 at obstacles and at the border ring), and stops at a 0 or
// after max_steps. No floating point: every backend, and the CPU LaserScanner, agree bit for bit.
#ifndef KARTOGRAF_KERNELS_LASER_SCAN_H
#define KARTOGRAF_KERNELS_LASER_SCAN_H
#include "shaders/prelude.h"

#define KG_LASER_SCAN_LOCAL_X 64

KG_RULES_BEGIN

// The work is one item per (cell, run of beams_per_item beams).
KG_PARAMS_BEGIN(LaserScanParams)
KG_PARAM(uint, item_count)      // cell count * items_per_cell
KG_PARAM(uint, items_per_cell)  // ceil(beams / beams_per_item)
KG_PARAM(uint, beams)
KG_PARAM(uint, beams_per_item)
KG_PARAM(int, map_width)
KG_PARAM(int, map_height)
KG_PARAM(int, max_steps)
KG_PARAMS_END(LaserScanParams)

// The centre of map cell `index` (column or row) in the padded grid, in 1/65536 cells.
KG_INLINE int laser_cell_origin(int index) {
  return (index + 1) * 65536 + 32768;
}

// The step count of the beam with direction (dx, dy) from (x0, y0) in `skips` (row stride
// `stride`), at most max_steps. Samples stay inside the padded grid (its border ring stops every
// beam), so positions are >= 0 and below 2^31: the shift is a floor and nothing overflows.
KG_INLINE int laser_trace_beam(KG_BUFFER_PARAM(const int, skips) int stride, int x0, int y0, int dx,
                               int dy, int max_steps) {
  int step = 0;
  while (step < max_steps) {
    const int x = (x0 + step * dx) >> 16;
    const int y = (y0 + step * dy) >> 16;
    const int skip = skips[y * stride + x];
    if (skip == 0) break;
    step += skip;
  }
  return min(step, max_steps);
}

// Work item `item`: steps[cell * beams + k] for its cell's run of beams k. A cell outside the map
// (the host rejects those) gives zeros.
KG_INLINE void laser_scan_item(KG_BUFFER_PARAM(const int, skips)
                                   KG_BUFFER_PARAM(const int2, directions)
                                       KG_BUFFER_PARAM(const int2, cells)
                                           KG_BUFFER_PARAM(int, steps) uint item,
                               LaserScanParams p) {
  const uint cell = item / p.items_per_cell;
  const uint first_beam = (item % p.items_per_cell) * p.beams_per_item;
  const uint end_beam = min(first_beam + p.beams_per_item, p.beams);
  const int2 c = cells[cell];
  const bool inside = c.x >= 0 && c.y >= 0 && c.x < p.map_width && c.y < p.map_height;
  const int x0 = laser_cell_origin(c.x);
  const int y0 = laser_cell_origin(c.y);
  for (uint k = first_beam; k < end_beam; ++k) {
    const int2 direction = directions[k];
    steps[cell * p.beams + k] = inside ? laser_trace_beam(KG_BUFFER_ARG(skips) p.map_width + 2, x0,
                                                          y0, direction.x, direction.y, p.max_steps)
                                       : 0;
  }
}

KG_RULES_END

#endif
