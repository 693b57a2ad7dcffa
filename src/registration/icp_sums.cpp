#include "kartograf/registration/icp_sums.hpp"

#include <array>
#include <cmath>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "compute/cpu_parallel.hpp"
#include "registration/row_reduction.hpp"

namespace kartograf::registration {

namespace {

constexpr std::uint32_t kGroupSize = 64;  // KG_REDUCTION_GROUP in shaders/common.glsl
constexpr std::size_t kMaxSums = 32;      // KG_MAX_SUMS
constexpr std::size_t kPointToPointSums = 26;
constexpr std::size_t kPointToPlaneSums = 32;
constexpr std::size_t kFrameValues = 20;

constexpr compute::KernelSpec kPointToPointKernel{"icp_point_to_point", kGroupSize};
constexpr compute::KernelSpec kPointToPlaneKernel{"icp_point_to_plane", kGroupSize};

struct IcpSumsParams {  // layout of shaders/icp_*.comp and kernels/icp_sums.cl
  std::uint32_t pair_count;
  std::uint32_t target_count;
  std::uint32_t has_correspondences;
  std::uint32_t has_weights;
  std::uint32_t robust_kernel;
};

using Sums = std::array<double, kMaxSums>;

// R (row-major), t, pivot a, pivot b, max distance^2, robust scale: what the kernels read.
std::array<double, kFrameValues> frame_values(const Correspondences& pairs,
                                              const Eigen::Vector3d& pivot_a,
                                              const Eigen::Vector3d& pivot_b) {
  std::array<double, kFrameValues> frame{};
  const Eigen::Matrix3d rotation = pairs.source_to_target.linear();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) frame[3 * r + c] = rotation(r, c);
    frame[9 + r] = pairs.source_to_target.translation()(r);
    frame[12 + r] = pivot_a(r);
    frame[15 + r] = pivot_b(r);
  }
  frame[18] = pairs.max_distance * pairs.max_distance;
  frame[19] = pairs.robust.scale;
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

// The CPU path: the kernels' per-pair arithmetic in double, over source points [begin, end).
// Returns the number of considered source points (valid, not kNotSelected).
template <class AddPair>
std::uint64_t for_each_pair_cpu(const Correspondences& pairs,
                                const std::array<double, kFrameValues>& frame, std::size_t begin,
                                std::size_t end, AddPair&& add_pair) {
  const auto source = pairs.source->host_span();
  const auto target = pairs.target->host_span();
  const std::int32_t* correspondences =
      pairs.correspondences ? pairs.correspondences->host_span().data() : nullptr;
  const float* weights = pairs.weights ? pairs.weights->host_span().data() : nullptr;
  std::uint64_t considered = 0;
  for (std::size_t i = begin; i < end; ++i) {
    // The entry first: with 1-in-k selection most points are skipped without touching them.
    if (correspondences && correspondences[i] < kNoMatch) continue;
    const Point4f& p = source[i];
    if (!is_valid(p)) continue;
    ++considered;
    std::size_t j = i;
    if (correspondences) {
      if (correspondences[i] < 0 || static_cast<std::size_t>(correspondences[i]) >= target.size())
        continue;
      j = static_cast<std::size_t>(correspondences[i]);
    } else if (i >= target.size()) {
      continue;
    }
    double w = 1.0;
    if (weights) {
      w = weights[i];
      if (!(w > 0.0)) continue;
    }
    const Point4f& q = target[j];
    if (!is_valid(q)) continue;
    const double px = p.x(), py = p.y(), pz = p.z();
    const Eigen::Vector3d moved(frame[0] * px + frame[1] * py + frame[2] * pz + frame[9],
                                frame[3] * px + frame[4] * py + frame[5] * pz + frame[10],
                                frame[6] * px + frame[7] * py + frame[8] * pz + frame[11]);
    const Eigen::Vector3d qd = q.head<3>().cast<double>();
    const double distance_sq = (moved - qd).squaredNorm();
    if (!(distance_sq <= frame[18])) continue;
    add_pair(moved, qd, j, w, distance_sq);
  }
  return considered;
}

// Sums add_pair(sums, pair...) over all pairs: per-chunk rows (compute::detail::for_each_chunk, on up to
// two threads on this machine), added in chunk order as the device adds its work-group rows.
// The considered count goes to sums[considered_slot].
template <class AddPair>
Sums reduce_cpu(const Correspondences& pairs, const std::array<double, kFrameValues>& frame,
                std::size_t considered_slot, const AddPair& add_pair) {
  struct alignas(64) Row {
    Sums sums{};
  };
  std::array<Row, compute::detail::kCpuChunks> rows{};
  const std::size_t count = pairs.source->size();
  compute::detail::for_each_chunk(count, count, [&](std::size_t begin, std::size_t end, std::size_t chunk) {
    Sums& sums = rows[chunk].sums;
    sums[considered_slot] = static_cast<double>(for_each_pair_cpu(
        pairs, frame, begin, end, [&](auto&&... pair) { add_pair(sums, pair...); }));
  });
  Sums total{};
  for (const Row& row : rows) {
    for (std::size_t k = 0; k < kMaxSums; ++k) total[k] += row.sums[k];
  }
  return total;
}

}  // namespace

