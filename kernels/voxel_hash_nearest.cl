// Nearest-neighbour search in a voxel-hash grid; see shaders/voxel_hash_nearest.comp. Contraction
// is off so moved points and distances are the CPU's doubles, bit for bit.
typedef struct {
  uint source_count;
  uint source_width;
  uint subsample;
  uint capacity_log2;
  uint use_normals;
} VoxelHashNearestParams;

// The distance, in cells, from a query at `fraction` of its cell to the neighbour at `offset`.
inline double kg_gap(int offset, double fraction) {
  return offset == 0 ? 0.0 : offset < 0 ? fraction : 1.0 - fraction;
}

inline int kg_voxel_hash_nearest(uint i, __global const float4* source,
                                 __global const float4* source_normals,
                                 __global const float4* target_normals,
                                 __global const ulong* cell_keys, __global const uint2* cell_ranges,
                                 __global const float4* cell_points,
                                 __global const uint* cell_indices, __global const double* frame,
                                 const VoxelHashNearestParams* params) {
#pragma OPENCL FP_CONTRACT OFF
  const uint row = params->source_width == 0u ? 0u : i / params->source_width;
  if ((i + row) % params->subsample != 0u) return -2;
  const float4 p = source[i];
  if (!kg_is_valid_point(p)) return -1;
  const double3 ps = convert_double3(p.xyz);
  const double3 moved =
      (double3)(frame[0] * ps.x + frame[1] * ps.y + frame[2] * ps.z + frame[9],
                frame[3] * ps.x + frame[4] * ps.y + frame[5] * ps.z + frame[10],
                frame[6] * ps.x + frame[7] * ps.y + frame[8] * ps.z + frame[11]);
  double3 rotated_normal = (double3)(0.0, 0.0, 0.0);
  if (params->use_normals != 0u) {
    const float4 np = source_normals[i];
    if (!kg_is_valid_point(np)) return -1;
    const double3 n = convert_double3(np.xyz);
    rotated_normal = (double3)(frame[0] * n.x + frame[1] * n.y + frame[2] * n.z,
                               frame[3] * n.x + frame[4] * n.y + frame[5] * n.z,
                               frame[6] * n.x + frame[7] * n.y + frame[8] * n.z);
  }
  const double3 scaled = moved * frame[12];
  const double3 base = floor(scaled);
  const double bound = KG_VOXEL_LIMIT + 1.0;
  if (!(fabs(base.x) <= bound && fabs(base.y) <= bound && fabs(base.z) <= bound)) return -1;
  const double3 fraction = scaled - base;
  const double cell_sq = 1.0 / (frame[12] * frame[12]);
  const uint mask = (1u << params->capacity_log2) - 1u;
  int best = -1;
  double best_distance_sq = frame[13];
  const int order[3] = {0, -1, 1};
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      for (int c = 0; c < 3; ++c) {
        const int3 offset = (int3)(order[c], order[b], order[a]);
        const double3 gap = fmax((double3)(kg_gap(offset.x, fraction.x), kg_gap(offset.y, fraction.y),
                                           kg_gap(offset.z, fraction.z)) - 1e-9,
                                 (double3)(0.0, 0.0, 0.0));
        if (dot(gap, gap) * cell_sq > best_distance_sq) continue;
        const double3 cell = base + convert_double3(offset);
        if (cell.x < -KG_VOXEL_LIMIT || cell.y < -KG_VOXEL_LIMIT || cell.z < -KG_VOXEL_LIMIT ||
            cell.x >= KG_VOXEL_LIMIT || cell.y >= KG_VOXEL_LIMIT || cell.z >= KG_VOXEL_LIMIT) {
          continue;
        }
        const ulong key = kg_voxel_key(cell);
        uint slot = kg_voxel_slot(key, params->capacity_log2);
        while (cell_keys[slot] != key && cell_keys[slot] != 0UL) slot = (slot + 1u) & mask;
        if (cell_keys[slot] == 0UL) continue;
        const uint2 range = cell_ranges[slot];
        for (uint m = range.x; m < range.x + range.y; ++m) {
          const int j = (int)cell_indices[m];
          const double3 d = moved - convert_double3(cell_points[m].xyz);
          const double distance_sq = d.x * d.x + d.y * d.y + d.z * d.z;
          if (!(distance_sq < best_distance_sq ||
                (distance_sq == best_distance_sq && (best < 0 || j < best)))) {
            continue;
          }
          if (params->use_normals != 0u) {
            const float4 nq = target_normals[j];
            if (!kg_is_valid_point(nq)) continue;
            const double cosine = rotated_normal.x * (double)nq.x + rotated_normal.y * (double)nq.y +
                                  rotated_normal.z * (double)nq.z;
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

__kernel void voxel_hash_nearest(__global const float4* source, __global const float4* source_normals,
                                 __global const float4* target_normals,
                                 __global const ulong* cell_keys, __global const uint2* cell_ranges,
                                 __global const float4* cell_points,
                                 __global const uint* cell_indices, __global const double* frame,
                                 __global int* correspondences, const VoxelHashNearestParams params) {
  const uint i = get_global_id(0);
  if (i >= params.source_count) return;
  correspondences[i] = kg_voxel_hash_nearest(i, source, source_normals, target_normals, cell_keys,
                                             cell_ranges, cell_points, cell_indices, frame, &params);
}
