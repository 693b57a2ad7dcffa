#include "kartograf/registration/color_gate.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "kernels/color_gate/color_gate.h"
#include "registration/row_reduction.hpp"

namespace kartograf::registration {

namespace {

constexpr std::size_t kSumCount = KG_COLOR_GATE_SUMS;  // pairs, sum dS, hue pairs, sum dH
constexpr compute::KernelSpec kDifferencesKernel{"color_gate_differences",
                                                 KG_COLOR_GATE_DIFFERENCES_LOCAL_X};
constexpr compute::KernelSpec kApplyKernel{"color_gate_apply", KG_COLOR_GATE_APPLY_LOCAL_X};
static_assert(KG_COLOR_GATE_NO_HUE == kNoHue && KG_COLOR_GATE_HUE_CODES == kHueCodes,
              "the kernels' HSI codes are hsi.hpp's");

using Sums = std::array<double, kSumCount>;

ColorGateStatistics statistics_of(const Sums& sums, std::uint64_t rejected_count) {
  ColorGateStatistics s;
  s.pair_count = static_cast<std::uint64_t>(sums[0]);
  s.hue_pair_count = static_cast<std::uint64_t>(sums[2]);
  if (sums[0] > 0) s.mean_saturation_difference = sums[1] / sums[0] / kSaturationMax;
  if (sums[2] > 0) s.mean_hue_difference_deg = sums[3] / sums[2] * 360.0 / kHueCodes;
  s.rejected_count = rejected_count;
  return s;
}

}  // namespace

ColorGate::ColorGate(const compute::Context& context, ColorGateParams params)
    : context_(&context), params_(params) {
  require(std::isfinite(params_.mean_factor) && params_.mean_factor > 0,
          "colour gate: mean_factor must be finite and > 0, got " +
              std::to_string(params_.mean_factor));
  sums_ = compute::Buffer<double>(context, kSumCount);
  rejected_ = compute::Buffer<std::uint32_t>(context, 1);
  sums_.fill_zero();  // statistics() before the first apply() reads zeros
  rejected_.fill_zero();
}

void ColorGate::apply(const compute::Buffer<std::uint32_t>& source_colors,
                      const compute::Buffer<std::uint32_t>& target_colors,
                      compute::Buffer<std::int32_t>& target_index) {
  require(source_colors.size() == target_index.size(),
          "colour gate: " + std::to_string(source_colors.size()) + " source colours for " +
              std::to_string(target_index.size()) + " source points");
  require(
      target_index.size() < (std::size_t{1} << 31) && target_colors.size() < (std::size_t{1} << 31),
      "colour gate: more than 2^31 points");
  const auto count = static_cast<std::uint32_t>(target_index.size());
  const kernels::ColorGateApplyParams apply_params{count, params_.use_hue ? 1u : 0u,
                                                   params_.use_saturation ? 1u : 0u,
                                                   static_cast<float>(params_.mean_factor)};

  rejected_.fill_zero();
  if (count == 0) {
    sums_.fill_zero();
    return;
  }
  if (table_.empty()) table_ = compute::Buffer<HsiCode>::from_host(*context_, hsi_table());
  if (differences_.size() < count) differences_ = compute::Buffer<std::uint32_t>(*context_, count);
  // Few work-groups on CPU-hosted drivers, where barriers are expensive; enough to fill a GPU.
  const std::uint32_t max_groups = context_->device_info().is_gpu() ? 1024 : 16;
  const std::uint32_t groups = std::max<std::uint32_t>(
      1, std::min(max_groups, compute::groups_for(count, kReductionGroupSize)));
  if (partials_.size() < std::size_t{groups} * kSumCount) {
    partials_ = compute::Buffer<double>(*context_, std::size_t{max_groups} * kSumCount);
  }
  compute::dispatch(
      *context_, kDifferencesKernel,
      {source_colors, target_colors, target_index, table_, differences_, partials_},
      kernels::ColorGateDifferencesParams{count, static_cast<std::uint32_t>(target_colors.size())},
      {groups, 1});
  reduce_rows(*context_, partials_, sums_, groups, static_cast<std::uint32_t>(kSumCount));
  compute::dispatch(*context_, kApplyKernel, {differences_, sums_, target_index, rejected_},
                    apply_params, {compute::groups_for(count, kApplyKernel.local_x), 1});
}

ColorGateStatistics ColorGate::statistics() const {
  Sums sums{};
  sums_.download(sums);
  std::uint32_t rejected_count = 0;
  rejected_.download(std::span(&rejected_count, 1));
  return statistics_of(sums, rejected_count);
}

ColorGatedFinder::ColorGatedFinder(const compute::Context& context,
                                   std::unique_ptr<CorrespondenceFinder> inner,
                                   ColorGateParams params)
    : inner_(std::move(inner)), gate_(context, params) {
  require(inner_ != nullptr, "colour-gated finder: the inner finder is missing");
}

void ColorGatedFinder::prepare(const CloudView& target, int level) {
  inner_->prepare(target, level);
}

void ColorGatedFinder::find(const CloudView& source, const CloudView& target,
                            const Eigen::Isometry3d& source_to_target,
                            const AssociationParams& params, CorrespondenceBuffers& out) {
  require(source.colors && target.colors, "colour-gated finder: both clouds need colours");
  require(target.colors->size() == target.size(),
          "colour-gated finder: target colours and points differ in count");
  inner_->find(source, target, source_to_target, params, out);
  gate_.apply(*source.colors, *target.colors, out.target_index);
}

}  // namespace kartograf::registration
