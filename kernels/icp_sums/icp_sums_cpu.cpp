// CPU wrapper of kernels/icp_sums/icp_sums.h: each chunk of source points (in the chunks of
// compute::detail::for_each_chunk) sums its pairs into one row, and the chunk rows become the
// dispatch's partial rows in chunk order (store_chunk_rows), which reduce_rows adds in order.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>

#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/icp_sums/icp_sums.h"
#include "kernels/reduce_rows/chunk_rows_cpu.hpp"

namespace kartograf::kernels {

namespace {

struct IcpInputs {
  const float4* source;
  const float4* target;
  const int* correspondences;  // null without the buffer
  const float* weights;        // null without the buffer
  IcpSumsParams params;
  IcpFrame frame;
};

// Source point i's pair, when it has one that counts; `considered` counts i when it is valid and
// selected. The correspondence entry first: with 1-in-k selection most points are skipped
// without touching them.
inline bool load_pair(const IcpInputs& in, uint i, std::uint64_t& considered, IcpPair& pair) {
  const int entry = in.params.has_correspondences != 0u ? in.correspondences[i] : int(i);
  if (!icp_is_selected(entry)) return false;
  const float4 p = in.source[i];
  if (kg_isnan(p.x)) return false;
  ++considered;
  const int j = icp_target_of(entry, in.params);
  if (j < 0) return false;
  const double weight = in.params.has_weights != 0u ? double(in.weights[i]) : 1.0;
  if (!(weight > 0.0)) return false;
  const float4 q = in.target[j];
  if (kg_isnan(q.x)) return false;
  pair = icp_pair(p, q, uint(j), weight, in.frame);
  return icp_pair_in_range(pair, in.frame);
}

// Bindings: source, target, [extra...], correspondences, weights, frame, partials.
IcpInputs inputs_of(const compute::detail::CpuDispatch& call, std::size_t first_optional) {
  const auto params = call.params_as<IcpSumsParams>();
  return {call.buffer<const float4>(0),
          call.buffer<const float4>(1),
          call.buffer<const int>(first_optional),
          call.buffer<const float>(first_optional + 1),
          params,
          KG_ICP_READ_FRAME(call.buffer<const double>(first_optional + 2))};
}

template <class AddPair>
void sum_pairs(const compute::detail::CpuDispatch& call, const IcpInputs& in,
               std::size_t considered_slot, std::size_t sum_count, double* partials,
               const AddPair& add_pair) {
  struct alignas(64) ChunkRow {
    double sums[KG_MAX_SUMS] = {};
  };
  std::array<ChunkRow, compute::detail::kCpuChunks> rows{};
  const std::size_t count = in.params.pair_count;
  const auto sum_chunk = [&](std::size_t begin, std::size_t end, std::size_t chunk) {
    const IcpInputs chunk_in = in;  // a copy the row's stores cannot alias
    double sums[KG_MAX_SUMS] = {};  // local, so that the sums can stay in registers
    std::uint64_t considered = 0;   // an integer: no floating-point dependency chain
    for (std::size_t i = begin; i < end; ++i) {
      IcpPair pair;
      if (load_pair(chunk_in, uint(i), considered, pair)) add_pair(sums, pair, chunk_in);
    }
    sums[considered_slot] = static_cast<double>(considered);
    std::copy(sums, sums + KG_MAX_SUMS, rows[chunk].sums);
  };
  compute::detail::for_each_chunk(count, count, sum_chunk);
  store_chunk_rows(std::span<const ChunkRow>(rows), sum_count, call.groups.x, partials);
}

void icp_point_to_point(const compute::detail::CpuDispatch& call) {
  const IcpInputs in = inputs_of(call, 2);
  sum_pairs(call, in, KG_ICP_POINT_CONSIDERED, KG_ICP_POINT_SUMS, call.buffer<double>(5),
            [](double* sums, const IcpPair& pair, const IcpInputs& chunk_in) {
              icp_add_point_to_point(KG_ACCUMULATOR_ARG(sums) pair, chunk_in.frame,
                                     chunk_in.params.robust_kernel);
            });
}

void icp_point_to_plane(const compute::detail::CpuDispatch& call) {
  const IcpInputs in = inputs_of(call, 3);
  const auto* normals = call.buffer<const float4>(2);
  sum_pairs(call, in, KG_ICP_PLANE_CONSIDERED, KG_ICP_PLANE_SUMS, call.buffer<double>(6),
            [normals](double* sums, const IcpPair& pair, const IcpInputs& chunk_in) {
              const float4 normal = normals[pair.target_index];
              if (kg_isnan(normal.x)) return;
              icp_add_point_to_plane(KG_ACCUMULATOR_ARG(sums) pair, normal, chunk_in.frame,
                                     chunk_in.params.robust_kernel);
            });
}

}  // namespace

void register_icp_sums_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("icp_point_to_point", icp_point_to_point);
  registry.add("icp_point_to_plane", icp_point_to_plane);
}

}  // namespace kartograf::kernels
