// CPU wrapper of kernels/color_gate/color_gate.h: the same passes as the devices. The sums are of
// integers (exact in double), so how the entries split into partial-sum rows changes nothing.
#include <atomic>

#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/color_gate/color_gate.h"

namespace kartograf::kernels {

namespace {

// Row r of the partial sums covers the entries [r * count / rows, (r + 1) * count / rows).
void color_gate_differences(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<ColorGateDifferencesParams>();
  const auto* source_colors = call.buffer<const uint>(0);
  const auto* target_colors = call.buffer<const uint>(1);
  const auto* correspondences = call.buffer<const int>(2);
  const auto* table = call.buffer<const std::uint16_t>(3);
  auto* differences = call.buffer<uint>(4);
  auto* partials = call.buffer<double>(5);
  const std::size_t rows = call.groups.x;
  const std::size_t count = params.pair_count;
  compute::detail::for_each_chunk(
      rows, count, [&](std::size_t first, std::size_t last, std::size_t) {
        for (std::size_t row = first; row < last; ++row) {
          double sums[KG_COLOR_GATE_SUMS] = {0.0, 0.0, 0.0, 0.0};
          for (std::size_t i = row * count / rows; i < (row + 1) * count / rows; ++i) {
            const uint d = color_gate_entry_differences(
                source_colors, target_colors, correspondences, table, static_cast<uint>(i), params);
            differences[i] = d;
            for (uint k = 0; k < KG_COLOR_GATE_SUMS; ++k) sums[k] += color_gate_sum_term(d, k);
          }
          for (uint k = 0; k < KG_COLOR_GATE_SUMS; ++k)
            partials[row * KG_COLOR_GATE_SUMS + k] = sums[k];
        }
      });
}

void color_gate_apply(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<ColorGateApplyParams>();
  const auto* differences = call.buffer<const uint>(0);
  const auto* sums = call.buffer<const double>(1);
  auto* correspondences = call.buffer<int>(2);
  std::atomic_ref<uint> rejected(*call.buffer<uint>(3));
  compute::detail::for_each_chunk(
      params.pair_count, params.pair_count, [&](std::size_t first, std::size_t last, std::size_t) {
        uint count = 0;
        for (std::size_t i = first; i < last; ++i) {
          if (!color_gate_rejects(differences[i], sums[0], sums[1], sums[2], sums[3], params)) {
            continue;
          }
          correspondences[i] = -1;
          ++count;
        }
        rejected.fetch_add(count);
      });
}

}  // namespace

void register_color_gate_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("color_gate_differences", color_gate_differences);
  registry.add("color_gate_apply", color_gate_apply);
}

}  // namespace kartograf::kernels
