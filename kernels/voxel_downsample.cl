// Voxel downsampling in six passes; see shaders/voxel_downsample_*.comp (same rules and layouts)
// and src/geometry/voxel_downsample.cpp.
typedef struct {
  uint point_count;
  uint capacity_log2;
  uint has_normals;
  float inverse_size;
} VoxelInsertParams;

typedef struct {
  uint point_count;
  uint chunk;
} VoxelChunkParams;

typedef struct {
  uint thread_count;
} VoxelScanParams;

typedef struct {
  uint count;  // points (accumulate) or voxels (finalize)
  uint stride;
  uint has_normals;
  uint has_colors;
  float inverse_size;
  float position_scale;
  float normal_scale;
} VoxelSumParams;

inline bool kg_is_unit_bounded(float4 n) {
  return fabs(n.x) <= 2.0f && fabs(n.y) <= 2.0f && fabs(n.z) <= 2.0f;
}

__kernel void voxel_downsample_insert(__global const float4* points, __global const float4* normals,
                                      __global ulong* keys, __global uint* first,
                                      __global int* point_slots, __global uint* status,
                                      const VoxelInsertParams params) {
  const uint i = get_global_id(0);
  if (i >= params.point_count) return;
  const float4 p = points[i];
  int slot = -1;
  double3 voxel;
  if (kg_is_valid_point(p) && params.has_normals != 0u) {
    const float4 n = normals[i];
    if (kg_is_valid_point(n) && !kg_is_unit_bounded(n)) atomic_inc(&status[2]);
  }
  if (kg_is_valid_point(p)) {
    if (!kg_voxel_of(convert_double3(p.xyz) * (double)params.inverse_size, &voxel)) {
      atomic_inc(&status[0]);
    } else {
      const ulong key = kg_voxel_key(voxel);
      const uint mask = (1u << params.capacity_log2) - 1u;
      uint s = kg_voxel_slot(key, params.capacity_log2);
      for (uint probe = 0u; probe <= mask; ++probe) {
        const ulong found = atom_cmpxchg(&keys[s], 0UL, key);
        if (found == 0UL || found == key) {
          slot = (int)s;
          break;
        }
        s = (s + 1u) & mask;
      }
      if (slot < 0) {
        atomic_inc(&status[1]);
      } else {
        atomic_max(&first[slot], 0xffffffffu - i);
      }
    }
  }
  point_slots[i] = slot;
}

inline bool kg_is_first_of_voxel(uint i, __global const int* point_slots, __global const uint* first) {
  const int slot = point_slots[i];
  return slot >= 0 && first[slot] == 0xffffffffu - i;
}

__kernel void voxel_downsample_count(__global const int* point_slots, __global const uint* first,
                                     __global uint* counts, const VoxelChunkParams params) {
  const uint t = get_global_id(0);
  const uint begin = min(t * params.chunk, params.point_count);
  const uint end = min(begin + params.chunk, params.point_count);
  uint count = 0u;
  for (uint i = begin; i < end; ++i) count += kg_is_first_of_voxel(i, point_slots, first) ? 1u : 0u;
  counts[t] = count;
}

__kernel void voxel_downsample_scan(__global uint* counts, const VoxelScanParams params) {
  __local uint part_offsets[64];
  const uint lane = get_local_id(0);
  const uint part = params.thread_count / 64u;
  const uint base = lane * part;
  uint sum = 0u;
  for (uint j = 0u; j < part; ++j) sum += counts[base + j];
  part_offsets[lane] = sum;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lane == 0u) {
    uint running = 0u;
    for (uint l = 0u; l < 64u; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = running;
      running += value;
    }
    counts[params.thread_count] = running;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  uint offset = part_offsets[lane];
  for (uint j = 0u; j < part; ++j) {
    const uint value = counts[base + j];
    counts[base + j] = offset;
    offset += value;
  }
}

