// CPU wrapper of kernels/cell_scores/cell_scores.h: the jobs in chunks over the threads. The
// cells mode on the CPU backend scores on the host, four pixels at a time (cell_planes.cpp); this
// wrapper is the rule as written, which the tests hold both to.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/cell_scores/cell_scores.h"

namespace kartograf::kernels {

namespace {

void cell_scores(const compute::detail::CpuDispatch& call) {
  const auto p = call.params_as<CellScoresParams>();
  const auto* points = call.buffer<const float4>(0);
  const auto* jobs = call.buffer<const uint>(1);
  const auto* candidates = call.buffer<const uint>(2);
  const auto* planes = call.buffer<const float4>(3);
  auto* choices = call.buffer<uint>(4);
  auto* distances = call.buffer<float>(5);
  compute::detail::for_each_chunk(p.job_count, std::size_t{p.job_count} * 256,
                                  [&](std::size_t begin, std::size_t end, std::size_t) {
                                    for (std::size_t j = begin; j < end; ++j) {
                                      cell_score_job(points, jobs, candidates, planes, choices,
                                                     distances, static_cast<uint>(j), p);
                                    }
                                  });
}

}  // namespace

void register_cell_scores_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("cell_scores", cell_scores);
}

}  // namespace kartograf::kernels
