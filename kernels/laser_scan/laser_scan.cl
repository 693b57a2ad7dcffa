// OpenCL wrapper of kernels/laser_scan/laser_scan.h.
#include "kernels/laser_scan/laser_scan.h"

__kernel void laser_scan(__global const int* skips, __global const int2* directions,
                         __global const int2* cells, __global int* steps,
                         const LaserScanParams params) {
  // A 1-D grid of items folded into x and y, as the Vulkan dispatch needs.
  const uint item = (uint)get_global_id(1) * (uint)get_global_size(0) + (uint)get_global_id(0);
  if (item >= params.item_count) return;
  laser_scan_item(skips, directions, cells, steps, item, params);
}
