#include "kartograf/geometry/voxel_downsample.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "geometry/voxel_key.hpp"
#include "kartograf/compute/kernel.hpp"
#include "kernels/voxel_downsample/voxel_downsample.h"

namespace kartograf::geometry {

namespace {

constexpr std::uint32_t kGroupSize = KG_VOXEL_DOWNSAMPLE_LOCAL_X;
constexpr compute::KernelSpec kInsertKernel{"voxel_downsample_insert", kGroupSize};
constexpr compute::KernelSpec kCountKernel{"voxel_downsample_count", kGroupSize};
constexpr compute::KernelSpec kScanKernel{"voxel_downsample_scan", kGroupSize};
constexpr compute::KernelSpec kAssignKernel{"voxel_downsample_assign", kGroupSize};
constexpr compute::KernelSpec kAccumulateKernel{"voxel_downsample_accumulate", kGroupSize};
constexpr compute::KernelSpec kFinalizeKernel{"voxel_downsample_finalize", kGroupSize};
constexpr std::size_t kMaxPoints = std::size_t{1} << 26;

// Which attributes the cloud has, and the sums per voxel (layout in the rule header).
struct Layout {
  bool normals = false;
  bool colors = false;
  std::uint32_t stride = 4;
};

Layout layout_of(const DeviceCloud& cloud) {
  Layout layout;
  layout.normals = cloud.has_normals();
  layout.colors = cloud.has_colors();
  layout.stride = kernels::voxel_sum_stride(layout.normals ? 1u : 0u, layout.colors ? 1u : 0u);
  return layout;
}

kernels::VoxelSumParams sum_params(std::size_t count, const Layout& layout, float inverse_size,
                                   std::size_t points) {
  return {static_cast<std::uint32_t>(count),
          layout.stride,
          layout.normals ? 1u : 0u,
          layout.colors ? 1u : 0u,
          inverse_size,
          detail::fixed_point_scale(static_cast<double>(points)),  // fractions < 1
          detail::fixed_point_scale(KG_VOXEL_MAX_NORMAL_COMPONENT * static_cast<double>(points))};
}

void check(const std::array<std::uint32_t, KG_VOXEL_STATUS_VALUES>& status, float voxel_size) {
  const std::uint32_t out_of_range = status[KG_VOXEL_STATUS_OUT_OF_RANGE];
  const std::uint32_t bad_normals = status[KG_VOXEL_STATUS_BAD_NORMALS];
  require(out_of_range == 0, "voxel downsample: " + std::to_string(out_of_range) +
                                 " points lie beyond 2^20 voxels of " + std::to_string(voxel_size) +
                                 " m from the origin (or have NaN/Inf coordinates)");
  require(bad_normals == 0, "voxel downsample: " + std::to_string(bad_normals) +
                                " normals have a component beyond +-2 (not unit vectors)");
  require(status[KG_VOXEL_STATUS_TABLE_FULL] == 0,
          "voxel downsample: the hash table overflowed (internal error)");
}

DeviceCloud allocate_cloud(const compute::Context& context, std::size_t count,
                           const Layout& layout) {
  DeviceCloud out;
  out.points = compute::Buffer<Point4f>(context, count);
  if (layout.normals) out.normals = compute::Buffer<Point4f>(context, count);
  if (layout.colors) out.colors = compute::Buffer<std::uint32_t>(context, count);
  return out;
}

compute::BufferArg optional(const compute::RawBuffer& buffer, bool present) {
  return present ? compute::BufferArg(buffer) : compute::BufferArg();
}

}  // namespace

VoxelDownsampler::VoxelDownsampler(const compute::Context& context)
    : context_(&context), status_(context, KG_VOXEL_STATUS_VALUES) {}

DeviceCloud voxel_downsample(const compute::Context& context, const DeviceCloud& cloud,
                             const VoxelDownsampleParams& params) {
  return VoxelDownsampler(context).run(cloud, params);
}

DeviceCloud VoxelDownsampler::run(const DeviceCloud& cloud, const VoxelDownsampleParams& params) {
  const compute::Context& context = *context_;
  cloud.validate("voxel downsample");
  require(std::isfinite(params.voxel_size) && params.voxel_size > 0,
          "voxel downsample: voxel_size must be finite and > 0, got " +
              std::to_string(params.voxel_size));
  require(cloud.size() <= kMaxPoints,
          "voxel downsample: more than 2^26 points (" + std::to_string(cloud.size()) + ")");
  const float inverse_size = static_cast<float>(1.0 / params.voxel_size);
  require(std::isfinite(inverse_size), "voxel downsample: voxel_size is too small");
  const Layout layout = layout_of(cloud);
  const std::size_t n = cloud.size();
  if (n == 0) return allocate_cloud(context, 0, layout);

  const unsigned capacity_log2 = detail::hash_capacity_log2(n);
  const std::size_t capacity = std::size_t{1} << capacity_log2;
  if (keys_.size() != capacity) {
    keys_ = compute::Buffer<std::uint64_t>(context, capacity);
    first_ = compute::Buffer<std::uint32_t>(context, capacity);
    voxel_of_slot_ = compute::Buffer<std::uint32_t>(context, capacity);
  }
  if (point_slots_.size() < n) point_slots_ = compute::Buffer<std::int32_t>(context, n);
  // The ordering passes give each of `threads` threads a contiguous chunk of points: few
  // work-groups on CPU-hosted drivers, enough to fill a GPU.
  const std::uint32_t max_groups = context.device_info().is_gpu() ? 1024 : 16;
  const std::uint32_t groups =
      std::max<std::uint32_t>(1, std::min(max_groups, compute::groups_for(n, kGroupSize)));
  const std::uint32_t threads = groups * kGroupSize;
  const auto chunk = static_cast<std::uint32_t>((n + threads - 1) / threads);
  if (counts_.size() < threads + 1u)
    counts_ = compute::Buffer<std::uint32_t>(context, threads + 1u);

  keys_.fill_zero();
  first_.fill_zero();
  status_.fill_zero();
  const auto point_count = static_cast<std::uint32_t>(n);
  const std::uint32_t point_groups = compute::groups_for(n, kGroupSize);
  compute::dispatch(context, kInsertKernel,
                    {cloud.points, optional(cloud.normals.raw(), layout.normals), keys_, first_,
                     point_slots_, status_},
                    kernels::VoxelInsertParams{point_count, capacity_log2, layout.normals ? 1u : 0u,
                                               inverse_size},
                    {point_groups, 1});
  compute::dispatch(context, kCountKernel, {point_slots_, first_, counts_},
                    kernels::VoxelChunkParams{point_count, chunk}, {groups, 1});
  compute::dispatch(context, kScanKernel, {counts_}, kernels::VoxelScanParams{threads}, {1, 1});
  std::uint32_t voxel_count = 0;
  counts_.download(std::span(&voxel_count, 1), threads);
  std::array<std::uint32_t, KG_VOXEL_STATUS_VALUES> status{};
  status_.download(status);
  check(status, params.voxel_size);

  DeviceCloud out = allocate_cloud(context, voxel_count, layout);
  if (voxel_count == 0) return out;
  compute::Buffer<std::uint64_t> voxel_keys(context, voxel_count);
  compute::Buffer<std::int64_t> sums(context, std::size_t{voxel_count} * layout.stride);
  sums.fill_zero();
  compute::dispatch(context, kAssignKernel,
                    {point_slots_, first_, counts_, keys_, voxel_of_slot_, voxel_keys},
                    kernels::VoxelChunkParams{point_count, chunk}, {groups, 1});
  compute::dispatch(
      context, kAccumulateKernel,
      {cloud.points, optional(cloud.normals.raw(), layout.normals),
       optional(cloud.colors.raw(), layout.colors), point_slots_, voxel_of_slot_, sums},
      sum_params(n, layout, inverse_size, n), {point_groups, 1});
  compute::dispatch(context, kFinalizeKernel,
                    {voxel_keys, sums, out.points, optional(out.normals.raw(), layout.normals),
                     optional(out.colors.raw(), layout.colors)},
                    sum_params(voxel_count, layout, inverse_size, n),
                    {compute::groups_for(voxel_count, kGroupSize), 1});
  return out;
}

}  // namespace kartograf::geometry
