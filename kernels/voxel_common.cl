// Voxel keys and the open-addressing hash of voxel_downsample.cl and voxel_hash_nearest.cl; see
// shaders/voxel_hash.glsl (same arithmetic) for the key layout.
#define KG_VOXEL_LIMIT 1048576.0

inline bool kg_voxel_of(double3 scaled, double3* voxel) {
  *voxel = floor(scaled);
  return voxel->x >= -KG_VOXEL_LIMIT && voxel->y >= -KG_VOXEL_LIMIT && voxel->z >= -KG_VOXEL_LIMIT &&
         voxel->x < KG_VOXEL_LIMIT && voxel->y < KG_VOXEL_LIMIT && voxel->z < KG_VOXEL_LIMIT;
}

inline ulong kg_voxel_key(double3 voxel) {
  const ulong x = (ulong)((long)voxel.x + 1048576L);
  const ulong y = (ulong)((long)voxel.y + 1048576L);
  const ulong z = (ulong)((long)voxel.z + 1048576L);
  return 1UL + (x | (y << 21) | (z << 42));
}

inline double3 kg_voxel_of_key(ulong key) {
  const ulong biased = key - 1UL;
  return (double3)((double)((long)(biased & 0x1fffffUL) - 1048576L),
                   (double)((long)((biased >> 21) & 0x1fffffUL) - 1048576L),
                   (double)((long)((biased >> 42) & 0x1fffffUL) - 1048576L));
}

inline uint kg_voxel_slot(ulong key, uint capacity_log2) {
  return (uint)((key * 0x9e3779b97f4a7c15UL) >> (64u - capacity_log2));
}