IcpReduction::IcpReduction(const compute::Context& context) : context_(&context) {
  if (context.is_cpu()) return;
  frame_ = compute::Buffer<double>(context, kFrameValues);
  result_ = compute::Buffer<double>(context, kMaxSums);
}

namespace {

// Runs the two device passes and returns the final row.
Sums reduce_on_device(const compute::Context& context, const compute::KernelSpec& kernel,
                      std::initializer_list<compute::BufferArg> inputs,
                      compute::Buffer<double>& frame, compute::Buffer<double>& partials,
                      compute::Buffer<double>& result, const IcpSumsParams& params,
                      std::size_t sum_count) {
  // Few work-groups on CPU-hosted drivers, where barriers are expensive; enough to fill a GPU
  // (on an H100, 2048 made the first pass of the odometry's ICP 18-22 % slower than 1024).
  const std::uint32_t max_groups = context.device_info().is_gpu() ? 1024 : 16;
  const std::uint32_t groups = std::max<std::uint32_t>(
      1, std::min(max_groups, compute::groups_for(params.pair_count, kGroupSize)));
  if (partials.size() < std::size_t{groups} * sum_count) {
    partials = compute::Buffer<double>(context, std::size_t{max_groups} * kMaxSums);
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

template <class T>
compute::BufferArg optional_buffer(const compute::Buffer<T>* buffer) {
  return buffer ? compute::BufferArg(*buffer) : compute::BufferArg();
}

IcpSumsParams kernel_params(const Correspondences& pairs) {
  return {static_cast<std::uint32_t>(pairs.source->size()),
          static_cast<std::uint32_t>(pairs.target->size()), pairs.correspondences ? 1u : 0u,
          pairs.weights ? 1u : 0u, static_cast<std::uint32_t>(pairs.robust.kernel)};
}

}  // namespace

PointToPointSums IcpReduction::point_to_point(const Correspondences& pairs,
                                              const Eigen::Vector3d& source_pivot,
                                              const Eigen::Vector3d& target_pivot) {
  validate(pairs, false, "point-to-point ICP sums");
  const auto frame = frame_values(pairs, source_pivot, target_pivot);
  Sums sums{};
  if (context_->is_cpu()) {
    const auto add_pair = [&](Sums& sums, const Eigen::Vector3d& moved, const Eigen::Vector3d& q,
                              std::size_t, double user_weight, double distance_sq) {
      const Eigen::Vector3d a = moved - source_pivot;
      const Eigen::Vector3d b = q - target_pivot;
      const double w = user_weight * robust_weight(pairs.robust, std::sqrt(distance_sq));
      sums[0] += 1.0;
      sums[1] += w;
      for (int r = 0; r < 3; ++r) {
        sums[2 + r] += w * a(r);
        sums[5 + r] += w * b(r);
        for (int c = 0; c < 3; ++c) sums[8 + 3 * r + c] += w * a(r) * b(c);
      }
      sums[17] += w * distance_sq;
      sums[18] += distance_sq;
      std::size_t slot = 20;
      for (int r = 0; r < 3; ++r) {
        for (int c = r; c < 3; ++c) sums[slot++] += w * a(r) * a(c);
      }
    };
    sums = reduce_cpu(pairs, frame, 19, add_pair);
  } else {
    frame_.upload(frame);
    sums = reduce_on_device(*context_, kPointToPointKernel,
                            {*pairs.source, *pairs.target, optional_buffer(pairs.correspondences),
                             optional_buffer(pairs.weights)},
                            frame_, partials_, result_, kernel_params(pairs), kPointToPointSums);
  }
  PointToPointSums result;
  result.pair_count = static_cast<std::uint64_t>(sums[0]);
  result.weight_sum = sums[1];
  result.squared_error_sum = sums[17];
  result.unweighted_squared_error_sum = sums[18];
  result.considered_count = static_cast<std::uint64_t>(sums[19]);
  if (result.weight_sum <= 0) return result;
  const Eigen::Vector3d sum_a(sums[2], sums[3], sums[4]);
  const Eigen::Vector3d sum_b(sums[5], sums[6], sums[7]);
  Eigen::Matrix3d sum_ab;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) sum_ab(r, c) = sums[8 + 3 * r + c];
  }
  result.source_mean = source_pivot + sum_a / result.weight_sum;
  result.target_mean = target_pivot + sum_b / result.weight_sum;
  result.cross_covariance = sum_ab - sum_a * sum_b.transpose() / result.weight_sum;
  Eigen::Matrix3d sum_aa;
  std::size_t slot = 20;
  for (int r = 0; r < 3; ++r) {
    for (int c = r; c < 3; ++c) sum_aa(r, c) = sum_aa(c, r) = sums[slot++];
  }
  result.source_scatter = sum_aa - sum_a * sum_a.transpose() / result.weight_sum;
  return result;
}

