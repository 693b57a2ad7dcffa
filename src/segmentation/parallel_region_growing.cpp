#include "kartograf/segmentation/parallel_region_growing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "registration/cpu_parallel.hpp"

namespace kartograf::segmentation {

namespace {

using geometry::kNoLabel;

constexpr std::uint32_t kPixelsPerBlock = 256;  // KG_PIXELS_PER_BLOCK in the shaders and kernels
// Lab is clamped to +-255 (sRGB colours stay within +-128) and quantised to 1/64 unit: codes fit
// 16 bits and a squared distance (< 3 * 2^30) 32 bits, exactly, on every backend.
constexpr float kLabClamp = 255.0f;
constexpr float kLabScale = 64.0f;
constexpr float kMaxLabThreshold = 1000.0f;  // (1000 * 64)^2 < 2^32

constexpr compute::KernelSpec kInitKernel{"region_grow_init", 64};  // one row per item
constexpr compute::KernelSpec kUnionKernel{"region_grow_union", 256};
constexpr compute::KernelSpec kCountKernel{"region_grow_count", 64};
constexpr compute::KernelSpec kScanKernel{"region_grow_scan", 64};
constexpr compute::KernelSpec kNumberRootsKernel{"region_grow_number_roots", 64};
constexpr compute::KernelSpec kAssignKernel{"region_grow_assign", 256};

struct RegionGrowKernelParams {  // layout of shaders/region_grow.glsl and kernels/region_grow.cl
  std::uint32_t width;
  std::uint32_t height;
  std::uint32_t pixel_count;
  std::uint32_t block_count;  // padded to a multiple of 64 (the scan's lanes)
  std::uint32_t limit;        // connect when the quantised squared Lab distance < limit
  float depth_ratio;
};

// The smallest integer above every quantised squared distance that is below the threshold:
// d2 < (t * scale)^2 <=> d2 < ceil((t * scale)^2) for integer d2 (the square is exact in double).
std::uint32_t squared_distance_limit(float lab_threshold) {
  const double scaled = static_cast<double>(lab_threshold) * kLabScale;
  return static_cast<std::uint32_t>(std::ceil(scaled * scaled));
}

// Round half to even of |v| <= 2^22 without a libm call: adding 1.5 * 2^23 leaves no fraction
// bits, so the float addition rounds (to nearest even, like roundEven / convert_int_rte).
std::int16_t quantise(float value) {
  constexpr float kShift = 12582912.0f;  // 1.5 * 2^23
  const float scaled = std::clamp(value, -kLabClamp, kLabClamp) * kLabScale;
  return static_cast<std::int16_t>((scaled + kShift) - kShift);
}

// The CPU path's per-pixel planes (one 16-bit code per Lab channel, depth, validity): row loops
// over them vectorise.
struct HostPlanes {
  std::int16_t* l;
  std::int16_t* a;
  std::int16_t* b;
  float* z;
  std::uint8_t* valid;
};

// Bits of the CPU path's per-pixel edge byte: which backward neighbours are joined.
enum EdgeBit : std::uint8_t { kLeft = 1, kUpLeft = 2, kUp = 4, kUpRight = 8 };

// Sets `bit` in edges[i] for each i in [begin, end) joined to pixel i + offset: the rules of
// connected() in shaders/region_grow.glsl. No branch on the data, so the loop vectorises.
template <bool kDepthTest>
void mark_edges(const HostPlanes& q, std::uint32_t limit, double depth_ratio, std::size_t begin,
                std::size_t end, std::ptrdiff_t offset, std::uint8_t bit, std::uint8_t* edges) {
  // __restrict: the byte stores could alias the planes as far as the compiler knows, which
  // stops it from vectorising. Suffix n: the neighbours (pixel i + offset).
  const std::int16_t* __restrict l = q.l + begin;
  const std::int16_t* __restrict a = q.a + begin;
  const std::int16_t* __restrict b = q.b + begin;
  const float* __restrict z = q.z + begin;
  const std::uint8_t* __restrict valid = q.valid + begin;
  const std::int16_t* __restrict ln = l + offset;
  const std::int16_t* __restrict an = a + offset;
  const std::int16_t* __restrict bn = b + offset;
  const float* __restrict zn = z + offset;
  const std::uint8_t* __restrict valid_n = valid + offset;
  std::uint8_t* __restrict out = edges + begin;
  for (std::size_t k = 0; k < end - begin; ++k) {
    const std::int32_t dl = l[k] - ln[k], da = a[k] - an[k], db = b[k] - bn[k];
    const std::uint32_t distance_sq = static_cast<std::uint32_t>(dl * dl) +
                                      static_cast<std::uint32_t>(da * da) +
                                      static_cast<std::uint32_t>(db * db);
    bool joined = (distance_sq < limit) & (valid[k] != 0) & (valid_n[k] != 0);
    if constexpr (kDepthTest) {
      const double za = z[k], zb = zn[k];
      joined &= std::fabs(za - zb) <= depth_ratio * std::min(za, zb);
    }
    out[k] |= joined ? bit : 0;
  }
}

// The edges of row `row` (first pixel index) to its left and, with `up`, upper neighbours.
void mark_row_edges(const HostPlanes& q, std::uint32_t limit, double depth_ratio, std::size_t row,
                    std::size_t width, bool left, bool up, std::uint8_t* edges) {
  const auto mark = [&](std::size_t first_x, std::size_t end_x, std::ptrdiff_t offset,
                        std::uint8_t bit) {
    if (depth_ratio == 0.0) {
      mark_edges<false>(q, limit, 0.0, row + first_x, row + end_x, offset, bit, edges);
    } else {
      mark_edges<true>(q, limit, depth_ratio, row + first_x, row + end_x, offset, bit, edges);
    }
  };
  const auto w = static_cast<std::ptrdiff_t>(width);
  if (left) mark(1, width, -1, kLeft);
  if (!up) return;
  mark(1, width, -w - 1, kUpLeft);
  mark(0, width, -w, kUp);
  mark(0, width - 1, -w + 1, kUpRight);
}

// Fills the planes, parent (itself or kNoLabel) and cleared edges of pixels [begin, end); written
// for the vectoriser (selects, no early exits; a NaN never reaches the integer conversion).
void quantise_pixels(const Eigen::Vector4f* lab, const Point4f* points, std::size_t begin,
                     std::size_t end, const HostPlanes& q, std::uint32_t* parent,
                     std::uint8_t* edges) {
  const float* __restrict in_lab = lab[begin].data();
  const float* __restrict in_points = points[begin].data();
  std::int16_t* __restrict l = q.l + begin;
  std::int16_t* __restrict a = q.a + begin;
  std::int16_t* __restrict b = q.b + begin;
  float* __restrict z = q.z + begin;
  std::uint8_t* __restrict valid_out = q.valid + begin;
  std::uint32_t* __restrict parent_out = parent + begin;
  std::uint8_t* __restrict edges_out = edges + begin;
  const auto finite = [](float v) { return std::fabs(v) <= std::numeric_limits<float>::max(); };
  for (std::size_t k = 0; k < end - begin; ++k) {
    const float x = in_points[4 * k], cl = in_lab[4 * k], ca = in_lab[4 * k + 1],
                cb = in_lab[4 * k + 2];
    const bool valid = (x == x) & finite(cl) & finite(ca) & finite(cb);  // x == x: not NaN
    valid_out[k] = valid;
    parent_out[k] = valid ? static_cast<std::uint32_t>(begin + k) : kNoLabel;
    l[k] = quantise(valid ? cl : 0.0f);
    a[k] = quantise(valid ? ca : 0.0f);
    b[k] = quantise(valid ? cb : 0.0f);
    z[k] = in_points[4 * k + 2];
    edges_out[k] = 0;
  }
}

// Union-find with min-linking on the host: parent[i] <= i always, so a root is the smallest
// index of its tree.
std::uint32_t find_root(std::uint32_t* parent, std::uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];  // path halving keeps parent[i] <= i
    i = parent[i];
  }
  return i;
}

