// Voxel downsampling (rules in include/kartograf/geometry/voxel_downsample.hpp): one output point
// per voxel of valid input points, voxels in the order of their first (lowest-index) point, with
// the centroid, the normalised sum of the valid normals and the rounded mean colour. Every point
// adds its terms to its voxel's 64-bit fixed-point sums: integer addition is exact and
// order-independent, so all backends agree bit for bit. Six passes
// (src/geometry/voxel_downsample.cpp):
//   1 insert      each valid point puts its voxel key in the hash table, records its slot and keeps
//                 the lowest point index per slot (as 0xffffffff - i, atomic max; 0 = none yet)
//   2 count       thread t counts the first points of voxels in its chunk of points
//   3 scan        exclusive prefix sums of those counts (the total after them)
//   4 assign      thread t numbers the voxels first met in its chunk from its offset on
//   5 accumulate  every point adds its terms to its voxel's sums
//   6 finalize    one output point per voxel from its sums
// The passes' loops and table probes are written here once; in GLSL, where a rule reads the
// shader's buffers by name, a shader enables the sections whose buffers it declares
// (KG_VOXEL_*_PASS). The terms of pass 5 are added by the wrappers (atomics on devices, plain adds
// in one ordered loop on the CPU: the same integers).
#ifndef KARTOGRAF_KERNELS_VOXEL_DOWNSAMPLE_H
#define KARTOGRAF_KERNELS_VOXEL_DOWNSAMPLE_H
#include "kernels/voxel_hash/voxel_hash.h"

#define KG_VOXEL_DOWNSAMPLE_LOCAL_X 64

// The status counters the insert pass fills and the host reports.
#define KG_VOXEL_STATUS_OUT_OF_RANGE 0u  // voxels beyond 2^20 (or NaN/Inf coordinates)
#define KG_VOXEL_STATUS_TABLE_FULL 1u
#define KG_VOXEL_STATUS_BAD_NORMALS 2u  // valid normals with a component beyond +-2
#define KG_VOXEL_STATUS_VALUES 3u

// Per voxel, `stride` int64 sums: the point count, the position within the voxel (fraction of
// p * inverse_size, in [0, 1)), with normals the sum of the usable normals and their count, then
// with colours the r, g, b sums (at voxel_color_offset).
#define KG_VOXEL_SUM_COUNT 0u
#define KG_VOXEL_SUM_POSITION 1u
#define KG_VOXEL_SUM_NORMAL 4u
#define KG_VOXEL_SUM_NORMAL_COUNT 7u
#define KG_VOXEL_MAX_SUMS 11  // with normals and colours

// Normals beyond +-2 per component are an error; skipping them keeps the fixed-point sums bounded.
#define KG_VOXEL_MAX_NORMAL_COMPONENT 2.0f

KG_RULES_BEGIN

KG_PARAMS_BEGIN(VoxelInsertParams)
KG_PARAM(uint, point_count)
KG_PARAM(uint, capacity_log2)
KG_PARAM(uint, has_normals)
KG_PARAM(float, inverse_size)
KG_PARAMS_END(VoxelInsertParams)

// The ordering passes: thread t walks points [t * chunk, (t + 1) * chunk).
KG_PARAMS_BEGIN(VoxelChunkParams)
KG_PARAM(uint, point_count)
KG_PARAM(uint, chunk)
KG_PARAMS_END(VoxelChunkParams)

KG_PARAMS_BEGIN(VoxelScanParams)
KG_PARAM(uint, thread_count)  // a multiple of KG_VOXEL_DOWNSAMPLE_LOCAL_X
KG_PARAMS_END(VoxelScanParams)

KG_PARAMS_BEGIN(VoxelSumParams)
KG_PARAM(uint, count)  // points (accumulate) or voxels (finalize)
KG_PARAM(uint, stride)
KG_PARAM(uint, has_normals)
KG_PARAM(uint, has_colors)
KG_PARAM(float, inverse_size)
KG_PARAM(float, position_scale)  // 2^k: fixed-point scale of the position sums
KG_PARAM(float, normal_scale)    // 2^k: fixed-point scale of the normal sums
KG_PARAMS_END(VoxelSumParams)

KG_INLINE uint voxel_color_offset(uint has_normals) {
  return has_normals != 0u ? 8u : 4u;
}

KG_INLINE uint voxel_sum_stride(uint has_normals, uint has_colors) {
  return voxel_color_offset(has_normals) + (has_colors != 0u ? 3u : 0u);
}

