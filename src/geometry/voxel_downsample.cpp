#include "kartograf/geometry/voxel_downsample.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "geometry/voxel_key.hpp"
#include "kartograf/compute/kernel.hpp"

namespace kartograf::geometry {

namespace {

constexpr std::uint32_t kGroupSize = 64;
constexpr compute::KernelSpec kInsertKernel{"voxel_downsample_insert", kGroupSize};
constexpr compute::KernelSpec kCountKernel{"voxel_downsample_count", kGroupSize};
constexpr compute::KernelSpec kScanKernel{"voxel_downsample_scan", kGroupSize};
constexpr compute::KernelSpec kAssignKernel{"voxel_downsample_assign", kGroupSize};
constexpr compute::KernelSpec kAccumulateKernel{"voxel_downsample_accumulate", kGroupSize};
constexpr compute::KernelSpec kFinalizeKernel{"voxel_downsample_finalize", kGroupSize};
constexpr std::size_t kMaxPoints = std::size_t{1} << 26;
constexpr float kMaxNormalComponent = 2.0f;

// Layouts of shaders/voxel_downsample_*.comp and kernels/voxel_downsample.cl.
struct InsertParams {
  std::uint32_t point_count;
  std::uint32_t capacity_log2;
  std::uint32_t has_normals;
  float inverse_size;
};
struct ChunkParams {
  std::uint32_t point_count;
  std::uint32_t chunk;
};
struct ScanParams {
  std::uint32_t thread_count;
};
struct SumParams {
  std::uint32_t count;  // points (accumulate) or voxels (finalize)
  std::uint32_t stride;
  std::uint32_t has_normals;
  std::uint32_t has_colors;
  float inverse_size;
  float position_scale;
  float normal_scale;
};

// Per voxel: [0] count, [1..3] position sums, then [4..6] normal sums and [7] normal count when
// there are normals, then r, g, b sums when there are colours.
struct Layout {
  bool normals = false;
  bool colors = false;
  std::uint32_t stride = 4;
  std::uint32_t color_offset = 4;
};

Layout layout_of(const DeviceCloud& cloud) {
  Layout layout;
  layout.normals = cloud.has_normals();
  layout.colors = cloud.has_colors();
  layout.color_offset = layout.normals ? 8 : 4;
  layout.stride = layout.color_offset + (layout.colors ? 3 : 0);
  return layout;
}

SumParams sum_params(std::size_t count, const Layout& layout, float inverse_size,
                     std::size_t points) {
  return {static_cast<std::uint32_t>(count),
          layout.stride,
          layout.normals ? 1u : 0u,
          layout.colors ? 1u : 0u,
          inverse_size,
          detail::fixed_point_scale(static_cast<double>(points)),  // fractions < 1
          detail::fixed_point_scale(kMaxNormalComponent * static_cast<double>(points))};
}

bool unit_bounded(const Point4f& n) {
  return std::fabs(n.x()) <= kMaxNormalComponent && std::fabs(n.y()) <= kMaxNormalComponent &&
         std::fabs(n.z()) <= kMaxNormalComponent;
}

std::int64_t to_fixed(double value, double scale) {
  return static_cast<std::int64_t>(std::nearbyint(value * scale));
}

struct Status {
  std::uint32_t out_of_range = 0;
  std::uint32_t table_full = 0;
  std::uint32_t bad_normals = 0;
};

void check(const Status& status, float voxel_size) {
  require(status.out_of_range == 0, "voxel downsample: " + std::to_string(status.out_of_range) +
                                        " points lie beyond 2^20 voxels of " +
                                        std::to_string(voxel_size) +
                                        " m from the origin (or have NaN/Inf coordinates)");
  require(status.bad_normals == 0, "voxel downsample: " + std::to_string(status.bad_normals) +
                                       " normals have a component beyond +-2 (not unit vectors)");
  require(status.table_full == 0, "voxel downsample: the hash table overflowed (internal error)");
}

// The finalisation kernel's arithmetic for voxel v.
void finalize_voxel(std::size_t v, std::uint64_t key, const std::int64_t* s, const Layout& layout,
                    const SumParams& params, DeviceCloud& out) {
  const double count = static_cast<double>(s[0]);
  const Eigen::Vector3d fraction =
      Eigen::Vector3d(static_cast<double>(s[1]), static_cast<double>(s[2]),
                      static_cast<double>(s[3])) /
      (count * static_cast<double>(params.position_scale));
  const Eigen::Vector3d centroid =
      (detail::voxel_of_key(key) + fraction) / static_cast<double>(params.inverse_size);
  out.points.host_span()[v] =
      Point4f(static_cast<float>(centroid.x()), static_cast<float>(centroid.y()),
              static_cast<float>(centroid.z()), 1.0f);
  if (layout.normals) {
    const Eigen::Vector3d sum =
        Eigen::Vector3d(static_cast<double>(s[4]), static_cast<double>(s[5]),
                        static_cast<double>(s[6])) /
        static_cast<double>(params.normal_scale);
    const double norm = std::sqrt(sum.dot(sum));
    out.normals.host_span()[v] =
        s[7] == 0 || norm < 1e-3 * static_cast<double>(s[7])
            ? invalid_point()
            : Point4f(static_cast<float>(sum.x() / norm), static_cast<float>(sum.y() / norm),
                      static_cast<float>(sum.z() / norm), 0.0f);
  }
  if (layout.colors) {
    const auto n = static_cast<std::uint64_t>(s[0]);
    std::uint32_t packed = 0;
    for (std::uint32_t channel = 0; channel < 3; ++channel) {
      const std::uint64_t mean =
          (2 * static_cast<std::uint64_t>(s[layout.color_offset + channel]) + n) / (2 * n);
      packed |= static_cast<std::uint32_t>(mean) << (8 * channel);
    }
    out.colors.host_span()[v] = packed;
  }
}

DeviceCloud allocate_cloud(const compute::Context& context, std::size_t count,
                           const Layout& layout) {
  DeviceCloud out;
  out.points = compute::Buffer<Point4f>(context, count);
  if (layout.normals) out.normals = compute::Buffer<Point4f>(context, count);
  if (layout.colors) out.colors = compute::Buffer<std::uint32_t>(context, count);
  return out;
}

DeviceCloud downsample_cpu(const compute::Context& context, const DeviceCloud& cloud,
                           const Layout& layout, float inverse_size, float voxel_size) {
  const SumParams params = sum_params(0, layout, inverse_size, cloud.size());
  const auto points = cloud.points.host_span();
  const std::span<const Point4f> normals =
      layout.normals ? cloud.normals.host_span() : std::span<const Point4f>();
  const std::span<const std::uint32_t> colors =
      layout.colors ? cloud.colors.host_span() : std::span<const std::uint32_t>();
  std::unordered_map<std::uint64_t, std::uint32_t> voxel_of_key;
  std::vector<std::uint64_t> keys;  // per voxel, in the order of first points
  std::vector<std::int64_t> sums;
  Status status;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point4f& p = points[i];
    if (!is_valid(p)) continue;
    if (layout.normals && is_valid(normals[i]) && !unit_bounded(normals[i])) ++status.bad_normals;
    const Eigen::Vector3d scaled = p.head<3>().cast<double>() * static_cast<double>(inverse_size);
    Eigen::Vector3d voxel;
    if (!detail::voxel_of(scaled, voxel)) {
      ++status.out_of_range;
      continue;
    }
    const std::uint64_t key = detail::voxel_key(voxel);
    const auto [entry, inserted] =
        voxel_of_key.try_emplace(key, static_cast<std::uint32_t>(keys.size()));
    if (inserted) {
      keys.push_back(key);
      sums.resize(sums.size() + layout.stride, 0);
    }
    std::int64_t* s = &sums[std::size_t{entry->second} * layout.stride];
    const Eigen::Vector3d fraction = scaled - voxel;
    s[0] += 1;
    for (int axis = 0; axis < 3; ++axis)
      s[1 + axis] += to_fixed(fraction(axis), params.position_scale);
    if (layout.normals && is_valid(normals[i]) && unit_bounded(normals[i])) {
      for (int axis = 0; axis < 3; ++axis)
        s[4 + axis] += to_fixed(normals[i](axis), params.normal_scale);
      s[7] += 1;
    }
    if (layout.colors) {
      for (std::uint32_t channel = 0; channel < 3; ++channel) {
        s[layout.color_offset + channel] += (colors[i] >> (8 * channel)) & 0xff;
      }
    }
  }
  check(status, voxel_size);
  DeviceCloud out = allocate_cloud(context, keys.size(), layout);
  for (std::size_t v = 0; v < keys.size(); ++v) {
    finalize_voxel(v, keys[v], &sums[v * layout.stride], layout, params, out);
  }
  return out;
}

compute::BufferArg optional(const compute::RawBuffer& buffer, bool present) {
  return present ? compute::BufferArg(buffer) : compute::BufferArg();
}

}  // namespace

