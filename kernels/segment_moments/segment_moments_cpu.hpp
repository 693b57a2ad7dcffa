#pragma once
// The CPU side of kernels/segment_moments/segment_moments.h, callable on host arrays: the CPU
// backend's "segment_moments" kernel and the host reference geometry::segment_moments both run it.
#include <cstdint>

#include "kernels/segment_moments/segment_moments.h"

namespace kartograf::kernels {

// Adds every point's terms to moments (params.label_count x KG_SEGMENT_MOMENT_VALUES) and counts
// the rejected points in status[KG_SEGMENT_MOMENTS_*], in point order.
void accumulate_segment_moments(const float4* points, const uint* labels,
                                const SegmentMomentsParams& params, std::int64_t* moments,
                                uint* status);

}  // namespace kartograf::kernels
