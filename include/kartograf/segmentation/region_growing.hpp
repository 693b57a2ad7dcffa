#pragma once
// Over-segmentation by region growing in CIE-Lab, docs/methods.md M1 step 2: pixels are scanned in
// order; each unlabelled valid pixel seeds a segment grown with an explicit stack over
// 8-neighbours, accepting a pixel while its Lab distance to the segment's running mean colour
// (paper eq. 5) stays under a threshold.
//
// The mean is kept exactly, as the integer sum of the segment's Lab codes (1/64 units, see
// LabCode) and its pixel count: a pixel c joins a segment of n pixels with code sum S when
// |n c - S|^2 < (T n)^2, T the threshold in codes (rounded to 1/64 Lab unit). The depth test
// compares exact double values of float depths. So the result depends on nothing but the input,
// and every backend returns the same labels.
//
// Tiles (tile_size > 0) bound segments to tile_size x tile_size blocks of pixels. They are also
// what makes the growing parallel: each tile is the paper's sequential growing on its own, so
// tiles run on separate CPU threads, or one GPU work-item each (Vulkan, OpenCL; tiles of at most
// kMaxDeviceTileSize pixels), with the same labels as the sequential scan of the tiles. Without
// tiles (the paper), or with larger ones, RegionGrower grows on the host. The passes (one rule,
// one wrapper per backend) are in kernels/region_grow/.
#include <cstdint>
#include <vector>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/image.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/geometry/segment_moments.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/segmentation/segment_graph.hpp"

namespace kartograf::segmentation {

// SegmentLabelImage (segment_graph.hpp): segment id per pixel, geometry::kNoLabel where the
// pixel has no point or no colour. Segments are numbered 0..n-1 by tile (tiles in row-major
// order; the whole image is one tile without tiling), then by the scan order of their seeds
// within the tile.

inline constexpr int kMaxDeviceTileSize = 64;

struct RegionGrowingParams {
  float lab_threshold = 15.0f;  // Euclidean Lab distance to the running mean (the paper's value)
  // Depth-aware variant (0 = off, the paper): reject a pixel whose depth differs from the
  // neighbour it was reached from by more than this fraction of that neighbour's depth.
  float max_depth_jump = 0.0f;
  // Tiled variant (0 = off, the paper): segments never cross the borders of tile_size x tile_size
  // pixel tiles. Colour alone cannot see a crease between two walls of one colour; small pieces
  // keep such a segment from spanning both, and the merging step joins the pieces again.
  int tile_size = 0;

  void validate() const;  // throws Error naming the first bad field
};

// What the growing also measures of each segment as it grows (one pass for all).
struct SegmentStatistics {
  std::vector<Eigen::Vector3f> colours;  // mean Lab colour
  // With a moments origin (rounded to float): each segment's moments about it, summed in double
  // in the order the segment grew (so the same for any thread count; within rounding of the
  // fixed-point sums of geometry::SegmentMomentReducer).
  std::vector<geometry::SegmentMoments> moments;
};

// The CPU reference. lab and points have the same size; labels is resized to it. statistics,
// when given, receives each segment's colour and, with `moments_origin`, its moments. Returns the
// segment count. Runs the tiles on KARTOGRAF_CPU_THREADS threads (nothing depends on the count).
// Throws Error on a size mismatch or bad parameters.
std::uint32_t grow_regions(const LabCodeImage& lab, const PointImage& points,
                           const RegionGrowingParams& params, SegmentLabelImage& labels,
                           SegmentStatistics* statistics = nullptr,
                           const Eigen::Vector3d* moments_origin = nullptr);

// Convenience: float Lab in, labels out.
SegmentLabelImage grow_regions_lab(const LabImage& lab, const PointImage& points,
                                   const RegionGrowingParams& params);

// Number of segments in a compact label image (largest label + 1; 0 when every pixel is kNoLabel).
std::uint32_t segment_count(const SegmentLabelImage& labels);

// The growing on a context's backend, leaving the labels on the device for the per-segment
// moments (geometry::SegmentMomentReducer). Keeps its device buffers between frames.
class RegionGrower {
 public:
  explicit RegionGrower(const compute::Context& context);

  // lab (host) and points (on this context, row-major) are width x height. Returns the segment
  // count; one host wait. colours as in grow_regions. Throws Error on a size mismatch or bad
  // parameters.
  std::uint32_t grow(const LabCodeImage& lab, const compute::Buffer<Point4f>& points,
                     const RegionGrowingParams& params,
                     std::vector<Eigen::Vector3f>* colours = nullptr);
  // The same with statistics (and moments about moments_origin) as grow_regions measures them:
  // the same values on every backend, up to the devices' double rounding of the moments.
  std::uint32_t grow(const LabCodeImage& lab, const compute::Buffer<Point4f>& points,
                     const RegionGrowingParams& params, SegmentStatistics* statistics,
                     const Eigen::Vector3d* moments_origin);

  // The labels of the last grow(), on the device, and as an image.
  const compute::Buffer<std::uint32_t>& labels() const { return labels_; }
  SegmentLabelImage download_labels() const;

 private:
  std::uint32_t grow_tiles(const LabCodeImage& lab, const compute::Buffer<Point4f>& points,
                           const RegionGrowingParams& params, SegmentStatistics* statistics,
                           const Eigen::Vector3d* moments_origin);

  const compute::Context* context_;
  int width_ = 0;
  int height_ = 0;
  compute::Buffer<std::uint32_t> labels_;
  compute::Buffer<LabCode> lab_;
  compute::Buffer<std::uint32_t> tile_counts_;  // segments per tile, then their prefix sums
  compute::Buffer<std::uint32_t> stacks_;       // one growing stack per tile
  compute::Buffer<std::uint32_t> status_;       // [0]: segment count, [1]: stack overflows
  compute::Buffer<double> slots_;               // measuring: statistics per (tile, segment)
  compute::Buffer<double> statistics_;          // measuring: statistics in label order
  std::vector<double> host_statistics_;         // scratch: the statistics downloaded
  std::vector<Point4f> host_points_;            // untiled: the points grown on the host
  std::vector<std::uint32_t> host_labels_;      // untiled: the labels grown on the host
};

}  // namespace kartograf::segmentation
