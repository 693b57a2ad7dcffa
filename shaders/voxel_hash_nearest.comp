#version 450
// Nearest-neighbour search in a voxel-hash grid of the target (27 cells around each moved source
// point); rules in include/kartograf/registration/kdtree_correspondences.hpp, grid layout in
// voxel_hash_correspondences.hpp. Writes the target index, -1 (no match) or -2 (not selected).
// Moved points and distances are `precise` (no contraction): the CPU's doubles, bit for bit.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "voxel_hash.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Source { vec4 source[]; };
layout(std430, binding = 1) readonly buffer SourceNormals { vec4 source_normals[]; };  // optional
layout(std430, binding = 2) readonly buffer TargetNormals { vec4 target_normals[]; };  // optional
layout(std430, binding = 3) readonly buffer CellKeys { uint64_t cell_keys[]; };        // per slot
layout(std430, binding = 4) readonly buffer CellRanges { uvec2 cell_ranges[]; };       // first, count
layout(std430, binding = 5) readonly buffer CellPoints { vec4 cell_points[]; };        // by cell
layout(std430, binding = 6) readonly buffer CellIndices { uint cell_indices[]; };
// R (row-major 3x3), t, cell inverse, max squared distance, min normal cosine.
layout(std430, binding = 7) readonly buffer Frame { double frame[]; };
layout(std430, binding = 8) writeonly buffer Correspondences { int correspondences[]; };

layout(push_constant) uniform Params {
  uint source_count;
  uint source_width;  // 0: unorganized source
  uint subsample;
  uint capacity_log2;
  uint use_normals;
} params;

// The distance, in cells, from a query at `fraction` of its cell to the neighbour at `offset`.
double gap(int offset, double fraction) {
  return offset == 0 ? 0.0 : offset < 0 ? fraction : 1.0 - fraction;
}

int nearest(uint i) {
  const uint row = params.source_width == 0u ? 0u : i / params.source_width;
  if ((i + row) % params.subsample != 0u) return -2;
  const vec4 p = source[i];
  if (!is_valid_point(p)) return -1;
  const dvec3 ps = dvec3(p.xyz);
  precise dvec3 moved =
      dvec3(frame[0] * ps.x + frame[1] * ps.y + frame[2] * ps.z + frame[9],
            frame[3] * ps.x + frame[4] * ps.y + frame[5] * ps.z + frame[10],
            frame[6] * ps.x + frame[7] * ps.y + frame[8] * ps.z + frame[11]);
  dvec3 rotated_normal = dvec3(0.0);
  if (params.use_normals != 0u) {
    const vec4 np = source_normals[i];
    if (!is_valid_point(np)) return -1;
    const dvec3 n = dvec3(np.xyz);
    precise dvec3 rotated = dvec3(frame[0] * n.x + frame[1] * n.y + frame[2] * n.z,
                                  frame[3] * n.x + frame[4] * n.y + frame[5] * n.z,
                                  frame[6] * n.x + frame[7] * n.y + frame[8] * n.z);
    rotated_normal = rotated;
  }
  const dvec3 scaled = moved * frame[12];
  const dvec3 base = floor(scaled);
  if (!all(lessThanEqual(abs(base), dvec3(KG_VOXEL_LIMIT + 1.0)))) return -1;  // NaN fails too
  const dvec3 fraction = scaled - base;
  const double cell_sq = 1.0 / (frame[12] * frame[12]);
  const uint mask = (1u << params.capacity_log2) - 1u;
  int best = -1;
  double best_distance_sq = frame[13];
  // The query's own cell first; a cell whose nearest face is farther than the best so far is
  // skipped (gaps shrunk by 1e-9 cells against rounding).
  const int order[3] = int[3](0, -1, 1);
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      for (int c = 0; c < 3; ++c) {
        const ivec3 offset = ivec3(order[c], order[b], order[a]);
        const dvec3 gaps = max(dvec3(gap(offset.x, fraction.x), gap(offset.y, fraction.y),
                                     gap(offset.z, fraction.z)) - 1e-9lf,
                               dvec3(0.0));
        if (dot(gaps, gaps) * cell_sq > best_distance_sq) continue;
        const dvec3 cell = base + dvec3(offset);
        if (any(lessThan(cell, dvec3(-KG_VOXEL_LIMIT))) ||
            any(greaterThanEqual(cell, dvec3(KG_VOXEL_LIMIT)))) {
          continue;
        }
        const uint64_t key = voxel_key(cell);
        uint slot = voxel_slot(key, params.capacity_log2);
        while (cell_keys[slot] != key && cell_keys[slot] != 0ul) slot = (slot + 1u) & mask;
        if (cell_keys[slot] == 0ul) continue;
        const uvec2 range = cell_ranges[slot];
        for (uint m = range.x; m < range.x + range.y; ++m) {
          const int j = int(cell_indices[m]);
          const dvec3 q = dvec3(cell_points[m].xyz);
          precise dvec3 d = moved - q;
          precise double distance_sq = d.x * d.x + d.y * d.y + d.z * d.z;
          if (!(distance_sq < best_distance_sq ||
                (distance_sq == best_distance_sq && (best < 0 || j < best)))) {
            continue;
          }
          if (params.use_normals != 0u) {
            const vec4 nq = target_normals[j];
            if (!is_valid_point(nq)) continue;
            precise double cosine = rotated_normal.x * double(nq.x) +
                                    rotated_normal.y * double(nq.y) +
                                    rotated_normal.z * double(nq.z);
            if (!(cosine >= frame[14])) continue;
          }
          best = j;
          best_distance_sq = distance_sq;
        }
      }
    }
  }
  return best;
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.source_count) return;
  correspondences[i] = nearest(i);
}
