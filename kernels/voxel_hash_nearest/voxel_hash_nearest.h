// Nearest-neighbour search in a voxel-hash grid of the target (rules in
// include/kartograf/registration/kdtree_correspondences.hpp, grid layout in
// voxel_hash_correspondences.hpp): each selected source point, moved into the target's frame,
// searches the 27 cells around it for the nearest target point within max_distance (ties: the
// lowest index) that passes the normal gate. One entry per source point: the target index,
// KG_NEAREST_NO_MATCH or KG_NEAREST_NOT_SELECTED. Moved points, distances and cosines are spelled
// out in one order in double with no fused multiply-add, so every backend computes the same doubles
// (and the k-d tree finder, registration/nearest_neighbor.hpp, uses the same rules).
#ifndef KARTOGRAF_KERNELS_VOXEL_HASH_NEAREST_H
#define KARTOGRAF_KERNELS_VOXEL_HASH_NEAREST_H
#include "kernels/correspondence/selection.h"
#include "kernels/voxel_hash/voxel_hash.h"

#define KG_VOXEL_HASH_NEAREST_LOCAL_X 64
#define KG_NEAREST_NO_MATCH (-1)
#define KG_NEAREST_NOT_SELECTED (-2)

// The frame buffer's doubles: R (row-major 3x3), t, the grid's cell inverse, the two gates.
#define KG_NEAREST_FRAME_R 0
#define KG_NEAREST_FRAME_T 9
#define KG_NEAREST_FRAME_CELL_INVERSE 12
#define KG_NEAREST_FRAME_MAX_DISTANCE_SQ 13
#define KG_NEAREST_FRAME_MIN_COSINE 14
#define KG_NEAREST_FRAME_VALUES 15

// Cells whose nearest face is farther than the best candidate are skipped; their gaps are shrunk
// by 1e-9 cells, more than the rounding of p * s for |p * s| < 2^21, so none is lost. (Written as
// a quotient: an unsuffixed GLSL literal is a float.)
#define KG_NEAREST_GAP_MARGIN (KG_DOUBLE(1.0) / KG_DOUBLE(1000000000.0))

KG_RULES_BEGIN

KG_PARAMS_BEGIN(VoxelHashNearestParams)
KG_PARAM(uint, source_count)
KG_PARAM(uint, source_width)  // 0: unorganized source
KG_PARAM(uint, subsample)
KG_PARAM(uint, capacity_log2)
KG_PARAM(uint, use_normals)  // 0: the normal buffers are absent
KG_PARAMS_END(VoxelHashNearestParams)

KG_STRUCT_BEGIN(NearestCandidate)
int index;  // KG_NEAREST_NO_MATCH while there is none
double distance_sq;
KG_STRUCT_END(NearestCandidate)

// The frame's rotation times v, without fused multiply-adds.
KG_INLINE double3 nearest_rotate(KG_BUFFER_PARAM(const double, frame) double3 v) {
#if defined(__OPENCL_C_VERSION__)
#pragma OPENCL FP_CONTRACT OFF
#endif
  KG_PRECISE const double3 r = KG_DOUBLE3(frame[0] * v.x + frame[1] * v.y + frame[2] * v.z,
                                          frame[3] * v.x + frame[4] * v.y + frame[5] * v.z,
                                          frame[6] * v.x + frame[7] * v.y + frame[8] * v.z);
  return r;
}

// R p + t.
KG_INLINE double3 nearest_move(KG_BUFFER_PARAM(const double, frame) float4 p) {
  const double3 r = nearest_rotate(KG_BUFFER_ARG(frame)
                                       KG_DOUBLE3(KG_DOUBLE(p.x), KG_DOUBLE(p.y), KG_DOUBLE(p.z)));
  return KG_DOUBLE3(r.x + frame[KG_NEAREST_FRAME_T], r.y + frame[KG_NEAREST_FRAME_T + 1],
                    r.z + frame[KG_NEAREST_FRAME_T + 2]);
}