void unite(std::uint32_t* parent, std::uint32_t a, std::uint32_t b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a < b) parent[b] = a;
  if (b < a) parent[a] = b;
}

void check_params(const RegionGrowingParams& params) {
  require(std::isfinite(params.lab_threshold) && params.lab_threshold > 0 &&
              params.lab_threshold <= kMaxLabThreshold,
          "parallel region growing: lab_threshold must be in (0, 1000], got " +
              std::to_string(params.lab_threshold));
  require(std::isfinite(params.max_depth_jump) && params.max_depth_jump >= 0,
          "parallel region growing: max_depth_jump must be >= 0 (0 = off), got " +
              std::to_string(params.max_depth_jump));
}

}  // namespace

ParallelRegionGrowing::ParallelRegionGrowing(const compute::Context& context, int width, int height)
    : context_(&context), width_(width), height_(height) {
  require(width > 0 && height > 0, "parallel region growing: image size must be positive, got " +
                                       std::to_string(width) + "x" + std::to_string(height));
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  require(pixels < kNoLabel / 2, "parallel region growing: " + std::to_string(width) + "x" +
                                     std::to_string(height) + " is too many pixels");
  labels_ = compute::Buffer<std::uint32_t>(context, pixels);
  parent_ = compute::Buffer<std::uint32_t>(context, pixels);
  if (context.is_cpu()) {
    host_codes_.resize(3 * pixels);
    host_depth_.resize(pixels);
    host_valid_.resize(pixels);
    host_edges_.resize(pixels);
  } else {
    const std::size_t blocks = (pixels + kPixelsPerBlock - 1) / kPixelsPerBlock;
    block_counts_ = compute::Buffer<std::uint32_t>(context, (blocks + 63) / 64 * 64);
    status_ = compute::Buffer<std::uint32_t>(context, 1);
  }
}