KG_INLINE bool voxel_normal_bounded(float4 n) {
  return kg_fabs(n.x) <= KG_VOXEL_MAX_NORMAL_COMPONENT &&
         kg_fabs(n.y) <= KG_VOXEL_MAX_NORMAL_COMPONENT &&
         kg_fabs(n.z) <= KG_VOXEL_MAX_NORMAL_COMPONENT;
}

// p in voxel units: exact in double (a float times a float).
KG_INLINE double3 voxel_scaled(float4 p, float inverse_size) {
  return KG_DOUBLE3(KG_DOUBLE(p.x), KG_DOUBLE(p.y), KG_DOUBLE(p.z)) * KG_DOUBLE(inverse_size);
}

// value * scale as a fixed-point integer, rounded half to even.
KG_INLINE int64_t voxel_fixed(double value, float scale) {
  return kg_round_even_int64(value * KG_DOUBLE(scale));
}

// Whether a normal adds to its voxel's normal sums.
KG_INLINE bool voxel_normal_usable(float4 n) {
  return !kg_isnan(n.x) && voxel_normal_bounded(n);
}

// A point's terms (GLSL: module scope; C, C++: the caller's array).
KG_ACCUMULATOR_STORAGE(int64_t, terms, KG_VOXEL_MAX_SUMS)

// The terms point p (with its normal n and colour c where the cloud has them) adds to the sums of
// its voxel, terms[0..stride) (0: nothing to add). The wrappers add them: atomics on devices.
KG_FORCE_INLINE void voxel_point_terms(KG_ACCUMULATOR(int64_t, terms, KG_VOXEL_MAX_SUMS) float4 p,
                                       float4 n, uint c, VoxelSumParams params) {
  const double3 scaled = voxel_scaled(p, params.inverse_size);
  const double3 fraction = scaled - voxel_floor(scaled);  // exact
  terms[KG_VOXEL_SUM_COUNT] = KG_INT64(1);
  terms[KG_VOXEL_SUM_POSITION] = voxel_fixed(fraction.x, params.position_scale);
  terms[KG_VOXEL_SUM_POSITION + 1u] = voxel_fixed(fraction.y, params.position_scale);
  terms[KG_VOXEL_SUM_POSITION + 2u] = voxel_fixed(fraction.z, params.position_scale);
  if (params.has_normals != 0u) {
    const bool usable = voxel_normal_usable(n);
    const float4 added = usable ? n : KG_FLOAT4(0.0f, 0.0f, 0.0f, 0.0f);
    terms[KG_VOXEL_SUM_NORMAL] = voxel_fixed(KG_DOUBLE(added.x), params.normal_scale);
    terms[KG_VOXEL_SUM_NORMAL + 1u] = voxel_fixed(KG_DOUBLE(added.y), params.normal_scale);
    terms[KG_VOXEL_SUM_NORMAL + 2u] = voxel_fixed(KG_DOUBLE(added.z), params.normal_scale);
    terms[KG_VOXEL_SUM_NORMAL_COUNT] = KG_INT64(usable ? 1 : 0);
  }
  if (params.has_colors != 0u) {
    // Constant indices (not color_offset + channel) let compilers keep terms in registers.
    const int64_t r = KG_INT64(c & 0xffu), g = KG_INT64((c >> 8u) & 0xffu),
                  b = KG_INT64((c >> 16u) & 0xffu);
    if (params.has_normals != 0u) {
      terms[8] = r;
      terms[9] = g;
      terms[10] = b;
    } else {
      terms[4] = r;
      terms[5] = g;
      terms[6] = b;
    }
  }
}

// The output point of a voxel: (voxel + mean fraction) / inverse_size.
KG_INLINE float4 voxel_centroid(uint64_t key, int64_t count, int64_t sum_x, int64_t sum_y,
                                int64_t sum_z, VoxelSumParams params) {
  const double3 fraction = KG_DOUBLE3(KG_DOUBLE(sum_x), KG_DOUBLE(sum_y), KG_DOUBLE(sum_z)) /
                           (KG_DOUBLE(count) * KG_DOUBLE(params.position_scale));
  const double3 mean_point = (voxel_of_key(key) + fraction) / KG_DOUBLE(params.inverse_size);
  return KG_FLOAT4(KG_FLOAT(mean_point.x), KG_FLOAT(mean_point.y), KG_FLOAT(mean_point.z), 1.0f);
}

