#include "kartograf/registration/icp_sums.hpp"

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "kartograf/compute/kernel.hpp"
#include "kernels/icp_sums/icp_sums.h"
#include "registration/row_reduction.hpp"

namespace kartograf::registration {

namespace {

constexpr compute::KernelSpec kPointToPointKernel{"icp_point_to_point", KG_ICP_SUMS_LOCAL_X};
constexpr compute::KernelSpec kPointToPlaneKernel{"icp_point_to_plane", KG_ICP_SUMS_LOCAL_X};
static_assert(KG_ICP_SUMS_LOCAL_X == kReductionGroupSize, "the sums are reduce_rows' first pass");
static_assert(kNoMatch == KG_ICP_NO_MATCH, "the kernels' selection test is kNoMatch's");

using Sums = std::array<double, KG_MAX_SUMS>;
using Frame = std::array<double, KG_ICP_FRAME_VALUES>;

// What the kernels read: R, t, the pivots, max distance^2, the robust kernel's scale.
Frame frame_values(const Correspondences& pairs, const Eigen::Vector3d& source_pivot,
                   const Eigen::Vector3d& target_pivot) {
  Frame frame{};
  const Eigen::Matrix3d rotation = pairs.source_to_target.linear();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) frame[KG_ICP_FRAME_ROTATION + 3 * r + c] = rotation(r, c);
    frame[KG_ICP_FRAME_TRANSLATION + r] = pairs.source_to_target.translation()(r);
    frame[KG_ICP_FRAME_SOURCE_PIVOT + r] = source_pivot(r);
    frame[KG_ICP_FRAME_TARGET_PIVOT + r] = target_pivot(r);
  }
  frame[KG_ICP_FRAME_MAX_DISTANCE_SQ] = pairs.max_distance * pairs.max_distance;
  frame[KG_ICP_FRAME_ROBUST_SCALE] = pairs.robust.scale;
  return frame;
}

void validate(const Correspondences& pairs, bool needs_normals, const char* what) {
  const std::string name(what);
  require(pairs.source && pairs.target, name + ": source and target buffers are required");
  require(!needs_normals || pairs.target_normals, name + ": target normals are required");
  require(!needs_normals || pairs.target_normals->size() == pairs.target->size(),
          name + ": target normals and target points differ in count");
  require(!pairs.correspondences || pairs.correspondences->size() == pairs.source->size(),
          name + ": correspondence buffer and source points differ in count");
  require(!pairs.weights || pairs.weights->size() == pairs.source->size(),
          name + ": weight buffer and source points differ in count");
  require(!(pairs.max_distance < 0) && !std::isnan(pairs.max_distance),
          name + ": max_distance must be >= 0");
  require(pairs.source_to_target.matrix().allFinite(),
          name + ": the transform has NaN/Inf entries");
  require(pairs.robust.kernel == RobustKernel::none ||
              (std::isfinite(pairs.robust.scale) && pairs.robust.scale > 0),
          name + ": the robust kernel's scale must be finite and > 0");
  require(pairs.source->size() < (std::size_t{1} << 31) &&
              pairs.target->size() < (std::size_t{1} << 31),
          name + ": more than 2^31 points");
}

}  // namespace

IcpReduction::IcpReduction(const compute::Context& context)
    : context_(&context), frame_(context, KG_ICP_FRAME_VALUES), result_(context, KG_MAX_SUMS) {}

namespace {

template <class T>
compute::BufferArg optional_buffer(const compute::Buffer<T>* buffer) {
  return buffer ? compute::BufferArg(*buffer) : compute::BufferArg();
}

kernels::IcpSumsParams kernel_params(const Correspondences& pairs) {
  return {static_cast<std::uint32_t>(pairs.source->size()),
          static_cast<std::uint32_t>(pairs.target->size()), pairs.correspondences ? 1u : 0u,
          pairs.weights ? 1u : 0u, static_cast<std::uint32_t>(pairs.robust.kernel)};
}

// The two passes: one row of sums per work-group (on the CPU, the chunks' rows in chunk order),
// then reduce_rows. Returns the final row.
Sums reduce(const compute::Context& context, const compute::KernelSpec& kernel,
            std::initializer_list<compute::BufferArg> inputs, const kernels::IcpSumsParams& params,
            compute::Buffer<double>& frame, compute::Buffer<double>& partials,
            compute::Buffer<double>& result, std::size_t sum_count) {
  // Few work-groups on CPU-hosted drivers, where barriers are expensive; enough to fill a GPU
  // (on an H100, 2048 made the first pass of the odometry's ICP 18-22 % slower than 1024).
  const std::uint32_t max_groups = context.device_info().is_gpu() ? 1024 : 16;
  const std::uint32_t groups = std::max<std::uint32_t>(
      1, std::min(max_groups, compute::groups_for(params.pair_count, kernel.local_x)));
  if (partials.size() < std::size_t{groups} * sum_count) {
    partials = compute::Buffer<double>(context, std::size_t{max_groups} * KG_MAX_SUMS);
  }
  std::vector<compute::BufferArg> args(inputs);
  args.push_back(frame);
  args.push_back(partials);
  compute::dispatch_raw(context, kernel, args, std::as_bytes(std::span(&params, 1)), {groups, 1});
  reduce_rows(context, partials, result, groups, static_cast<std::uint32_t>(sum_count));
  Sums sums{};
  result.download(std::span(sums.data(), sum_count));
  return sums;
}

}  // namespace