std::uint32_t ParallelRegionGrowing::segment(const LabImage& lab, const PointImage& points,
                                             const RegionGrowingParams& params) {
  require(lab.width() == width_ && lab.height() == height_ && points.width() == width_ &&
              points.height() == height_,
          "parallel region growing: Lab image " + std::to_string(lab.width()) + "x" +
              std::to_string(lab.height()) + " and point image " + std::to_string(points.width()) +
              "x" + std::to_string(points.height()) + " must both be " + std::to_string(width_) +
              "x" + std::to_string(height_));
  check_params(params);
  if (context_->is_cpu()) {  // no copy: the host images are what the CPU path reads anyway
    segment_on_host(lab.pixels(), points.pixels(), params);
    return segment_count_;
  }
  if (lab_upload_.empty()) {
    lab_upload_ = compute::Buffer<Eigen::Vector4f>(*context_, lab.size());
    points_upload_ = compute::Buffer<Point4f>(*context_, points.size());
  }
  lab_upload_.upload(lab.pixels());
  points_upload_.upload(points.pixels());
  return segment(lab_upload_, points_upload_, params);
}

std::uint32_t ParallelRegionGrowing::segment(const compute::Buffer<Eigen::Vector4f>& lab,
                                             const compute::Buffer<Point4f>& points,
                                             const RegionGrowingParams& params) {
  const std::size_t pixels = labels_.size();
  require(lab.size() == pixels && points.size() == pixels,
          "parallel region growing: " + std::to_string(lab.size()) + " Lab pixels and " +
              std::to_string(points.size()) + " points for a " + std::to_string(width_) + "x" +
              std::to_string(height_) + " image");
  check_params(params);
  if (context_->is_cpu()) {
    segment_on_host(lab.host_span(), points.host_span(), params);
    return segment_count_;
  }

  const RegionGrowKernelParams kernel_params{static_cast<std::uint32_t>(width_),
                                             static_cast<std::uint32_t>(height_),
                                             static_cast<std::uint32_t>(pixels),
                                             static_cast<std::uint32_t>(block_counts_.size()),
                                             squared_distance_limit(params.lab_threshold),
                                             params.max_depth_jump};
  const compute::Context& context = *context_;
  const compute::GroupCount per_pixel{compute::groups_for(pixels, 256), 1};
  const compute::GroupCount per_block{compute::groups_for(block_counts_.size(), 64), 1};
  compute::dispatch(context, kInitKernel, {lab, points, parent_}, kernel_params,
                    {compute::groups_for(static_cast<std::size_t>(height_), 64), 1});
  compute::dispatch(context, kUnionKernel, {lab, points, parent_}, kernel_params, per_pixel);
  compute::dispatch(context, kCountKernel, {parent_, block_counts_}, kernel_params, per_block);
  compute::dispatch(context, kScanKernel, {block_counts_, status_}, kernel_params, {1, 1});
  compute::dispatch(context, kNumberRootsKernel, {parent_, block_counts_, labels_}, kernel_params,
                    per_block);
  compute::dispatch(context, kAssignKernel, {parent_, labels_}, kernel_params, per_pixel);
  status_.download(std::span<std::uint32_t>(&segment_count_, 1));
  return segment_count_;
}

