#version 450
// Vulkan wrapper of kernels/region_grow/region_grow.h, pass 1 of 4: one invocation grows every
// segment of one tile with its own stack, numbering them from 0, and (measuring) keeps each
// segment's statistics in its slot.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "kernels/region_grow/region_grow.h"

layout(local_size_x = KG_REGION_GROW_TILES_LOCAL_X) in;

// LabCode: four int16 (L, a, b, valid) packed in two uints, little-endian.
layout(std430, binding = 0) readonly buffer Lab { uvec2 lab[]; };
layout(std430, binding = 1) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 2) buffer Labels { uint labels[]; };
layout(std430, binding = 3) writeonly buffer TileCounts { uint tile_counts[]; };
layout(std430, binding = 4) buffer Stacks { uint stacks[]; };
layout(std430, binding = 5) buffer Status { uint status[]; };
layout(std430, binding = 6) writeonly buffer Slots { double slots[]; };
KG_PUSH_PARAMS(RegionGrowParams);

ivec4 lab_code(uint i) {
  const ivec2 v = ivec2(lab[i]);
  return ivec4(bitfieldExtract(v.x, 0, 16), bitfieldExtract(v.x, 16, 16),
               bitfieldExtract(v.y, 0, 16), bitfieldExtract(v.y, 16, 16));
}

bool is_valid_pixel(uint i) { return region_grow_valid(lab_code(i).w, points[i]); }

void main() {
  const uint t = gl_GlobalInvocationID.x;
  if (t >= params.tile_count) return;
  const uint x0 = (t % params.tiles_x) * params.tile_size;
  const uint y0 = (t / params.tiles_x) * params.tile_size;
  const uint x1 = min(params.width, x0 + params.tile_size);
  const uint y1 = min(params.height, y0 + params.tile_size);
  for (uint y = y0; y < y1; ++y) {
    for (uint x = x0; x < x1; ++x) labels[y * params.width + x] = KG_NO_LABEL;
  }
  const uint base = t * params.stack_stride;
  const int64_t threshold = int64_t(params.threshold_code);
  const int64_t threshold_sq = threshold * threshold;
  uint next = 0u;
  for (uint seed_y = y0; seed_y < y1; ++seed_y) {
    for (uint seed_x = x0; seed_x < x1; ++seed_x) {
      const uint seed = seed_y * params.width + seed_x;
      if (labels[seed] != KG_NO_LABEL || !is_valid_pixel(seed)) continue;
      const uint id = next++;
      int64_t sum_l = 0, sum_a = 0, sum_b = 0, count = 0;
      RegionMoments moments = region_moments_zero();
      uint top = 0u;
      stacks[base + top++] = seed;
      while (top > 0u) {
        const uint pixel = stacks[base + --top];
        if (labels[pixel] != KG_NO_LABEL) continue;
        const ivec4 c = lab_code(pixel);
        if (!region_grow_joins(count, sum_l, sum_a, sum_b, c.x, c.y, c.z, threshold_sq)) continue;
        labels[pixel] = id;
        ++count;
        sum_l += c.x, sum_a += c.y, sum_b += c.z;
        if (params.measure != 0u) moments = region_moments_add(moments, points[pixel], params);
        const int x = int(pixel % params.width), y = int(pixel / params.width);
        const double depth = double(points[pixel].z);
        for (int k = 0; k < 8; ++k) {
          const int nx = x + region_grow_neighbour_dx(k), ny = y + region_grow_neighbour_dy(k);
          if (nx < int(x0) || ny < int(y0) || nx >= int(x1) || ny >= int(y1)) continue;
          const uint neighbour = uint(ny) * params.width + uint(nx);
          if (labels[neighbour] != KG_NO_LABEL || !is_valid_pixel(neighbour)) continue;
          if (region_grow_depth_breaks(depth, points[neighbour].z, params.depth_ratio)) continue;
          if (top >= params.stack_stride) {
            atomicAdd(status[KG_REGION_GROW_OVERFLOWS], 1u);
            continue;
          }
          stacks[base + top++] = neighbour;
        }
      }
      if (params.measure == 0u) continue;
      const uint slot = region_statistics_slot(t, id, params);
      for (uint v = 0u; v < KG_REGION_GROW_STATISTICS; ++v) {
        slots[slot + v] = region_statistic(v, count, sum_l, sum_a, sum_b, moments);
      }
    }
  }
  tile_counts[t] = next;
}
