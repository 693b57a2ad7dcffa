#pragma once
// The CPU side of kernels/region_grow/region_grow.h, callable on host arrays: the CPU backend's
// region_grow_* kernels and the host reference segmentation::grow_regions both run these passes.
// Unlike the devices' (tiles of at most 64 x 64 pixels), the CPU's tiles may be of any size.
#include <cstdint>

#include "kernels/region_grow/region_grow.h"

namespace kartograf::kernels {

struct LabCode4 {  // segmentation::LabCode: L, a, b in 1/64 units, valid
  std::int16_t l, a, b, valid;
};

// What pass 1 reads and writes.
struct RegionGrowArrays {
  const LabCode4* lab;
  const float4* points;
  uint* labels;
  uint* tile_counts;  // padded_tile_count entries, zero beyond tile_count
  double* slots;      // measuring: KG_REGION_GROW_STATISTICS per slot, else unused
};

// Pass 1: the tiles in parallel chunks (labels do not depend on the thread count).
void region_grow_tiles_cpu(const RegionGrowParams& params, const RegionGrowArrays& arrays);
// Pass 2: exclusive prefix sums of the tile counts in place; returns the segment count.
uint region_grow_scan_cpu(const RegionGrowParams& params, uint* tile_counts);
// Pass 3: tile-local labels to labels in the image.
void region_grow_offsets_cpu(const RegionGrowParams& params, uint* labels,
                             const uint* tile_offsets);
// Pass 4: the statistics of the `total` segments from their slots to label order.
void region_grow_statistics_cpu(const RegionGrowParams& params, const uint* tile_offsets,
                                uint total, const double* slots, double* statistics);

}  // namespace kartograf::kernels
