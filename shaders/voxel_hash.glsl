// Voxel keys and the open-addressing hash of voxel_downsample_*.comp and voxel_hash_nearest.comp;
// the same arithmetic as src/geometry/voxel_key.hpp and kernels/voxel_common.cl.
// A voxel (kx, ky, kz) = floor(p * inverse_size), each in [-2^20, 2^20), is stored as the 64-bit
// key 1 + (kx + 2^20) | (ky + 2^20) << 21 | (kz + 2^20) << 42, so 0 marks an empty slot.
#define KG_VOXEL_LIMIT 1048576.0

bool voxel_of(dvec3 scaled, out dvec3 voxel) {
  voxel = floor(scaled);
  return all(greaterThanEqual(voxel, dvec3(-KG_VOXEL_LIMIT))) &&
         all(lessThan(voxel, dvec3(KG_VOXEL_LIMIT)));
}

uint64_t voxel_key(dvec3 voxel) {
  const u64vec3 biased = u64vec3(i64vec3(voxel) + int64_t(1048576));
  return 1ul + (biased.x | (biased.y << 21) | (biased.z << 42));
}

dvec3 voxel_of_key(uint64_t key) {
  const uint64_t biased = key - 1ul;
  return dvec3(i64vec3(u64vec3(biased, biased >> 21, biased >> 42) & 0x1ffffful) - int64_t(1048576));
}

// The first slot to probe (Fibonacci hashing); probing then walks slot + 1, + 2, ... mod capacity.
uint voxel_slot(uint64_t key, uint capacity_log2) {
  return uint((key * 0x9e3779b97f4a7c15ul) >> (64u - capacity_log2));
}
