// OpenCL wrapper of kernels/region_grow/region_grow.h: the four passes, with the names, buffers
// and parameters of the region_grow_*.comp shaders.
#include "kernels/region_grow/region_grow.h"
#include "kernels/work_group/group_scan.h"

inline bool region_grow_valid_pixel(__global const short4* lab, __global const float4* points,
                                    uint i) {
  return region_grow_valid(lab[i].w, points[i]);
}

// Pass 1: one work-item grows every segment of one tile (see region_grow_tiles.comp).
__kernel void region_grow_tiles(__global const short4* lab, __global const float4* points,
                                __global uint* labels, __global uint* tile_counts,
                                __global uint* stacks, __global uint* status,
                                __global double* slots, const RegionGrowParams params) {
  const uint t = get_global_id(0);
  if (t >= params.tile_count) return;
  const uint x0 = (t % params.tiles_x) * params.tile_size;
  const uint y0 = (t / params.tiles_x) * params.tile_size;
  const uint x1 = min(params.width, x0 + params.tile_size);
  const uint y1 = min(params.height, y0 + params.tile_size);
  for (uint y = y0; y < y1; ++y) {
    for (uint x = x0; x < x1; ++x) labels[y * params.width + x] = KG_NO_LABEL;
  }
  const uint base = t * params.stack_stride;
  const long threshold = (long)params.threshold_code;
  const long threshold_sq = threshold * threshold;
  uint next = 0;
  for (uint seed_y = y0; seed_y < y1; ++seed_y) {
    for (uint seed_x = x0; seed_x < x1; ++seed_x) {
      const uint seed = seed_y * params.width + seed_x;
      if (labels[seed] != KG_NO_LABEL || !region_grow_valid_pixel(lab, points, seed)) continue;
      const uint id = next++;
      long sum_l = 0, sum_a = 0, sum_b = 0, count = 0;
      RegionMoments moments = region_moments_zero();
      uint top = 0;
      stacks[base + top++] = seed;
      while (top > 0) {
        const uint pixel = stacks[base + --top];
        if (labels[pixel] != KG_NO_LABEL) continue;
        const short4 c = lab[pixel];
        if (!region_grow_joins(count, sum_l, sum_a, sum_b, c.x, c.y, c.z, threshold_sq)) continue;
        labels[pixel] = id;
        ++count;
        sum_l += c.x, sum_a += c.y, sum_b += c.z;
        if (params.measure != 0) moments = region_moments_add(moments, points[pixel], params);
        const int x = (int)(pixel % params.width), y = (int)(pixel / params.width);
        const double depth = (double)points[pixel].z;
        for (int k = 0; k < 8; ++k) {
          const int nx = x + region_grow_neighbour_dx(k), ny = y + region_grow_neighbour_dy(k);
          if (nx < (int)x0 || ny < (int)y0 || nx >= (int)x1 || ny >= (int)y1) continue;
          const uint neighbour = (uint)ny * params.width + (uint)nx;
          if (labels[neighbour] != KG_NO_LABEL ||
              !region_grow_valid_pixel(lab, points, neighbour)) {
            continue;
          }
          if (region_grow_depth_breaks(depth, points[neighbour].z, params.depth_ratio)) continue;
          if (top >= params.stack_stride) {
            atomic_inc(&status[KG_REGION_GROW_OVERFLOWS]);
            continue;
          }
          stacks[base + top++] = neighbour;
        }
      }
      if (params.measure == 0) continue;
      const uint slot = region_statistics_slot(t, id, params);
      for (uint v = 0; v < KG_REGION_GROW_STATISTICS; ++v) {
        slots[slot + v] = region_statistic(v, count, sum_l, sum_a, sum_b, moments);
      }
    }
  }
  tile_counts[t] = next;
}

// Pass 2: one work-group, exclusive prefix sums of the tile counts, the total to the status
// (kernels/work_group/group_scan.h).
__kernel void region_grow_scan(__global uint* tile_counts, __global uint* status,
                               const RegionGrowParams params) {
  __local uint part_offsets[KG_GROUP_SCAN_LANES];
  const uint total = kg_group_exclusive_scan(tile_counts, part_offsets, params.padded_tile_count);
  if (get_local_id(0) == 0u) status[KG_REGION_GROW_SEGMENT_COUNT] = total;
}

// Pass 3: tile-local segment numbers plus the tile's offset (see region_grow_offsets.comp).
__kernel void region_grow_offsets(__global uint* labels, __global const uint* tile_offsets,
                                  const RegionGrowParams params) {
  const uint i = get_global_id(0);
  if (i >= params.width * params.height || labels[i] == KG_NO_LABEL) return;
  const uint x = i % params.width, y = i / params.width;
  labels[i] += tile_offsets[(y / params.tile_size) * params.tiles_x + x / params.tile_size];
}

// Pass 4: statistics from the slots to label order (see region_grow_statistics.comp).
__kernel void region_grow_statistics(__global const uint* tile_offsets,
                                     __global const uint* status, __global const double* slots,
                                     __global double* statistics, const RegionGrowParams params) {
  const uint i = get_global_id(0);
  if (i >= params.tile_count * params.slots_per_tile) return;
  const uint t = i / params.slots_per_tile, segment = i % params.slots_per_tile;
  const uint first = tile_offsets[t];
  const uint end =
      t + 1u < params.tile_count ? tile_offsets[t + 1u] : status[KG_REGION_GROW_SEGMENT_COUNT];
  if (first + segment >= end) return;
  const uint slot = region_statistics_slot(t, segment, params);
  const uint target = (first + segment) * KG_REGION_GROW_STATISTICS;
  for (uint v = 0; v < KG_REGION_GROW_STATISTICS; ++v) statistics[target + v] = slots[slot + v];
}