// The unit sum of the voxel's usable normals; invalid when there is none or the sum is shorter
// than 1e-3 x their count (they cancel).
KG_INLINE float4 voxel_normal(int64_t sum_x, int64_t sum_y, int64_t sum_z, int64_t normal_count,
                              VoxelSumParams params) {
  const double3 sum = KG_DOUBLE3(KG_DOUBLE(sum_x), KG_DOUBLE(sum_y), KG_DOUBLE(sum_z)) /
                      KG_DOUBLE(params.normal_scale);
  const double norm = sqrt(dot(sum, sum));
  // 1e-3 in double in every language (an unsuffixed GLSL literal is a float).
  const double min_length_per_normal = KG_DOUBLE(1.0) / KG_DOUBLE(1000.0);
  if (normal_count == KG_INT64(0) || norm < min_length_per_normal * KG_DOUBLE(normal_count)) {
    return KG_INVALID_POINT;
  }
  return KG_FLOAT4(KG_FLOAT(sum.x / norm), KG_FLOAT(sum.y / norm), KG_FLOAT(sum.z / norm), 0.0f);
}

// One channel's mean (sum / count rounded half up), shifted into its byte of the packed colour.
KG_INLINE uint voxel_color_channel(int64_t sum, int64_t count, uint channel) {
  const uint64_t n = KG_UINT64(count);
  const uint64_t mean = (2UL * KG_UINT64(sum) + n) / (2UL * n);
  return KG_UINT(mean) << (8u * channel);
}

// ---- Pass 1 (insert): the shader declares keys, first and status.
#if !defined(VULKAN) || defined(KG_VOXEL_INSERT_PASS)

// Point i (p, and its normal n where has_normals): its slot, or -1 for an invalid point or an
// error.
KG_FORCE_INLINE int voxel_insert_point(KG_BUFFER_PARAM(uint64_t, keys) KG_BUFFER_PARAM(uint, first)
                                           KG_BUFFER_PARAM(uint, status) uint i,
                                       float4 p, float4 n, VoxelInsertParams params) {
  if (kg_isnan(p.x)) return -1;
  if (params.has_normals != 0u && !kg_isnan(n.x) && !voxel_normal_bounded(n)) {
    kg_atomic_add_u32(status, KG_VOXEL_STATUS_BAD_NORMALS, 1u);
  }
  const double3 voxel = voxel_floor(voxel_scaled(p, params.inverse_size));
  if (!voxel_in_range(voxel)) {
    kg_atomic_add_u32(status, KG_VOXEL_STATUS_OUT_OF_RANGE, 1u);
    return -1;
  }
  const int slot = voxel_insert_key(KG_BUFFER_ARG(keys) voxel_key(voxel), params.capacity_log2);
  if (slot < 0) {
    kg_atomic_add_u32(status, KG_VOXEL_STATUS_TABLE_FULL, 1u);
  } else {
    kg_atomic_max_u32(first, KG_UINT(slot), 0xffffffffu - i);
  }
  return slot;
}

#endif

// ---- Passes 2 and 4 (count, assign): the shader declares point_slots and first.
#if !defined(VULKAN) || defined(KG_VOXEL_ORDER_PASS)

// Whether point i is the lowest-index point of its voxel.
KG_INLINE bool voxel_is_first_point(KG_BUFFER_PARAM(const int, point_slots)
                                        KG_BUFFER_PARAM(const uint, first) uint i) {
  const int slot = point_slots[i];
  return slot >= 0 && first[slot] == 0xffffffffu - i;
}

KG_INLINE uint voxel_chunk_begin(uint t, VoxelChunkParams params) {
  return min(t * params.chunk, params.point_count);
}

KG_INLINE uint voxel_chunk_end(uint t, VoxelChunkParams params) {
  return min(voxel_chunk_begin(t, params) + params.chunk, params.point_count);
}

KG_FORCE_INLINE uint voxel_count_first_points(KG_BUFFER_PARAM(const int, point_slots)
                                                  KG_BUFFER_PARAM(const uint, first) uint t,
                                              VoxelChunkParams params) {
  uint count = 0u;
  const uint end = voxel_chunk_end(t, params);
  for (uint i = voxel_chunk_begin(t, params); i < end; ++i) {
    if (voxel_is_first_point(KG_BUFFER_ARG(point_slots) KG_BUFFER_ARG(first) i)) ++count;
  }
  return count;
}

#endif

// ---- Pass 4 (assign): the shader also declares counts, keys, voxel_of_slot and voxel_keys.
#if !defined(VULKAN) || defined(KG_VOXEL_ASSIGN_PASS)