KG_INLINE double nearest_distance_sq(double3 moved, float4 q) {
#if defined(__OPENCL_C_VERSION__)
#pragma OPENCL FP_CONTRACT OFF
#endif
  const double dx = moved.x - KG_DOUBLE(q.x);
  const double dy = moved.y - KG_DOUBLE(q.y);
  const double dz = moved.z - KG_DOUBLE(q.z);
  KG_PRECISE const double distance_sq = dx * dx + dy * dy + dz * dz;
  return distance_sq;
}

// Whether target point j at distance_sq beats the best so far: nearer, or as near with a lower
// index. The best starts at max_distance^2 with no index, so a point exactly there counts.
KG_INLINE bool nearest_improves(double distance_sq, int j, NearestCandidate best) {
  return distance_sq < best.distance_sq ||
         (distance_sq == best.distance_sq && (best.index < 0 || j < best.index));
}

// The normal gate: target normal nq valid and (R n_p) . nq >= min_cosine.
KG_INLINE bool nearest_normal_accepts(double3 rotated_normal, float4 nq, double min_cosine) {
#if defined(__OPENCL_C_VERSION__)
#pragma OPENCL FP_CONTRACT OFF
#endif
  if (kg_isnan(nq.x)) return false;
  KG_PRECISE const double cosine = rotated_normal.x * KG_DOUBLE(nq.x) +
                                   rotated_normal.y * KG_DOUBLE(nq.y) +
                                   rotated_normal.z * KG_DOUBLE(nq.z);
  return cosine >= min_cosine;
}

// The neighbour offsets in visiting order: the query's own cell first.
KG_INLINE int nearest_offset(int k) {
  return k == 0 ? 0 : k == 1 ? -1 : 1;
}

// The distance, in cells, from a query at `fraction` of its cell to the neighbour at `offset`,
// less the margin.
KG_INLINE double nearest_gap(int offset, double fraction) {
  const double gap = offset == 0 ? 0.0 : offset < 0 ? fraction : 1.0 - fraction;
  return max(gap - KG_NEAREST_GAP_MARGIN, KG_DOUBLE(0.0));
}

// ---- The search: reads the shader's cell_keys, cell_ranges, cell_points, cell_indices,
// target_normals, frame (and source, source_normals for a whole item).

// The slot of key in the grid's table, or -1 when the cell is empty.
KG_FORCE_INLINE int nearest_find_cell(KG_BUFFER_PARAM(const uint64_t, cell_keys) uint64_t key,
                                      uint capacity_log2) {
  uint slot = voxel_slot(key, capacity_log2);
  while (cell_keys[slot] != key && cell_keys[slot] != KG_EMPTY_VOXEL_KEY) {
    slot = voxel_next_slot(slot, capacity_log2);
  }
  return cell_keys[slot] == KG_EMPTY_VOXEL_KEY ? -1 : KG_INT(slot);
}

// best, improved by the points of the cell at `slot`.
KG_FORCE_INLINE NearestCandidate
nearest_in_cell(KG_BUFFER_PARAM(const uint2, cell_ranges) KG_BUFFER_PARAM(const float4, cell_points)
                    KG_BUFFER_PARAM(const uint, cell_indices)
                        KG_BUFFER_PARAM(const float4, target_normals) uint slot,
                double3 moved, double3 rotated_normal, uint use_normals, double min_cosine,
                NearestCandidate best) {
  const uint2 range = cell_ranges[slot];
  for (uint m = range.x; m < range.x + range.y; ++m) {
    const int j = KG_INT(cell_indices[m]);
    const double distance_sq = nearest_distance_sq(moved, cell_points[m]);
    if (!nearest_improves(distance_sq, j, best)) continue;
    if (use_normals != 0u &&
        !nearest_normal_accepts(rotated_normal, target_normals[j], min_cosine)) {
      continue;
    }
    best.index = j;
    best.distance_sq = distance_sq;
  }
  return best;
}

