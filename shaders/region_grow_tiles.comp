#version 450
// Tiled Lab region growing, pass 1 of 3: one invocation grows every segment of one tile with the
// paper's stack (8-neighbours, running mean kept as exact integer sums), numbering them from 0 in
// the scan order of their seeds. The rules are those of grow_tile in
// src/segmentation/region_growing.cpp, in the same integer and double arithmetic.
#extension GL_GOOGLE_include_directive : require
#include "region_grow.glsl"

layout(local_size_x = 64) in;

// LabCode: four int16 (L, a, b, valid) packed in two uints, little-endian.
layout(std430, binding = 0) readonly buffer Lab { uvec2 lab[]; };
layout(std430, binding = 1) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 2) buffer Labels { uint labels[]; };
layout(std430, binding = 3) writeonly buffer TileCounts { uint tile_counts[]; };
layout(std430, binding = 4) buffer Stacks { uint stacks[]; };
layout(std430, binding = 5) buffer Status { uint status[]; };  // [1]: stack overflows

const int kDx[8] = int[8](-1, 0, 1, -1, 1, -1, 0, 1);
const int kDy[8] = int[8](-1, -1, -1, 0, 0, 1, 1, 1);

ivec4 lab_code(uint i) {
  const ivec2 v = ivec2(lab[i]);
  return ivec4(bitfieldExtract(v.x, 0, 16), bitfieldExtract(v.x, 16, 16),
               bitfieldExtract(v.y, 0, 16), bitfieldExtract(v.y, 16, 16));
}

bool is_valid_pixel(uint i) { return lab_code(i).w != 0 && is_valid_point(points[i]); }

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
  const double depth_ratio = double(params.depth_ratio);
  uint next = 0u;
  for (uint seed_y = y0; seed_y < y1; ++seed_y) {
    for (uint seed_x = x0; seed_x < x1; ++seed_x) {
      const uint seed = seed_y * params.width + seed_x;
      if (labels[seed] != KG_NO_LABEL || !is_valid_pixel(seed)) continue;
      const uint id = next++;
      i64vec3 sum = i64vec3(0);
      int64_t count = 0;
      uint top = 0u;
      stacks[base + top++] = seed;
      while (top > 0u) {
        const uint pixel = stacks[base + --top];
        if (labels[pixel] != KG_NO_LABEL) continue;
        const i64vec3 c = i64vec3(lab_code(pixel).xyz);
        if (count > 0) {
          const i64vec3 d = count * c - sum;
          if (d.x * d.x + d.y * d.y + d.z * d.z >= threshold_sq * count * count) continue;
        }
        labels[pixel] = id;
        ++count;
        sum += c;
        const int x = int(pixel % params.width), y = int(pixel / params.width);
        const double depth = double(points[pixel].z);
        for (int k = 0; k < 8; ++k) {
          const int nx = x + kDx[k], ny = y + kDy[k];
          if (nx < int(x0) || ny < int(y0) || nx >= int(x1) || ny >= int(y1)) continue;
          const uint neighbour = uint(ny) * params.width + uint(nx);
          if (labels[neighbour] != KG_NO_LABEL || !is_valid_pixel(neighbour)) continue;
          if (depth_ratio > 0.0 &&
              abs(double(points[neighbour].z) - depth) > depth_ratio * depth) {
            continue;
          }
          if (top >= params.stack_stride) {
            atomicAdd(status[1], 1u);
            continue;
          }
          stacks[base + top++] = neighbour;
        }
      }
    }
  }
  tile_counts[t] = next;
}
