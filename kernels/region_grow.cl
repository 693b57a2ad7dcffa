// Tiled Lab region growing in 3 passes (grow each tile, scan the tile counts, add the offsets);
// see shaders/region_grow*.{glsl,comp} (the same rules, kernel names, buffers and parameter
// layout) and include/kartograf/segmentation/region_growing.hpp for the contract.
typedef struct {
  uint width;
  uint height;
  uint tile_size;
  uint tiles_x;
  uint tile_count;
  uint padded_tile_count;  // a multiple of 64 (the scan's lanes)
  uint stack_stride;       // stack entries per tile: 8 tile_size^2 + 1
  uint threshold_code;     // the threshold in 1/64 Lab units
  float depth_ratio;       // 0: no depth test
} RegionGrowParams;

#define KG_NO_LABEL 0xffffffffu

__constant int kg_dx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
__constant int kg_dy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};

inline bool kg_is_valid_pixel(__global const short4* lab, __global const float4* points, uint i) {
  return lab[i].w != 0 && kg_is_valid_point(points[i]);
}

// One work-item grows every segment of one tile (see region_grow_tiles.comp).
__kernel void region_grow_tiles(__global const short4* lab, __global const float4* points,
                                __global uint* labels, __global uint* tile_counts,
                                __global uint* stacks, __global uint* status,
                                const RegionGrowParams params) {
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
  const double depth_ratio = (double)params.depth_ratio;
  uint next = 0;
  for (uint seed_y = y0; seed_y < y1; ++seed_y) {
    for (uint seed_x = x0; seed_x < x1; ++seed_x) {
      const uint seed = seed_y * params.width + seed_x;
      if (labels[seed] != KG_NO_LABEL || !kg_is_valid_pixel(lab, points, seed)) continue;
      const uint id = next++;
      long sum_l = 0, sum_a = 0, sum_b = 0, count = 0;
      uint top = 0;
      stacks[base + top++] = seed;
      while (top > 0) {
        const uint pixel = stacks[base + --top];
        if (labels[pixel] != KG_NO_LABEL) continue;
        const short4 c = lab[pixel];
        if (count > 0) {
          const long dl = count * c.x - sum_l, da = count * c.y - sum_a, db = count * c.z - sum_b;
          if (dl * dl + da * da + db * db >= threshold_sq * count * count) continue;
        }
        labels[pixel] = id;
        ++count;
        sum_l += c.x;
        sum_a += c.y;
        sum_b += c.z;
        const int x = (int)(pixel % params.width), y = (int)(pixel / params.width);
        const double depth = (double)points[pixel].z;
        for (int k = 0; k < 8; ++k) {
          const int nx = x + kg_dx[k], ny = y + kg_dy[k];
          if (nx < (int)x0 || ny < (int)y0 || nx >= (int)x1 || ny >= (int)y1) continue;
          const uint neighbour = (uint)ny * params.width + (uint)nx;
          if (labels[neighbour] != KG_NO_LABEL || !kg_is_valid_pixel(lab, points, neighbour)) {
            continue;
          }
          if (depth_ratio > 0.0 &&
              fabs((double)points[neighbour].z - depth) > depth_ratio * depth) {
            continue;
          }
          if (top >= params.stack_stride) {
            atomic_inc(&status[1]);
            continue;
          }
          stacks[base + top++] = neighbour;
        }
      }
    }
  }
  tile_counts[t] = next;
}

// One work-group of 64: exclusive prefix sums of the tile counts, the total to status[0] (see
// region_grow_scan.comp).
__kernel void region_grow_scan(__global uint* tile_counts, __global uint* status,
                               const RegionGrowParams params) {
  __local uint part_offsets[64];
  const uint lane = get_local_id(0);
  const uint part = params.padded_tile_count / 64u;
  const uint base = lane * part;
  uint sum = 0;
  for (uint j = 0; j < part; ++j) sum += tile_counts[base + j];
  part_offsets[lane] = sum;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lane == 0) {
    uint running = 0;
    for (uint l = 0; l < 64u; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = running;
      running += value;
    }
    status[0] = running;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  uint offset = part_offsets[lane];
  for (uint j = 0; j < part; ++j) {
    const uint value = tile_counts[base + j];
    tile_counts[base + j] = offset;
    offset += value;
  }
}

// Tile-local segment numbers plus the tile's offset (see region_grow_offsets.comp).
__kernel void region_grow_offsets(__global uint* labels, __global const uint* tile_offsets,
                                  const RegionGrowParams params) {
  const uint i = get_global_id(0);
  if (i >= params.width * params.height || labels[i] == KG_NO_LABEL) return;
  const uint x = i % params.width, y = i / params.width;
  labels[i] += tile_offsets[(y / params.tile_size) * params.tiles_x + x / params.tile_size];
}