// Numbers the voxels whose first point lies in thread t's chunk: output voxel v is the v-th voxel
// in the order of first points. Writes the voxel number per slot and the key per voxel.
KG_FORCE_INLINE void voxel_assign_chunk(
    KG_BUFFER_PARAM(const int, point_slots) KG_BUFFER_PARAM(const uint, first)
        KG_BUFFER_PARAM(const uint, counts) KG_BUFFER_PARAM(const uint64_t, keys)
            KG_BUFFER_PARAM(uint, voxel_of_slot) KG_BUFFER_PARAM(uint64_t, voxel_keys) uint t,
    VoxelChunkParams params) {
  uint voxel = counts[t];
  const uint end = voxel_chunk_end(t, params);
  for (uint i = voxel_chunk_begin(t, params); i < end; ++i) {
    if (!voxel_is_first_point(KG_BUFFER_ARG(point_slots) KG_BUFFER_ARG(first) i)) continue;
    const uint slot = KG_UINT(point_slots[i]);
    voxel_of_slot[slot] = voxel;
    voxel_keys[voxel] = keys[slot];
    ++voxel;
  }
}

#endif

// ---- Pass 5 (accumulate): the shader declares points, normals and colors.
#if !defined(VULKAN) || defined(KG_VOXEL_ACCUMULATE_PASS)

// Point i's terms, reading its normal and colour where the cloud has them.
KG_FORCE_INLINE void voxel_point_terms_at(KG_BUFFER_PARAM(const float4, points)
                                              KG_BUFFER_PARAM(const float4, normals)
                                                  KG_BUFFER_PARAM(const uint, colors)
                                                      KG_ACCUMULATOR(int64_t, terms,
                                                                     KG_VOXEL_MAX_SUMS) uint i,
                                          VoxelSumParams params) {
  const float4 n = params.has_normals != 0u ? normals[i] : KG_INVALID_POINT;
  const uint c = params.has_colors != 0u ? colors[i] : 0u;
  voxel_point_terms(KG_ACCUMULATOR_ARG(terms) points[i], n, c, params);
}

#endif

// ---- Pass 6 (finalize): the shader declares voxel_keys, sums, out_points, out_normals and
// out_colors.
#if !defined(VULKAN) || defined(KG_VOXEL_FINALIZE_PASS)

KG_INLINE float4 voxel_output_point(KG_BUFFER_PARAM(const int64_t, sums) uint64_t key, uint base,
                                    VoxelSumParams params) {
  return voxel_centroid(key, sums[base + KG_VOXEL_SUM_COUNT], sums[base + KG_VOXEL_SUM_POSITION],
                        sums[base + KG_VOXEL_SUM_POSITION + 1u],
                        sums[base + KG_VOXEL_SUM_POSITION + 2u], params);
}

KG_INLINE float4 voxel_output_normal(KG_BUFFER_PARAM(const int64_t, sums) uint base,
                                     VoxelSumParams params) {
  return voxel_normal(sums[base + KG_VOXEL_SUM_NORMAL], sums[base + KG_VOXEL_SUM_NORMAL + 1u],
                      sums[base + KG_VOXEL_SUM_NORMAL + 2u], sums[base + KG_VOXEL_SUM_NORMAL_COUNT],
                      params);
}

KG_INLINE uint voxel_output_color(KG_BUFFER_PARAM(const int64_t, sums) uint base,
                                  VoxelSumParams params) {
  const uint color_base = base + voxel_color_offset(params.has_normals);
  const int64_t count = sums[base + KG_VOXEL_SUM_COUNT];
  uint packed = 0u;
  for (uint channel = 0u; channel < 3u; ++channel) {
    packed |= voxel_color_channel(sums[color_base + channel], count, channel);
  }
  return packed;
}

// Output voxel v from its sums (the normal and colour where the cloud has them).
KG_FORCE_INLINE void voxel_finalize(KG_BUFFER_PARAM(const uint64_t, voxel_keys)
                                        KG_BUFFER_PARAM(const int64_t, sums)
                                            KG_BUFFER_PARAM(float4, out_points)
                                                KG_BUFFER_PARAM(float4, out_normals)
                                                    KG_BUFFER_PARAM(uint, out_colors) uint v,
                                    VoxelSumParams params) {
  const uint base = v * params.stride;
  out_points[v] = voxel_output_point(KG_BUFFER_ARG(sums) voxel_keys[v], base, params);
  if (params.has_normals != 0u) {
    out_normals[v] = voxel_output_normal(KG_BUFFER_ARG(sums) base, params);
  }
  if (params.has_colors != 0u) out_colors[v] = voxel_output_color(KG_BUFFER_ARG(sums) base, params);
}

#endif

KG_RULES_END

#endif