PointToPointSums IcpReduction::point_to_point(const Correspondences& pairs,
                                              const Eigen::Vector3d& source_pivot,
                                              const Eigen::Vector3d& target_pivot) {
  validate(pairs, false, "point-to-point ICP sums");
  frame_.upload(frame_values(pairs, source_pivot, target_pivot));
  const Sums sums = reduce(*context_, kPointToPointKernel,
                           {*pairs.source, *pairs.target, optional_buffer(pairs.correspondences),
                            optional_buffer(pairs.weights)},
                           kernel_params(pairs), frame_, partials_, result_, KG_ICP_POINT_SUMS);
  PointToPointSums result;
  result.pair_count = static_cast<std::uint64_t>(sums[KG_ICP_POINT_PAIRS]);
  result.weight_sum = sums[KG_ICP_POINT_WEIGHT_SUM];
  result.squared_error_sum = sums[KG_ICP_POINT_SQUARED_ERROR];
  result.unweighted_squared_error_sum = sums[KG_ICP_POINT_UNWEIGHTED_SQUARED_ERROR];
  result.considered_count = static_cast<std::uint64_t>(sums[KG_ICP_POINT_CONSIDERED]);
  if (result.weight_sum <= 0) return result;
  const Eigen::Vector3d sum_a(sums.data() + KG_ICP_POINT_SUM_A);
  const Eigen::Vector3d sum_b(sums.data() + KG_ICP_POINT_SUM_B);
  Eigen::Matrix3d sum_ab;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) sum_ab(r, c) = sums[KG_ICP_POINT_SUM_AB + 3 * r + c];
  }
  result.source_mean = source_pivot + sum_a / result.weight_sum;
  result.target_mean = target_pivot + sum_b / result.weight_sum;
  result.cross_covariance = sum_ab - sum_a * sum_b.transpose() / result.weight_sum;
  Eigen::Matrix3d sum_aa;
  std::size_t slot = KG_ICP_POINT_SUM_AA;
  for (int r = 0; r < 3; ++r) {
    for (int c = r; c < 3; ++c) sum_aa(r, c) = sum_aa(c, r) = sums[slot++];
  }
  result.source_scatter = sum_aa - sum_a * sum_a.transpose() / result.weight_sum;
  return result;
}

PointToPlaneSystem IcpReduction::point_to_plane(const Correspondences& pairs,
                                                const Eigen::Vector3d& pivot) {
  validate(pairs, true, "point-to-plane ICP sums");
  frame_.upload(frame_values(pairs, pivot, Eigen::Vector3d::Zero()));
  const Sums sums = reduce(*context_, kPointToPlaneKernel,
                           {*pairs.source, *pairs.target, *pairs.target_normals,
                            optional_buffer(pairs.correspondences), optional_buffer(pairs.weights)},
                           kernel_params(pairs), frame_, partials_, result_, KG_ICP_PLANE_SUMS);
  PointToPlaneSystem system;
  system.pair_count = static_cast<std::uint64_t>(sums[KG_ICP_PLANE_PAIRS]);
  system.weight_sum = sums[KG_ICP_PLANE_WEIGHT_SUM];
  system.pivot = pivot;
  std::size_t slot = KG_ICP_PLANE_JTJ;
  for (int row = 0; row < 6; ++row) {
    for (int col = row; col < 6; ++col) {
      system.jtj(row, col) = system.jtj(col, row) = sums[slot++];
    }
  }
  for (int row = 0; row < 6; ++row) system.jtr(row) = sums[KG_ICP_PLANE_JTR + row];
  system.squared_error_sum = sums[KG_ICP_PLANE_SQUARED_ERROR];
  system.unweighted_squared_error_sum = sums[KG_ICP_PLANE_UNWEIGHTED_SQUARED_ERROR];
  system.considered_count = static_cast<std::uint64_t>(sums[KG_ICP_PLANE_CONSIDERED]);
  return system;
}

}  // namespace kartograf::registration
