// CPU wrapper of kernels/segment_moments/segment_moments.h.
#include "kernels/segment_moments/segment_moments_cpu.hpp"

#include "compute/cpu/cpu_kernel.hpp"

namespace kartograf::kernels {

void accumulate_segment_moments(const float4* points, const uint* labels,
                                const SegmentMomentsParams& params, std::int64_t* moments,
                                uint* status) {
  for (uint i = 0; i < params.point_count; ++i) {
    const uint label = labels[i];
    const float4 p = points[i];
    const uint outcome = segment_moment_outcome(label, p, params);
    if (outcome == KG_SEGMENT_MOMENT_BAD_LABEL) ++status[KG_SEGMENT_MOMENTS_BAD_LABEL];
    if (outcome == KG_SEGMENT_MOMENT_TOO_FAR) ++status[KG_SEGMENT_MOMENTS_TOO_FAR];
    if (outcome != KG_SEGMENT_MOMENT_ADD) continue;
    const SegmentMomentOffset d = segment_moment_offset(p, params);
    std::int64_t* sums = moments + std::size_t{label} * KG_SEGMENT_MOMENT_VALUES;
    for (uint slot = 0; slot < KG_SEGMENT_MOMENT_VALUES; ++slot) {
      sums[slot] += segment_moment_term(d, slot, params);
    }
  }
}

namespace {

// One pass over the points in order: integer sums, so the same as the devices' atomics.
void segment_moments(const compute::detail::CpuDispatch& call) {
  accumulate_segment_moments(call.buffer<const float4>(0), call.buffer<const uint>(1),
                             call.params_as<SegmentMomentsParams>(), call.buffer<std::int64_t>(2),
                             call.buffer<uint>(3));
}

}  // namespace

void register_segment_moments_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("segment_moments", segment_moments);
}

}  // namespace kartograf::kernels