// The nearest target point to `moved` (rotated_normal: its normal, where use_normals).
KG_FORCE_INLINE int nearest_in_grid(KG_BUFFER_PARAM(const uint64_t, cell_keys)
                                        KG_BUFFER_PARAM(const uint2, cell_ranges)
                                            KG_BUFFER_PARAM(const float4, cell_points)
                                                KG_BUFFER_PARAM(const uint, cell_indices)
                                                    KG_BUFFER_PARAM(const float4, target_normals)
                                                        KG_BUFFER_PARAM(const double, frame)
                                                            double3 moved,
                                    double3 rotated_normal, uint use_normals, uint capacity_log2) {
  const double cell_inverse = frame[KG_NEAREST_FRAME_CELL_INVERSE];
  const double3 scaled = moved * cell_inverse;
  const double3 base = voxel_floor(scaled);
  const double bound = KG_VOXEL_LIMIT + 1.0;
  if (!(kg_fabs(base.x) <= bound && kg_fabs(base.y) <= bound && kg_fabs(base.z) <= bound)) {
    return KG_NEAREST_NO_MATCH;  // NaN fails too
  }
  const double3 fraction = scaled - base;
  const double cell_sq = 1.0 / (cell_inverse * cell_inverse);
  NearestCandidate best;
  best.index = KG_NEAREST_NO_MATCH;
  best.distance_sq = frame[KG_NEAREST_FRAME_MAX_DISTANCE_SQ];
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      for (int c = 0; c < 3; ++c) {
        const int dx = nearest_offset(c), dy = nearest_offset(b), dz = nearest_offset(a);
        const double gx = nearest_gap(dx, fraction.x), gy = nearest_gap(dy, fraction.y),
                     gz = nearest_gap(dz, fraction.z);
        if ((gx * gx + gy * gy + gz * gz) * cell_sq > best.distance_sq) continue;
        const double3 cell = base + KG_DOUBLE3(KG_DOUBLE(dx), KG_DOUBLE(dy), KG_DOUBLE(dz));
        if (!voxel_in_range(cell)) continue;
        const int slot = nearest_find_cell(KG_BUFFER_ARG(cell_keys) voxel_key(cell), capacity_log2);
        if (slot < 0) continue;
        best = nearest_in_cell(
            KG_BUFFER_ARG(cell_ranges) KG_BUFFER_ARG(cell_points) KG_BUFFER_ARG(cell_indices)
                KG_BUFFER_ARG(target_normals) KG_UINT(slot),
            moved, rotated_normal, use_normals, frame[KG_NEAREST_FRAME_MIN_COSINE], best);
      }
    }
  }
  return best.index;
}

// Source point i's entry.
KG_FORCE_INLINE int voxel_hash_nearest_item(
    KG_BUFFER_PARAM(const float4, source) KG_BUFFER_PARAM(const float4, source_normals)
        KG_BUFFER_PARAM(const float4, target_normals) KG_BUFFER_PARAM(const uint64_t, cell_keys)
            KG_BUFFER_PARAM(const uint2, cell_ranges) KG_BUFFER_PARAM(const float4, cell_points)
                KG_BUFFER_PARAM(const uint, cell_indices) KG_BUFFER_PARAM(const double, frame)
                    uint i,
    VoxelHashNearestParams params) {
  if (!correspondence_selected(i, params.source_width, params.subsample)) {
    return KG_NEAREST_NOT_SELECTED;
  }
  const float4 p = source[i];
  if (kg_isnan(p.x)) return KG_NEAREST_NO_MATCH;
  double3 rotated_normal = KG_DOUBLE3(0.0, 0.0, 0.0);
  if (params.use_normals != 0u) {
    const float4 n = source_normals[i];
    if (kg_isnan(n.x)) return KG_NEAREST_NO_MATCH;
    rotated_normal = nearest_rotate(KG_BUFFER_ARG(frame)
                                        KG_DOUBLE3(KG_DOUBLE(n.x), KG_DOUBLE(n.y), KG_DOUBLE(n.z)));
  }
  return nearest_in_grid(KG_BUFFER_ARG(cell_keys) KG_BUFFER_ARG(cell_ranges)
                             KG_BUFFER_ARG(cell_points) KG_BUFFER_ARG(cell_indices)
                                 KG_BUFFER_ARG(target_normals) KG_BUFFER_ARG(frame)
                                     nearest_move(KG_BUFFER_ARG(frame) p),
                         rotated_normal, params.use_normals, params.capacity_log2);
}

KG_RULES_END

#endif