void ParallelRegionGrowing::segment_on_host(std::span<const Eigen::Vector4f> lab,
                                            std::span<const Point4f> points,
                                            const RegionGrowingParams& params) {
  const std::uint32_t limit = squared_distance_limit(params.lab_threshold);
  const double depth_ratio = params.max_depth_jump;
  const std::size_t width = static_cast<std::size_t>(width_);
  const std::size_t rows = static_cast<std::size_t>(height_);
  const std::size_t pixels = lab.size();
  std::uint32_t* parent = parent_.host_span().data();
  std::uint8_t* edges = host_edges_.data();
  const HostPlanes q{host_codes_.data(), host_codes_.data() + pixels,
                     host_codes_.data() + 2 * pixels, host_depth_.data(), host_valid_.data()};

  // Links the tree of `root` (pixel i's, updated) with the one of valid pixel j; parent[j] is
  // often `root` already (rows are compressed to their roots as they are done).
  const auto link_to = [&](std::uint32_t& root, std::size_t j) {
    std::uint32_t other = parent[j];
    if (other == root) return;
    other = find_root(parent, other);
    if (other < root) {
      parent[root] = other;
      root = other;
    } else if (other > root) {
      parent[other] = root;
    }
  };

  // Per chunk of rows (threads: registration::detail::for_each_chunk): quantise a row, mark its
  // edges, then link each pixel with its joined left and upper neighbours inside the chunk.
  // Trees never leave their chunk here, so chunks do not race.
  std::array<std::size_t, registration::detail::kCpuChunks> chunk_first_rows{};
  registration::detail::for_each_chunk(
      rows, pixels, [&](std::size_t first_row, std::size_t end_row, std::size_t chunk) {
        chunk_first_rows[chunk] = first_row;
        for (std::size_t y = first_row; y < end_row; ++y) {
          const std::size_t row = y * width;
          quantise_pixels(lab.data(), points.data(), row, row + width, q, parent, edges);
          const bool up = y > first_row;
          mark_row_edges(q, limit, depth_ratio, row, width, true, up, edges);
          // `root` is the root of pixel i's tree while it is linked: no find for i itself, nor
          // for the left neighbour (its root, from the step before, is still a root). An upper
          // neighbour joined to one already linked is in that tree: skipped.
          std::uint32_t left_root = kNoLabel;
          for (std::size_t i = row; i < row + width; ++i) {
            const std::uint8_t bits = edges[i];
            if (bits == 0) {
              left_root = parent[i];  // itself, or kNoLabel
              continue;
            }
            std::uint32_t root = static_cast<std::uint32_t>(i);
            const bool left = bits & kLeft, above = bits & kUp;
            if (left) {
              parent[i] = left_root;
              root = left_root;
            }
            if (above) link_to(root, i - width);
            if ((bits & kUpLeft) && !(above && (edges[i - width] & kLeft)) &&
                !(left && (edges[i - 1] & kUp))) {
              link_to(root, i - width - 1);
            }
            if ((bits & kUpRight) && !(above && (edges[i - width + 1] & kLeft))) {
              link_to(root, i - width + 1);
            }
            parent[i] = root;
            left_root = root;
          }
        }
      });
  // The seams between chunks (each chunk's first row with the row above), sequentially.
  for (std::size_t chunk = 1; chunk < chunk_first_rows.size(); ++chunk) {
    const std::size_t y = chunk_first_rows[chunk];
    if (y == 0 || y >= rows || y == chunk_first_rows[chunk - 1]) continue;
    const std::size_t row = y * width;
    mark_row_edges(q, limit, depth_ratio, row, width, false, true, edges);
    for (std::size_t x = 0; x < width; ++x) {
      const std::size_t i = row + x;
      const auto i32 = static_cast<std::uint32_t>(i);
      if (edges[i] & kUpLeft) unite(parent, i32, static_cast<std::uint32_t>(i - width - 1));
      if (edges[i] & kUp) unite(parent, i32, static_cast<std::uint32_t>(i - width));
      if (edges[i] & kUpRight) unite(parent, i32, static_cast<std::uint32_t>(i - width + 1));
    }
  }

  // Number the roots in scan order. In increasing i, parent[i] <= i has already been resolved
  // to its root (set below), so root(i) = parent[parent[i]] in O(1).
  std::uint32_t* labels = labels_.host_span().data();
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    const std::uint32_t p = parent[i];
    if (p == kNoLabel) {
      labels[i] = kNoLabel;
      continue;
    }
    const std::uint32_t root = parent[p];
    parent[i] = root;
    labels[i] = root == i ? next++ : labels[root];
  }
  segment_count_ = next;
}

SegmentLabelImage ParallelRegionGrowing::download_labels() const {
  SegmentLabelImage image(width_, height_);
  labels_.download(image.pixels());
  return image;
}

SegmentLabelImage grow_regions_lab_parallel(const compute::Context& context, const LabImage& lab,
                                            const PointImage& points,
                                            const RegionGrowingParams& params) {
  ParallelRegionGrowing growing(context, lab.width(), lab.height());
  growing.segment(lab, points, params);
  return growing.download_labels();
}

}  // namespace kartograf::segmentation
