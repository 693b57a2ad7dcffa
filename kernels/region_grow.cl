// Parallel Lab region growing in 6 passes (rows, then upper neighbours, then numbering); see shaders/region_grow*.{glsl,comp} (the same rules,
// kernel names, buffers and parameter layout) and
// include/kartograf/segmentation/parallel_region_growing.hpp for the contract.
typedef struct {
  uint width;
  uint height;
  uint pixel_count;
  uint block_count;  // padded to a multiple of 64
  uint limit;        // connect when the quantised squared Lab distance < limit
  float depth_ratio;  // 0: no depth test
} RegionGrowParams;

#define KG_NO_LABEL 0xffffffffu
#define KG_PIXELS_PER_BLOCK 256u

inline int3 kg_quantised_lab(float4 lab) {
  return convert_int3_rte(clamp(lab.xyz, -255.0f, 255.0f) * 64.0f);
}

inline bool kg_is_valid_pixel(float4 lab, float4 point) {
  return kg_is_valid_point(point) && isfinite(lab.x) && isfinite(lab.y) && isfinite(lab.z);
}

inline bool kg_connected(float4 lab_a, float4 point_a, float4 lab_b, float4 point_b,
                         const RegionGrowParams* params) {
  const int3 d = kg_quantised_lab(lab_a) - kg_quantised_lab(lab_b);
  const uint distance_sq = (uint)(d.x * d.x) + (uint)(d.y * d.y) + (uint)(d.z * d.z);
  if (distance_sq >= params->limit) return false;
  if (params->depth_ratio == 0.0f) return true;
  const double za = (double)point_a.z, zb = (double)point_b.z;
  return fabs(za - zb) <= (double)params->depth_ratio * fmin(za, zb);
}

// One work-item per row: each valid pixel's parent is the first pixel of its run of left-joined
// pixels (see region_grow_init.comp).
__kernel void region_grow_init(__global const float4* lab, __global const float4* points,
                               __global uint* parent, const RegionGrowParams params) {
  const uint y = get_global_id(0);
  if (y >= params.height) return;
  uint run_start = KG_NO_LABEL;
  bool previous_valid = false;
  float4 previous_lab = (float4)(0.0f), previous_point = (float4)(0.0f);
  for (uint i = y * params.width; i < (y + 1u) * params.width; ++i) {
    const float4 lab_i = lab[i], point_i = points[i];
    const bool valid = kg_is_valid_pixel(lab_i, point_i);
    if (!valid) {
      parent[i] = KG_NO_LABEL;
    } else {
      if (!previous_valid ||
          !kg_connected(lab_i, point_i, previous_lab, previous_point, &params)) {
        run_start = i;
      }
      parent[i] = run_start;
    }
    previous_valid = valid;
    previous_lab = lab_i;
    previous_point = point_i;
  }
}

// Follows parents to the root, then points `start` straight at it (atomic_min: see
// region_grow_union.comp).
inline uint kg_find_root(volatile __global uint* parent, uint start) {
  uint i = start;
  uint p = parent[i];
  while (p != i) {
    i = p;
    p = parent[i];
  }
  if (i != start) atomic_min(&parent[start], i);
  return i;
}

// Playne & Hawick's atomic union with min-linking (see region_grow_union.comp).
inline void kg_unite(volatile __global uint* parent, uint a, uint b) {
  for (;;) {
    a = kg_find_root(parent, a);
    b = kg_find_root(parent, b);
    if (a == b) return;
    if (a > b) {
      const uint t = a;
      a = b;
      b = t;
    }
    const uint old = atomic_min(&parent[b], a);
    if (old == b) return;
    b = old;
  }
}

__kernel void region_grow_union(__global const float4* lab, __global const float4* points,
                                volatile __global uint* parent, const RegionGrowParams params) {
  const uint i = get_global_id(0);
  if (i >= params.pixel_count || parent[i] == KG_NO_LABEL) return;
  const int x = (int)(i % params.width), y = (int)(i / params.width);
  const float4 lab_i = lab[i], point_i = points[i];
  if (y == 0) return;
  for (int dx = -1; dx <= 1; ++dx) {
    const int nx = x + dx;
    if (nx < 0 || nx >= (int)params.width) continue;
    const uint j = (uint)(y - 1) * params.width + (uint)nx;
    if (parent[j] == KG_NO_LABEL) continue;  // invalid pixels never change
    if (kg_connected(lab_i, point_i, lab[j], points[j], &params)) kg_unite(parent, i, j);
  }
}

__kernel void region_grow_count(__global const uint* parent, __global uint* block_counts,
                                const RegionGrowParams params) {
  const uint block = get_global_id(0);
  if (block >= params.block_count) return;
  const uint begin = min(block * KG_PIXELS_PER_BLOCK, params.pixel_count);
  const uint end = min(begin + KG_PIXELS_PER_BLOCK, params.pixel_count);
  uint roots = 0u;
  for (uint i = begin; i < end; ++i) roots += parent[i] == i ? 1u : 0u;
  block_counts[block] = roots;
}

__kernel void region_grow_scan(__global uint* block_counts, __global uint* status,
                               const RegionGrowParams params) {
  __local uint part_offsets[64];
  const uint lane = get_local_id(0);
  const uint part = params.block_count / 64u;
  const uint base = lane * part;
  uint sum = 0u;
  for (uint j = 0u; j < part; ++j) sum += block_counts[base + j];
  part_offsets[lane] = sum;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lane == 0u) {
    uint running = 0u;
    for (uint l = 0u; l < 64u; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = running;
      running += value;
    }
    status[0] = running;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  uint offset = part_offsets[lane];
  for (uint j = 0u; j < part; ++j) {
    const uint value = block_counts[base + j];
    block_counts[base + j] = offset;
    offset += value;
  }
}

__kernel void region_grow_number_roots(__global const uint* parent,
                                       __global const uint* block_offsets, __global uint* labels,
                                       const RegionGrowParams params) {
  const uint block = get_global_id(0);
  if (block >= params.block_count) return;
  const uint begin = min(block * KG_PIXELS_PER_BLOCK, params.pixel_count);
  const uint end = min(begin + KG_PIXELS_PER_BLOCK, params.pixel_count);
  uint next = block_offsets[block];
  for (uint i = begin; i < end; ++i) {
    if (parent[i] == i) labels[i] = next++;
  }
}

__kernel void region_grow_assign(__global const uint* parent, __global uint* labels,
                                 const RegionGrowParams params) {
  const uint i = get_global_id(0);
  if (i >= params.pixel_count) return;
  uint p = parent[i];
  if (p == KG_NO_LABEL) {
    labels[i] = KG_NO_LABEL;
    return;
  }
  if (p == i) return;  // a root: numbered by region_grow_number_roots
  uint root = i;
  while (p != root) {
    root = p;
    p = parent[root];
  }
  labels[i] = labels[root];
}
