// Voxel keys and their open-addressing hash table, shared by voxel downsampling
// (kernels/voxel_downsample), the voxel-hash nearest-neighbour grid (kernels/voxel_hash_nearest)
// and the host tables built on them (geometry/voxel_key.hpp). A voxel (kx, ky, kz) =
// floor(p * inverse_size), each in [-2^20, 2^20), is stored as the 64-bit key
// 1 + (kx + 2^20) | (ky + 2^20) << 21 | (kz + 2^20) << 42, so 0 marks an empty slot. A key's first
// slot is Fibonacci hashing; probing then walks slot + 1, + 2, ... mod the (power of two) capacity.
#ifndef KARTOGRAF_KERNELS_VOXEL_HASH_H
#define KARTOGRAF_KERNELS_VOXEL_HASH_H
#include "shaders/prelude.h"

#define KG_VOXEL_LIMIT 1048576.0  // 2^20
#define KG_EMPTY_VOXEL_KEY 0UL

KG_RULES_BEGIN

KG_INLINE double3 voxel_floor(double3 scaled) {
  return KG_DOUBLE3(floor(scaled.x), floor(scaled.y), floor(scaled.z));
}

// Whether a voxel (integral coordinates) has a key: each coordinate in [-2^20, 2^20), not NaN.
KG_INLINE bool voxel_in_range(double3 voxel) {
  return voxel.x >= -KG_VOXEL_LIMIT && voxel.y >= -KG_VOXEL_LIMIT && voxel.z >= -KG_VOXEL_LIMIT &&
         voxel.x < KG_VOXEL_LIMIT && voxel.y < KG_VOXEL_LIMIT && voxel.z < KG_VOXEL_LIMIT;
}

KG_INLINE uint64_t voxel_biased_axis(double k) {
  return KG_UINT64(KG_INT64(k) + KG_INT64(1048576));
}

KG_INLINE uint64_t voxel_key(double3 voxel) {
  return 1UL + (voxel_biased_axis(voxel.x) | (voxel_biased_axis(voxel.y) << 21) |
                (voxel_biased_axis(voxel.z) << 42));
}

KG_INLINE double voxel_axis_of_key(uint64_t key, uint shift) {
  return KG_DOUBLE(KG_INT64(((key - 1UL) >> shift) & 0x1fffffUL) - KG_INT64(1048576));
}

KG_INLINE double3 voxel_of_key(uint64_t key) {
  return KG_DOUBLE3(voxel_axis_of_key(key, 0u), voxel_axis_of_key(key, 21u),
                    voxel_axis_of_key(key, 42u));
}

// The first slot to probe for key in a table of 2^capacity_log2 slots.
KG_INLINE uint voxel_slot(uint64_t key, uint capacity_log2) {
  return KG_UINT((key * 0x9e3779b97f4a7c15UL) >> (64u - capacity_log2));
}

// The slot probed after `slot`.
KG_INLINE uint voxel_next_slot(uint slot, uint capacity_log2) {
  return (slot + 1u) & ((1u << capacity_log2) - 1u);
}

// ---- Insert and find: GLSL shaders that use them declare the table as a buffer named `keys`
// (writable, with GL_EXT_shader_atomic_int64, to insert) and define KG_VOXEL_HASH_INSERT or
// KG_VOXEL_HASH_FIND before the include.
#if !defined(VULKAN) || defined(KG_VOXEL_HASH_INSERT)

// The slot of key (inserted where it was absent), or -1 when the table is full.
KG_FORCE_INLINE int voxel_insert_key(KG_BUFFER_PARAM(uint64_t, keys) uint64_t key,
                                     uint capacity_log2) {
  uint slot = voxel_slot(key, capacity_log2);
  const uint capacity = 1u << capacity_log2;
  for (uint probe = 0u; probe < capacity; ++probe) {
    const uint64_t found = kg_atomic_cas_u64(keys, slot, KG_EMPTY_VOXEL_KEY, key);
    if (found == KG_EMPTY_VOXEL_KEY || found == key) return KG_INT(slot);
    slot = voxel_next_slot(slot, capacity_log2);
  }
  return -1;
}

#endif

#if !defined(VULKAN) || defined(KG_VOXEL_HASH_FIND)

// The slot of key, or -1 when it is not in the table.
KG_FORCE_INLINE int voxel_find_key(KG_BUFFER_PARAM(const uint64_t, keys) uint64_t key,
                                   uint capacity_log2) {
  uint slot = voxel_slot(key, capacity_log2);
  const uint capacity = 1u << capacity_log2;
  for (uint probe = 0u; probe < capacity; ++probe) {
    const uint64_t found = keys[slot];
    if (found == key) return KG_INT(slot);
    if (found == KG_EMPTY_VOXEL_KEY) return -1;
    slot = voxel_next_slot(slot, capacity_log2);
  }
  return -1;
}

#endif

KG_RULES_END

#endif