__kernel void voxel_downsample_assign(__global const int* point_slots, __global const uint* first,
                                      __global const uint* counts, __global const ulong* keys,
                                      __global uint* voxel_of_slot, __global ulong* voxel_keys,
                                      const VoxelChunkParams params) {
  const uint t = get_global_id(0);
  const uint begin = min(t * params.chunk, params.point_count);
  const uint end = min(begin + params.chunk, params.point_count);
  uint voxel = counts[t];
  for (uint i = begin; i < end; ++i) {
    if (!kg_is_first_of_voxel(i, point_slots, first)) continue;
    const uint slot = (uint)point_slots[i];
    voxel_of_slot[slot] = voxel;
    voxel_keys[voxel] = keys[slot];
    ++voxel;
  }
}

__kernel void voxel_downsample_accumulate(__global const float4* points, __global const float4* normals,
                                          __global const uint* colors, __global const int* point_slots,
                                          __global const uint* voxel_of_slot, __global long* sums,
                                          const VoxelSumParams params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  const int slot = point_slots[i];
  if (slot < 0) return;
  const uint base = voxel_of_slot[slot] * params.stride;
  const double3 scaled = convert_double3(points[i].xyz) * (double)params.inverse_size;
  const double3 fraction = scaled - floor(scaled);
  const double position_scale = (double)params.position_scale;
  atom_add(&sums[base], 1L);
  kg_add_fixed(sums, base + 1u, fraction.x, position_scale);
  kg_add_fixed(sums, base + 2u, fraction.y, position_scale);
  kg_add_fixed(sums, base + 3u, fraction.z, position_scale);
  if (params.has_normals != 0u) {
    const float4 n = normals[i];
    if (kg_is_valid_point(n) && kg_is_unit_bounded(n)) {
      const double normal_scale = (double)params.normal_scale;
      kg_add_fixed(sums, base + 4u, (double)n.x, normal_scale);
      kg_add_fixed(sums, base + 5u, (double)n.y, normal_scale);
      kg_add_fixed(sums, base + 6u, (double)n.z, normal_scale);
      atom_add(&sums[base + 7u], 1L);
    }
  }
  if (params.has_colors != 0u) {
    const uint c = colors[i];
    const uint color_base = base + (params.has_normals != 0u ? 8u : 4u);
    atom_add(&sums[color_base], (long)(c & 0xffu));
    atom_add(&sums[color_base + 1u], (long)((c >> 8) & 0xffu));
    atom_add(&sums[color_base + 2u], (long)((c >> 16) & 0xffu));
  }
}

__kernel void voxel_downsample_finalize(__global const ulong* voxel_keys, __global const long* sums,
                                        __global float4* out_points, __global float4* out_normals,
                                        __global uint* out_colors, const VoxelSumParams params) {
  const uint v = get_global_id(0);
  if (v >= params.count) return;
  const uint base = v * params.stride;
  const long count = sums[base];
  const double3 fraction = (double3)((double)sums[base + 1u], (double)sums[base + 2u],
                                     (double)sums[base + 3u]) /
                           ((double)count * (double)params.position_scale);
  const double3 centroid = (kg_voxel_of_key(voxel_keys[v]) + fraction) / (double)params.inverse_size;
  out_points[v] = (float4)(convert_float3(centroid), 1.0f);
  if (params.has_normals != 0u) {
    const long normal_count = sums[base + 7u];
    const double3 sum = (double3)((double)sums[base + 4u], (double)sums[base + 5u],
                                  (double)sums[base + 6u]) /
                        (double)params.normal_scale;
    const double norm = sqrt(dot(sum, sum));
    out_normals[v] = normal_count == 0 || norm < 1e-3 * (double)normal_count
                         ? KG_INVALID_POINT
                         : (float4)(convert_float3(sum / norm), 0.0f);
  }
  if (params.has_colors != 0u) {
    const uint color_base = base + (params.has_normals != 0u ? 8u : 4u);
    const ulong n = (ulong)count;
    uint packed = 0u;
    for (uint channel = 0u; channel < 3u; ++channel) {
      const ulong mean = (2UL * (ulong)sums[color_base + channel] + n) / (2UL * n);
      packed |= (uint)mean << (8u * channel);
    }
    out_colors[v] = packed;
  }
}
