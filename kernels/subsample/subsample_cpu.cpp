// CPU wrapper of kernels/subsample/subsample.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/subsample/subsample.h"

namespace kartograf::kernels {

namespace {

// out[m] = in[subsample_source_index(m)] for m in [0, out_count), over the CPU backend's threads.
template <class T>
void copy_selected(const T* in, T* out, SubsampleParams params) {
  compute::detail::for_each_chunk(params.out_count, params.out_count,
                                  [&](std::size_t first, std::size_t last, std::size_t) {
                                    for (std::size_t m = first; m < last; ++m) {
                                      out[m] = in[subsample_source_index(uint(m), params)];
                                    }
                                  });
}

void subsample(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<SubsampleParams>();
  copy_selected(call.buffer<const float4>(0), call.buffer<float4>(3), params);
  if (params.has_normals != 0) {
    copy_selected(call.buffer<const float4>(1), call.buffer<float4>(4), params);
  }
  if (params.has_colors != 0)
    copy_selected(call.buffer<const uint>(2), call.buffer<uint>(5), params);
}

}  // namespace

void register_subsample_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("subsample", subsample);
}

}  // namespace kartograf::kernels
