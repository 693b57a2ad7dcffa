// Whether point i is the lowest-index point of its voxel (voxel_downsample_count/assign.comp);
// the including shader declares point_slots[] and first[].
bool is_first_of_voxel(uint i) {
  const int slot = point_slots[i];
  return slot >= 0 && first[slot] == 0xffffffffu - i;
}
