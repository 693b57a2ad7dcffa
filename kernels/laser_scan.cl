// Simulated laser scans by integer sphere tracing; see shaders/laser_scan.comp (same layout).
typedef struct {
  uint item_count;
  uint items_per_cell;
  uint beams;
  uint beams_per_item;
  int map_width;
  int map_height;
  int max_steps;
} LaserScanParams;

__kernel void laser_scan(__global const int* skips, __global const int2* directions,
                         __global const int2* cells, __global int* steps,
                         const LaserScanParams params) {
  // A 1-D grid of items folded into x and y, as the Vulkan dispatch needs.
  const uint item = (uint)get_global_id(1) * (uint)get_global_size(0) + (uint)get_global_id(0);
  if (item >= params.item_count) return;
  const uint cell = item / params.items_per_cell;
  const uint first_beam = (item % params.items_per_cell) * params.beams_per_item;
  const uint end_beam = min(first_beam + params.beams_per_item, params.beams);
  const int2 c = cells[cell];
  // Cells outside the map never reach here (the host checks); they would give zeros.
  const bool inside = c.x >= 0 && c.y >= 0 && c.x < params.map_width && c.y < params.map_height;
  const int stride = params.map_width + 2;
  const int x0 = (c.x + 1) * 65536 + 32768, y0 = (c.y + 1) * 65536 + 32768;
  for (uint k = first_beam; k < end_beam; ++k) {
    const int2 direction = directions[k];
    int step = 0;
    while (inside && step < params.max_steps) {
      const int x = (x0 + step * direction.x) >> 16, y = (y0 + step * direction.y) >> 16;
      const int skip = skips[y * stride + x];
      if (skip == 0) break;
      step += skip;
    }
    steps[cell * params.beams + k] = min(step, params.max_steps);
  }
}