VoxelDownsampler::VoxelDownsampler(const compute::Context& context) : context_(&context) {
  if (!context.is_cpu()) status_ = compute::Buffer<std::uint32_t>(context, 3);
}

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
  if (context.is_cpu())
    return downsample_cpu(context, cloud, layout, inverse_size, params.voxel_size);

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
  compute::dispatch(
      context, kInsertKernel,
      {cloud.points, optional(cloud.normals.raw(), layout.normals), keys_, first_, point_slots_,
       status_},
      InsertParams{point_count, capacity_log2, layout.normals ? 1u : 0u, inverse_size},
      {point_groups, 1});
  compute::dispatch(context, kCountKernel, {point_slots_, first_, counts_},
                    ChunkParams{point_count, chunk}, {groups, 1});
  compute::dispatch(context, kScanKernel, {counts_}, ScanParams{threads}, {1, 1});
  std::uint32_t voxel_count = 0;
  counts_.download(std::span(&voxel_count, 1), threads);
  std::array<std::uint32_t, 3> status{};
  status_.download(status);
  check({status[0], status[1], status[2]}, params.voxel_size);

  DeviceCloud out = allocate_cloud(context, voxel_count, layout);
  if (voxel_count == 0) return out;
  compute::Buffer<std::uint64_t> voxel_keys(context, voxel_count);
  compute::Buffer<std::int64_t> sums(context, std::size_t{voxel_count} * layout.stride);
  sums.fill_zero();
  compute::dispatch(context, kAssignKernel,
                    {point_slots_, first_, counts_, keys_, voxel_of_slot_, voxel_keys},
                    ChunkParams{point_count, chunk}, {groups, 1});
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