PointToPlaneSystem IcpReduction::point_to_plane(const Correspondences& pairs,
                                                const Eigen::Vector3d& pivot) {
  validate(pairs, true, "point-to-plane ICP sums");
  const auto frame = frame_values(pairs, pivot, Eigen::Vector3d::Zero());
  Sums sums{};
  if (context_->is_cpu()) {
    const auto normals = pairs.target_normals->host_span();
    const auto add_pair = [&](Sums& sums, const Eigen::Vector3d& moved, const Eigen::Vector3d& q,
                              std::size_t j, double user_weight, double) {
      if (!is_valid(normals[j])) return;
      // Plain scalars: this is the CPU backend's hottest loop.
      const double nx = normals[j].x(), ny = normals[j].y(), nz = normals[j].z();
      const double ax = moved.x() - pivot.x(), ay = moved.y() - pivot.y(),
                   az = moved.z() - pivot.z();
      const double jacobian[6] = {
          ay * nz - az * ny, az * nx - ax * nz, ax * ny - ay * nx, nx, ny, nz};
      const double r =
          (moved.x() - q.x()) * nx + (moved.y() - q.y()) * ny + (moved.z() - q.z()) * nz;
      const double w = user_weight * robust_weight(pairs.robust, r);
      sums[0] += 1.0;
      sums[1] += w;
      std::size_t slot = 2;
      for (int row = 0; row < 6; ++row) {
        const double weighted = w * jacobian[row];
        for (int col = row; col < 6; ++col) sums[slot++] += weighted * jacobian[col];
        sums[23 + row] += weighted * r;
      }
      sums[29] += w * r * r;
      sums[30] += r * r;
    };
    sums = reduce_cpu(pairs, frame, 31, add_pair);
  } else {
    frame_.upload(frame);
    sums =
        reduce_on_device(*context_, kPointToPlaneKernel,
                         {*pairs.source, *pairs.target, *pairs.target_normals,
                          optional_buffer(pairs.correspondences), optional_buffer(pairs.weights)},
                         frame_, partials_, result_, kernel_params(pairs), kPointToPlaneSums);
  }
  PointToPlaneSystem system;
  system.pair_count = static_cast<std::uint64_t>(sums[0]);
  system.weight_sum = sums[1];
  system.pivot = pivot;
  std::size_t slot = 2;
  for (int row = 0; row < 6; ++row) {
    for (int col = row; col < 6; ++col) {
      system.jtj(row, col) = system.jtj(col, row) = sums[slot++];
    }
  }
  for (int row = 0; row < 6; ++row) system.jtr(row) = sums[23 + row];
  system.squared_error_sum = sums[29];
  system.unweighted_squared_error_sum = sums[30];
  system.considered_count = static_cast<std::uint64_t>(sums[31]);
  return system;
}

}  // namespace kartograf::registration
