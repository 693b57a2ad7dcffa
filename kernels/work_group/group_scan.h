// One work-group's exclusive prefix sums of a buffer of counts, in place, device code (the CPU
// wrappers scan in one loop): each of the KG_GROUP_SCAN_LANES lanes scans a contiguous part, lane 0
// scans the lanes' part sums in shared memory. GLSL: the shader declares the buffer as
// `scan_values` (uint[]) before including this file; OpenCL: the kernel declares
// `__local uint part_offsets[KG_GROUP_SCAN_LANES]`.
#ifndef KARTOGRAF_KERNELS_WORK_GROUP_GROUP_SCAN_H
#define KARTOGRAF_KERNELS_WORK_GROUP_GROUP_SCAN_H
#include "shaders/prelude.h"
#if defined(__cplusplus)
#error "work-group procedures are device code (GLSL, OpenCL C)"
#endif

#define KG_GROUP_SCAN_LANES 64

KG_SHARED_STORAGE(uint, part_offsets, KG_GROUP_SCAN_LANES)

// scan_values[0..count) (count a multiple of KG_GROUP_SCAN_LANES) become their exclusive prefix
// sums; returns their total in lane 0 (0 in the others).
KG_INLINE uint kg_group_exclusive_scan(KG_BUFFER_PARAM(uint, scan_values)
                                           KG_SHARED(uint, part_offsets) uint count) {
  const uint lane = KG_LANE;
  const uint part = count / KG_GROUP_SCAN_LANES;
  const uint base = lane * part;
  uint sum = 0u;
  for (uint j = 0u; j < part; ++j) sum += scan_values[base + j];
  part_offsets[lane] = sum;
  KG_GROUP_BARRIER();
  uint total = 0u;
  if (lane == 0u) {
    for (uint l = 0u; l < KG_GROUP_SCAN_LANES; ++l) {
      const uint value = part_offsets[l];
      part_offsets[l] = total;
      total += value;
    }
  }
  KG_GROUP_BARRIER();
  uint offset = part_offsets[lane];
  for (uint j = 0u; j < part; ++j) {
    const uint value = scan_values[base + j];
    scan_values[base + j] = offset;
    offset += value;
  }
  return total;
}

#endif
