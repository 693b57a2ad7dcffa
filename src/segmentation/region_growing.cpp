#include "kartograf/segmentation/region_growing.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "compute/cpu_parallel.hpp"
#include "kartograf/compute/kernel.hpp"

namespace kartograf::segmentation {

namespace {

using geometry::kNoLabel;

constexpr int kNeighbourDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
constexpr int kNeighbourDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};

constexpr compute::KernelSpec kTilesKernel{"region_grow_tiles", 64};  // one tile per work-item
constexpr compute::KernelSpec kScanKernel{"region_grow_scan", 64};    // one work-group
constexpr compute::KernelSpec kOffsetsKernel{"region_grow_offsets", 256};

struct RegionGrowKernelParams {  // layout of shaders/region_grow.glsl and kernels/region_grow.cl
  std::uint32_t width;
  std::uint32_t height;
  std::uint32_t tile_size;
  std::uint32_t tiles_x;
  std::uint32_t tile_count;
  std::uint32_t padded_tile_count;  // a multiple of 64 (the scan's lanes)
  std::uint32_t stack_stride;       // stack entries per tile: 8 tile_size^2 + 1
  std::uint32_t threshold_code;     // the threshold in 1/64 Lab units
  float depth_ratio;                // 0: no depth test
};

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The threshold in Lab codes (1/64 units).
std::int64_t threshold_code(float lab_threshold) {
  return std::llround(static_cast<double>(lab_threshold) * kLabCodeScale);
}

// What the growing of one tile reads.
struct GrowInput {
  const LabCode* lab;
  const Point4f* points;
  int width;
  std::int64_t threshold;  // codes
  double depth_ratio;
  const Eigen::Vector3d* moments_origin;  // null: no moments
};

// What the growing of a run of tiles measures: per segment (in label order).
struct GrowOutput {
  std::vector<Eigen::Vector4d> colour_sums;  // code sums, count
  std::vector<geometry::SegmentMoments> moments;
};

// Marks pixels without a point or a colour in the label image, so that one read of a neighbour's
// label tells both whether it is taken and whether it is valid; unmarked afterwards.
constexpr std::uint32_t kInvalid = kNoLabel - 1;

// Grows every segment of the tile [x0, x1) x [y0, y1) with the paper's stack, numbering them
// from `first`; labels of the tile's pixels are kNoLabel or kInvalid. Returns the number of
// segments. out (optional) receives each segment's measures. Wide: an integer type that holds
// (T n)^2 for the tile's pixel count n (int64 up to 64 x 64 pixels).
template <class Wide>
std::uint32_t grow_tile(const GrowInput& in, int x0, int y0, int x1, int y1, std::uint32_t first,
                        std::uint32_t* label, std::vector<std::uint32_t>& stack, GrowOutput* out) {
  const int width = in.width;
  const Wide threshold_sq = static_cast<Wide>(in.threshold) * in.threshold;
  std::int32_t offsets[8];
  for (int k = 0; k < 8; ++k) offsets[k] = kNeighbourDy[k] * width + kNeighbourDx[k];
  std::uint32_t next = first;
  for (int seed_y = y0; seed_y < y1; ++seed_y) {
    for (int seed_x = x0; seed_x < x1; ++seed_x) {
      const std::size_t seed = static_cast<std::size_t>(seed_y) * width + seed_x;
      if (label[seed] != kNoLabel) continue;
      const std::uint32_t id = next++;
      std::int64_t sum_l = 0, sum_a = 0, sum_b = 0, count = 0;
      // Moments: sum d, sum d d^T (upper triangle), d = p - origin, in double.
      double m[9] = {};
      stack.clear();
      stack.push_back(static_cast<std::uint32_t>(seed));
      while (!stack.empty()) {
        const std::uint32_t pixel = stack.back();
        stack.pop_back();
        if (label[pixel] != kNoLabel) continue;
        const LabCode& c = in.lab[pixel];
        if (count > 0) {  // the seed joins its own segment: distance 0 to its colour
          const Wide dl = count * c[0] - sum_l, da = count * c[1] - sum_a,
                     db = count * c[2] - sum_b;
          if (dl * dl + da * da + db * db >= threshold_sq * count * count) continue;
        }
        label[pixel] = id;
        ++count;
        sum_l += c[0], sum_a += c[1], sum_b += c[2];
        if (in.moments_origin) {
          const Point4f& point = in.points[pixel];
          const double dx = point.x() - in.moments_origin->x();
          const double dy = point.y() - in.moments_origin->y();
          const double dz = point.z() - in.moments_origin->z();
          m[0] += dx, m[1] += dy, m[2] += dz;
          m[3] += dx * dx, m[4] += dx * dy, m[5] += dx * dz;
          m[6] += dy * dy, m[7] += dy * dz, m[8] += dz * dz;
        }
        const int x = static_cast<int>(pixel % static_cast<std::uint32_t>(width));
        const int y = static_cast<int>(pixel / static_cast<std::uint32_t>(width));
        const double depth = in.points[pixel].z();
        const auto push = [&](std::uint32_t neighbour) {
          if (label[neighbour] != kNoLabel) return;
          if (in.depth_ratio > 0.0 && std::fabs(static_cast<double>(in.points[neighbour].z()) -
                                                depth) > in.depth_ratio * depth) {
            return;
          }
          stack.push_back(neighbour);
        };
        if (x > x0 && y > y0 && x + 1 < x1 && y + 1 < y1) {  // all 8 neighbours in the tile
          for (int k = 0; k < 8; ++k) push(pixel + offsets[k]);
        } else {
          for (int k = 0; k < 8; ++k) {
            const int nx = x + kNeighbourDx[k], ny = y + kNeighbourDy[k];
            if (nx >= x0 && ny >= y0 && nx < x1 && ny < y1) push(pixel + offsets[k]);
          }
        }
      }
      if (out) {
        out->colour_sums.emplace_back(static_cast<double>(sum_l), static_cast<double>(sum_a),
                                      static_cast<double>(sum_b), static_cast<double>(count));
        if (in.moments_origin) {
          geometry::SegmentMoments& moments = out->moments.emplace_back();
          moments.count = static_cast<std::uint64_t>(count);
          moments.sum = Eigen::Vector3d(m[0], m[1], m[2]);
          moments.sum_outer << m[3], m[4], m[5], m[4], m[6], m[7], m[5], m[7], m[8];
        }
      }
    }
  }
  return next - first;
}

void check_inputs(int lab_width, int lab_height, int width, int height,
                  const RegionGrowingParams& params) {
  require(lab_width == width && lab_height == height,
          "region growing: Lab image is " + size_text(lab_width, lab_height) +
              " but the point image is " + size_text(width, height));
  params.validate();
}

void fill_colours(const std::vector<Eigen::Vector4d>& sums, std::vector<Eigen::Vector3f>& colours) {
  colours.resize(sums.size());
  for (std::size_t s = 0; s < sums.size(); ++s) {
    colours[s] = sums[s].w() > 0
                     ? (sums[s].head<3>() / (sums[s].w() * kLabCodeScale)).cast<float>().eval()
                     : Eigen::Vector3f::Zero();
  }
}

// Each chunk of tiles numbered its segments from 0: shift them by the segments of the chunks before,
// so that the labels are those of one sequential scan. Returns the segment count.
std::uint32_t number_chunks_in_scan_order(const std::uint32_t* chunk_counts, std::uint32_t* labels,
                                          int width, int height, int tile, std::size_t tile_count) {
  const int tiles_x = (width + tile - 1) / tile;
  std::uint32_t total = 0;
  for (std::size_t chunk = 0; chunk < compute::detail::kCpuChunks; ++chunk) {
    const std::uint32_t offset = total;
    total += chunk_counts[chunk];
    if (offset == 0 || chunk_counts[chunk] == 0) continue;
    const std::size_t begin = tile_count * chunk / compute::detail::kCpuChunks;
    const std::size_t end = tile_count * (chunk + 1) / compute::detail::kCpuChunks;
    for (std::size_t t = begin; t < end; ++t) {
      const int x0 = static_cast<int>(t % tiles_x) * tile;
      const int y0 = static_cast<int>(t / tiles_x) * tile;
      for (int y = y0; y < std::min(height, y0 + tile); ++y) {
        std::uint32_t* row = labels + static_cast<std::size_t>(y) * width;
        for (int x = x0; x < std::min(width, x0 + tile); ++x) {
          if (row[x] != kNoLabel) row[x] += offset;
        }
      }
    }
  }
  return total;
}

std::uint32_t grow_on_host(const LabCode* lab, const Point4f* points, int width, int height,
                           const RegionGrowingParams& params, std::uint32_t* labels,
                           SegmentStatistics* statistics, const Eigen::Vector3d* moments_origin) {
  const std::size_t pixel_count = static_cast<std::size_t>(width) * height;
  if (statistics) {
    statistics->colours.clear();
    statistics->moments.clear();
  }
  if (pixel_count == 0) return 0;
  const GrowInput in{lab,
                     points,
                     width,
                     threshold_code(params.lab_threshold),
                     static_cast<double>(params.max_depth_jump),
                     statistics ? moments_origin : nullptr};
  const int tile = params.tile_size > 0 ? params.tile_size : std::max(width, height);
  const int tiles_x = (width + tile - 1) / tile, tiles_y = (height + tile - 1) / tile;
  const std::size_t tile_count = static_cast<std::size_t>(tiles_x) * tiles_y;
  // (T n)^2 < 2^63 for T <= 64000 codes and n <= 4096 pixels.
  const bool narrow = static_cast<std::int64_t>(tile) * tile <= 4096;
  // Contiguous runs of tiles per chunk, numbered from 0 within the chunk (then put in scan order).
  std::uint32_t chunk_counts[compute::detail::kCpuChunks] = {};
  GrowOutput chunk_outputs[compute::detail::kCpuChunks];
  compute::detail::for_each_chunk(
      tile_count, params.tile_size > 0 ? pixel_count : 0,
      [&](std::size_t begin, std::size_t end, std::size_t chunk) {
        std::vector<std::uint32_t> stack;
        stack.reserve(narrow ? 8 * static_cast<std::size_t>(tile) * tile + 1 : 1 << 16);
        std::uint32_t count = 0;
        for (std::size_t t = begin; t < end; ++t) {
          const int x0 = static_cast<int>(t % tiles_x) * tile;
          const int y0 = static_cast<int>(t / tiles_x) * tile;
          const int x1 = std::min(width, x0 + tile), y1 = std::min(height, y0 + tile);
          for (int y = y0; y < y1; ++y) {
            const std::size_t row = static_cast<std::size_t>(y) * width;
            for (int x = x0; x < x1; ++x) {
              labels[row + x] =
                  lab[row + x][3] != 0 && is_valid(points[row + x]) ? kNoLabel : kInvalid;
            }
          }
          GrowOutput* out = statistics ? &chunk_outputs[chunk] : nullptr;
          count += narrow ? grow_tile<std::int64_t>(in, x0, y0, x1, y1, count, labels, stack, out)
                          : grow_tile<__int128>(in, x0, y0, x1, y1, count, labels, stack, out);
          for (int y = y0; y < y1; ++y) {
            std::uint32_t* row = labels + static_cast<std::size_t>(y) * width;
            for (int x = x0; x < x1; ++x) {
              if (row[x] == kInvalid) row[x] = kNoLabel;
            }
          }
        }
        chunk_counts[chunk] = count;
      });
  const std::uint32_t total =
      number_chunks_in_scan_order(chunk_counts, labels, width, height, tile, tile_count);
  if (statistics) {
    std::vector<Eigen::Vector4d> sums;
    sums.reserve(total);
    for (GrowOutput& part : chunk_outputs) {
      sums.insert(sums.end(), part.colour_sums.begin(), part.colour_sums.end());
      statistics->moments.insert(statistics->moments.end(), part.moments.begin(),
                                 part.moments.end());
    }
    fill_colours(sums, statistics->colours);
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
  check_inputs(lab.width(), lab.height(), points.width(), points.height(), params);
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

RegionGrower::RegionGrower(const compute::Context& context) : context_(&context) {}

std::uint32_t RegionGrower::grow(const LabCodeImage& lab, const compute::Buffer<Point4f>& points,
                                 const RegionGrowingParams& params,
                                 std::vector<Eigen::Vector3f>* colours) {
  require(points.size() == lab.size(), "region growing: Lab image is " +
                                           size_text(lab.width(), lab.height()) + " but " +
                                           std::to_string(points.size()) + " points are given");
  params.validate();
  width_ = lab.width();
  height_ = lab.height();
  if (labels_.size() != lab.size()) labels_ = compute::Buffer<std::uint32_t>(*context_, lab.size());
  const bool on_device = !context_->is_cpu() && params.tile_size > 0 &&
                         params.tile_size <= kMaxDeviceTileSize && !lab.empty();
  if (context_->is_cpu()) {
    SegmentStatistics statistics;
    const std::uint32_t count =
        grow_on_host(lab.data(), points.host_span().data(), width_, height_, params,
                     labels_.host_span().data(), colours ? &statistics : nullptr, nullptr);
    if (colours) *colours = std::move(statistics.colours);
    return count;
  }
  host_labels_ = SegmentLabelImage(width_, height_);
  std::uint32_t count = 0;
  if (on_device) {
    count = grow_on_device(lab, points, params);
    labels_.download(host_labels_.pixels());
  } else {
    // Untiled (or larger tiles): the sequential growing on the host, labels uploaded.
    std::vector<Point4f> host_points(points.size());
    points.download(host_points);
    count = grow_on_host(lab.data(), host_points.data(), width_, height_, params,
                         host_labels_.data(), nullptr, nullptr);
    labels_.upload(host_labels_.pixels());
  }
  if (colours) {
    std::vector<Eigen::Vector4d> sums(count, Eigen::Vector4d::Zero());
    for (std::size_t i = 0; i < host_labels_.size(); ++i) {
      const std::uint32_t s = host_labels_.data()[i];
      if (s == kNoLabel) continue;
      const LabCode& c = lab.data()[i];
      sums[s] += Eigen::Vector4d(c[0], c[1], c[2], 1.0);
    }
    fill_colours(sums, *colours);
  }
  return count;
}

std::uint32_t RegionGrower::grow_on_device(const LabCodeImage& lab,
                                           const compute::Buffer<Point4f>& points,
                                           const RegionGrowingParams& params) {
  const compute::Context& context = *context_;
  const auto tile = static_cast<std::uint32_t>(params.tile_size);
  const std::uint32_t tiles_x = (static_cast<std::uint32_t>(width_) + tile - 1) / tile;
  const std::uint32_t tiles_y = (static_cast<std::uint32_t>(height_) + tile - 1) / tile;
  const std::uint32_t tile_count = tiles_x * tiles_y;
  const RegionGrowKernelParams kernel_params{
      static_cast<std::uint32_t>(width_),
      static_cast<std::uint32_t>(height_),
      tile,
      tiles_x,
      tile_count,
      (tile_count + 63) / 64 * 64,
      8 * tile * tile + 1,
      static_cast<std::uint32_t>(threshold_code(params.lab_threshold)),
      params.max_depth_jump};
  if (lab_.size() != lab.size()) lab_ = compute::Buffer<LabCode>(context, lab.size());
  lab_.upload(lab.pixels());
  if (tile_counts_.size() != kernel_params.padded_tile_count) {
    tile_counts_ = compute::Buffer<std::uint32_t>(context, kernel_params.padded_tile_count);
  }
  const std::size_t stack_entries = std::size_t{tile_count} * kernel_params.stack_stride;
  if (stacks_.size() != stack_entries) {
    stacks_ = compute::Buffer<std::uint32_t>(context, stack_entries);
  }
  if (status_.empty()) status_ = compute::Buffer<std::uint32_t>(context, 2);
  tile_counts_.fill_zero();
  status_.fill_zero();
  compute::dispatch(context, kTilesKernel, {lab_, points, labels_, tile_counts_, stacks_, status_},
                    kernel_params, {compute::groups_for(tile_count, kTilesKernel.local_x), 1});
  compute::dispatch(context, kScanKernel, {tile_counts_, status_}, kernel_params, {1, 1});
  compute::dispatch(context, kOffsetsKernel, {labels_, tile_counts_}, kernel_params,
                    {compute::groups_for(lab.size(), kOffsetsKernel.local_x), 1});
  std::uint32_t status[2] = {};
  status_.download(status);
  require(status[1] == 0, "region growing: a device stack overflowed (a bug)");
  return status[0];
}

SegmentLabelImage RegionGrower::download_labels() const {
  SegmentLabelImage image(width_, height_);
  labels_.download(image.pixels());
  return image;
}

}  // namespace kartograf::segmentation
