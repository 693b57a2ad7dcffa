#include "kartograf/segmentation/region_growing.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "kernels/region_grow/region_grow_cpu.hpp"

namespace kartograf::segmentation {

namespace {

using geometry::kNoLabel;

constexpr compute::KernelSpec kTilesKernel{"region_grow_tiles", KG_REGION_GROW_TILES_LOCAL_X};
constexpr compute::KernelSpec kScanKernel{"region_grow_scan", KG_REGION_GROW_SCAN_LOCAL_X};
constexpr compute::KernelSpec kOffsetsKernel{"region_grow_offsets", KG_REGION_GROW_OFFSETS_LOCAL_X};
constexpr compute::KernelSpec kStatisticsKernel{"region_grow_statistics",
                                                KG_REGION_GROW_STATISTICS_LOCAL_X};
constexpr std::size_t kStatistics = KG_REGION_GROW_STATISTICS;
static_assert(sizeof(LabCode) == sizeof(kernels::LabCode4) &&
              sizeof(Point4f) == sizeof(kernels::float4));

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The kernels' parameters. tile: the tile size in pixels (the whole image when not tiling);
// moments_origin (rounded to float) only measuring.
kernels::RegionGrowParams kernel_params(int width, int height, int tile,
                                        const RegionGrowingParams& params, bool measure,
                                        const Eigen::Vector3d* moments_origin) {
  const auto w = static_cast<std::uint32_t>(width), h = static_cast<std::uint32_t>(height);
  const auto t = static_cast<std::uint32_t>(tile);
  const std::uint32_t tiles_x = (w + t - 1) / t, tile_count = tiles_x * ((h + t - 1) / t);
  const Eigen::Vector3f origin =
      moments_origin ? moments_origin->cast<float>().eval() : Eigen::Vector3f::Zero();
  return {w, h, t, tiles_x, tile_count, (tile_count + 63) / 64 * 64, 8 * t * t + 1,
          // The threshold in Lab codes (1/64 units).
          static_cast<std::uint32_t>(
              std::llround(static_cast<double>(params.lab_threshold) * kLabCodeScale)),
          params.max_depth_jump, measure ? 1u : 0u, std::min(t, w) * std::min(t, h), origin.x(),
          origin.y(), origin.z()};
}

// Each segment's colour and (with_moments) moments from the kernels' statistics.
void fill_statistics(const double* values, std::uint32_t count, bool with_moments,
                     SegmentStatistics& statistics) {
  statistics.colours.resize(count);
  if (with_moments) statistics.moments.resize(count);
  for (std::uint32_t s = 0; s < count; ++s) {
    const double* v = values + std::size_t{s} * kStatistics;
    statistics.colours[s] =
        v[0] > 0 ? (Eigen::Vector3d(v[1], v[2], v[3]) / (v[0] * kLabCodeScale)).cast<float>().eval()
                 : Eigen::Vector3f::Zero();
    if (!with_moments) continue;
    geometry::SegmentMoments& moments = statistics.moments[s];
    moments.count = static_cast<std::uint64_t>(v[0]);
    moments.sum = Eigen::Vector3d(v[4], v[5], v[6]);
    moments.sum_outer << v[7], v[8], v[9], v[8], v[10], v[11], v[9], v[11], v[12];
  }
}

// The passes of kernels/region_grow on host arrays (any tile size).
std::uint32_t grow_on_host(const LabCode* lab, const Point4f* points, int width, int height,
                           const RegionGrowingParams& params, std::uint32_t* labels,
                           SegmentStatistics* statistics, const Eigen::Vector3d* moments_origin) {
  if (statistics) {
    statistics->colours.clear();
    statistics->moments.clear();
  }
  if (width == 0 || height == 0) return 0;
  const int tile = params.tile_size > 0 ? params.tile_size : std::max(width, height);
  const kernels::RegionGrowParams kp =
      kernel_params(width, height, tile, params, statistics != nullptr, moments_origin);
  std::vector<std::uint32_t> tile_counts(kp.padded_tile_count, 0);
  // Slots written only for the segments that exist: left uninitialised.
  const std::unique_ptr<double[]> slots(
      statistics ? new double[std::size_t{kp.tile_count} * kp.slots_per_tile * kStatistics]
                 : nullptr);
  kernels::region_grow_tiles_cpu(kp, {reinterpret_cast<const kernels::LabCode4*>(lab),
                                      reinterpret_cast<const kernels::float4*>(points), labels,
                                      tile_counts.data(), slots.get()});
  const std::uint32_t total = kernels::region_grow_scan_cpu(kp, tile_counts.data());
  kernels::region_grow_offsets_cpu(kp, labels, tile_counts.data());
  if (statistics) {
    std::vector<double> values(std::size_t{total} * kStatistics);
    kernels::region_grow_statistics_cpu(kp, tile_counts.data(), total, slots.get(), values.data());
    fill_statistics(values.data(), total, moments_origin != nullptr, *statistics);
  }
  return total;
}

}  // namespace

void RegionGrowingParams::validate() const {
  require(
      std::isfinite(lab_threshold) && lab_threshold > 0 && lab_threshold <= 1000,
      "region growing: lab_threshold must be in (0, 1000], got " + std::to_string(lab_threshold));
  require(std::isfinite(max_depth_jump) && max_depth_jump >= 0,
          "region growing: max_depth_jump must be >= 0 (0 = off), got " +
              std::to_string(max_depth_jump));
  require(tile_size >= 0,
          "region growing: tile_size must be >= 0 (0 = off), got " + std::to_string(tile_size));
}

std::uint32_t grow_regions(const LabCodeImage& lab, const PointImage& points,
                           const RegionGrowingParams& params, SegmentLabelImage& labels,
                           SegmentStatistics* statistics, const Eigen::Vector3d* moments_origin) {
  require(lab.width() == points.width() && lab.height() == points.height(),
          "region growing: Lab image is " + size_text(lab.width(), lab.height()) +
              " but the point image is " + size_text(points.width(), points.height()));
  params.validate();
  if (labels.width() != points.width() || labels.height() != points.height())
    labels = SegmentLabelImage(points.width(), points.height());
  return grow_on_host(lab.data(), points.data(), points.width(), points.height(), params,
                      labels.data(), statistics, moments_origin);
}

SegmentLabelImage grow_regions_lab(const LabImage& lab, const PointImage& points,
                                   const RegionGrowingParams& params) {
  SegmentLabelImage labels;
  grow_regions(to_lab_codes(lab), points, params, labels);
  return labels;
}

std::uint32_t segment_count(const SegmentLabelImage& labels) {
  std::uint32_t count = 0;
  for (const std::uint32_t l : labels.pixels())
    if (l != kNoLabel) count = std::max(count, l + 1);
  return count;
}

RegionGrower::RegionGrower(const compute::Context& context)
    : context_(&context), status_(context, 2) {}

std::uint32_t RegionGrower::grow(const LabCodeImage& lab, const compute::Buffer<Point4f>& points,
                                 const RegionGrowingParams& params,
                                 std::vector<Eigen::Vector3f>* colours) {
  SegmentStatistics statistics;
  const std::uint32_t count = grow(lab, points, params, colours ? &statistics : nullptr, nullptr);
  if (colours) *colours = std::move(statistics.colours);
  return count;
}

std::uint32_t RegionGrower::grow(const LabCodeImage& lab, const compute::Buffer<Point4f>& points,
                                 const RegionGrowingParams& params, SegmentStatistics* statistics,
                                 const Eigen::Vector3d* moments_origin) {
  require(points.size() == lab.size(), "region growing: Lab image is " +
                                           size_text(lab.width(), lab.height()) + " but " +
                                           std::to_string(points.size()) + " points are given");
  params.validate();
  width_ = lab.width();
  height_ = lab.height();
  if (labels_.size() != lab.size()) labels_ = compute::Buffer<std::uint32_t>(*context_, lab.size());
  if (statistics) {
    statistics->colours.clear();
    statistics->moments.clear();
  }
  if (lab.empty()) return 0;
  if (params.tile_size > 0 && params.tile_size <= kMaxDeviceTileSize) {
    return grow_tiles(lab, points, params, statistics, moments_origin);
  }
  // Untiled (or larger tiles than a device's integers allow): the passes on the host.
  host_points_.resize(points.size());
  points.download(host_points_);
  host_labels_.resize(lab.size());
  const std::uint32_t count = grow_on_host(lab.data(), host_points_.data(), width_, height_, params,
                                           host_labels_.data(), statistics, moments_origin);
  labels_.upload(host_labels_);
  return count;
}

std::uint32_t RegionGrower::grow_tiles(const LabCodeImage& lab,
                                       const compute::Buffer<Point4f>& points,
                                       const RegionGrowingParams& params,
                                       SegmentStatistics* statistics,
                                       const Eigen::Vector3d* moments_origin) {
  const compute::Context& context = *context_;
  const kernels::RegionGrowParams kp = kernel_params(width_, height_, params.tile_size, params,
                                                     statistics != nullptr, moments_origin);
  lab_.refer_or_upload(context, lab.pixels());  // no copy on the CPU backend
  if (tile_counts_.size() != kp.padded_tile_count) {
    tile_counts_ = compute::Buffer<std::uint32_t>(context, kp.padded_tile_count);
  }
  const std::size_t stack_entries = std::size_t{kp.tile_count} * kp.stack_stride;
  if (stacks_.size() != stack_entries)
    stacks_ = compute::Buffer<std::uint32_t>(context, stack_entries);
  const std::size_t slot_values = std::size_t{kp.tile_count} * kp.slots_per_tile * kStatistics;
  if (statistics && slots_.size() < slot_values)
    slots_ = compute::Buffer<double>(context, slot_values);
  tile_counts_.fill_zero();
  status_.fill_zero();
  compute::dispatch(context, kTilesKernel,
                    {lab_, points, labels_, tile_counts_, stacks_, status_,
                     statistics ? compute::BufferArg(slots_) : compute::BufferArg()},
                    kp, {compute::groups_for(kp.tile_count, kTilesKernel.local_x), 1});
  compute::dispatch(context, kScanKernel, {tile_counts_, status_}, kp, {1, 1});
  compute::dispatch(context, kOffsetsKernel, {labels_, tile_counts_}, kp,
                    {compute::groups_for(lab.size(), kOffsetsKernel.local_x), 1});
  std::uint32_t status[2] = {};
  status_.download(status);
  require(status[KG_REGION_GROW_OVERFLOWS] == 0,
          "region growing: a device stack overflowed (a bug)");
  const std::uint32_t count = status[KG_REGION_GROW_SEGMENT_COUNT];
  if (statistics && count > 0) {
    if (statistics_.size() < std::size_t{count} * kStatistics) {
      statistics_ = compute::Buffer<double>(context, std::size_t{count} * kStatistics);
    }
    compute::dispatch(
        context, kStatisticsKernel, {tile_counts_, status_, slots_, statistics_}, kp,
        {compute::groups_for(slot_values / kStatistics, kStatisticsKernel.local_x), 1});
    host_statistics_.resize(std::size_t{count} * kStatistics);
    statistics_.download(std::span<double>(host_statistics_));
    fill_statistics(host_statistics_.data(), count, moments_origin != nullptr, *statistics);
  }
  return count;
}

SegmentLabelImage RegionGrower::download_labels() const {
  SegmentLabelImage image(width_, height_);
  labels_.download(image.pixels());
  return image;
}

}  // namespace kartograf::segmentation
