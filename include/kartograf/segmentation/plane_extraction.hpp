#pragma once
// Plane extraction from one organized RGB-D frame, docs/methods.md M1 steps 2-4: Lab region growing
// (over-segmentation) with per-segment moments on the context's backend and plane fits, merging of
// neighbouring segments, and the output planes with a per-pixel plane id image.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/segmentation/plane_merge.hpp"
#include "kartograf/segmentation/region_growing.hpp"

namespace kartograf::segmentation {

enum class PlaneExtractionMode : std::uint8_t {
  // docs/methods.md M1: CIE-Lab region growing over pixels, segment plane fits, merging (the
  // paper's method; the reference for docs/planes.md's tables).
  regions,
  // Depth first: square cells whose points are planar become the segments merging joins
  // (colour decides only whether planes apart are one surface); pixels are assigned per cell,
  // tested one by one only in cells at a plane's border (docs/planes.md "Cells").
  cells,
};

// The cells mode's cells and their planarity test.
struct CellPlaneParams {
  // Pixels a side, 4..64 (even: a cell is 2 x 2 blocks, tested when it is not planar).
  int cell_size = 16;
  // A cell is planar when at least this share of its pixels is valid, ...
  double min_valid_fraction = 0.2;
  // ... its depth is continuous (neighbouring pixels jump by more than growing.max_depth_jump of
  // their depth z and more than jump_per_z2 z^2 [1/m] at most cell_size / 2 times: far away, a
  // structured-light sensor's noise and quantization alone exceed the relative part), and the RMS
  // distance of its points to their plane is within rms_base + rms_per_z2 z^2 [m] (z: the
  // cell's mean depth; the depth noise and quantization of a structured-light sensor grow as z^2).
  double rms_base = 0.0015;
  double rms_per_z2 = 0.0025;
  double jump_per_z2 = 0.008;
  // The per-z^2 terms hold at this focal length [px] and scale with reference_focal / fx: a
  // structured-light sensor's disparity step is z^2 / (f b) in depth, so a coarser image of it
  // (a smaller f) is noisier per pixel. (A finer sensor subsampled keeps its own noise: the
  // scaling then only makes the tests more lenient.)
  double reference_focal = 525.0;
  // Passes of the pixel assignment: the first reaches the cells next to a plane's cells, each
  // further one a ring of cells further (around objects, across gaps of no depth).
  int reach_passes = 4;
  // Then connected regions of valid pixels that no plane reached (thin poles, strips narrower than
  // a cell) become planes of their own when they are planar, as in the regions mode (8-connected
  // here). Costs ~0.5 ms a 7-Scenes frame; off: faster, fewer pixels on planes.
  bool leftover_planes = true;

  void validate() const;  // throws Error naming the first bad field
};

struct PlaneExtractionParams {
  PlaneExtractionMode mode = PlaneExtractionMode::regions;
  CellPlaneParams cells;
  // The paper's Lab growing (threshold 15) with two variants on, tuned on synthetic Kinect frames:
  // 16 px tiles (a segment cannot span a crease between two planes of one colour) and a 2 %
  // depth-jump test (nor an occlusion edge or a step: a table leg set 4 cm back from the top's
  // edge at 1.5 m).
  RegionGrowingParams growing{.lab_threshold = 15.0f, .max_depth_jump = 0.02f, .tile_size = 16};
  PlaneMergeParams merge;
  std::uint64_t min_plane_pixels = 300;  // smaller merged planes are dropped (their pixels: 0)
  // Pixels along plane borders (in segments left out of every plane, or touching another plane's
  // segments) go to the nearest plane among their own and the neighbouring segments', within the
  // merge distance allowance: mixed segments along edges and creases are split between planes.
  // Then planes grow pixel by pixel into the valid pixels no plane took, within the allowance
  // and without crossing a depth jump (growing.max_depth_jump).
  bool refine_pixels = true;

  void validate() const;  // throws Error naming the first bad field
};

// A plane n . p + offset = 0 in the camera frame, n of unit length towards the camera (offset > 0
// for planes not through the camera centre).
struct Plane {
  Label id = 0;  // 1..n, by decreasing pixel count
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double offset = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  // Extent: the bounding box of the plane's points in the in-plane frame (centroid; major_axis,
  // minor_axis), i.e. coordinates (p - centroid) . axis between extent_min and extent_max.
  Eigen::Vector3d major_axis = Eigen::Vector3d::Zero();
  Eigen::Vector3d minor_axis = Eigen::Vector3d::Zero();
  Eigen::Vector2d extent_min = Eigen::Vector2d::Zero();
  Eigen::Vector2d extent_max = Eigen::Vector2d::Zero();
  std::uint64_t inlier_count = 0;  // pixels labelled with this plane
  double rms_error = 0;            // RMS point-plane distance of those pixels [m]
  // (The plane is fitted to its merged segments; refined pixels count in inlier_count, rms_error
  // and the extent but not in the fit.)
};

struct PlaneExtractionTimings {  // milliseconds, host wall clock
  double lab = 0;
  double growing = 0;  // with the moments, summed as the segments grow
  double moments = 0;  // (0: the moments are summed by the growing)
  double merging = 0;
  double refinement = 0;  // border pixels, growth into left-over pixels, left-over planes
  double output = 0;      // plane records and the label image
  double total() const { return lab + growing + moments + merging + refinement + output; }
};

struct PlaneSet {
  std::vector<Plane> planes;        // planes[i].id == i + 1
  LabelImage labels;                // plane id per pixel, 0 = none
  std::uint32_t segment_count = 0;  // segments of the over-segmentation
  std::uint32_t merged_count = 0;   // merged planes before the size filter
  PlaneExtractionTimings timings;
};

// One plane per segment of any segmentation (e.g. the clustering baselines of
// docs/methods.md M1 step 7): the total-least-squares fit of its points (fit_plane); segments
// without a valid fit or with fewer than min_pixels points get no plane. Plane ids follow the
// segment order; the label image gives each pixel its segment's plane (0: none). Throws Error on a
// size mismatch or a label >= segment_count.
PlaneSet fit_segment_planes(const PointImage& points, const SegmentLabelImage& segments,
                            std::uint32_t segment_count, std::uint64_t min_pixels = 3);

namespace detail {
struct CellGrid;        // src/segmentation/cell_planes.hpp
struct PlanePixelSums;  // src/segmentation/plane_output.hpp
}  // namespace detail

// The cells mode's buffers on the context (src/segmentation/cell_planes.hpp, measure_cells and
// assign_cell_pixels): the colour image, and per block its float sums, counts and validity bits;
// off the CPU backend, the pixel scores' planes, jobs, candidates and results (grown as needed,
// kept from frame to frame).
struct CellBuffers {
  compute::RawBuffer colours;
  compute::Buffer<float> sums;
  compute::Buffer<std::uint32_t> counts, masks;
  compute::Buffer<Eigen::Vector4f> score_planes;
  compute::Buffer<std::uint32_t> score_jobs, score_candidates, score_choices;
  compute::Buffer<float> score_distances;
};

class PlaneExtractor {
 public:
  // Throws Error on invalid intrinsics or parameters.
  PlaneExtractor(const compute::Context& context, const PinholeIntrinsics& intrinsics,
                 const PlaneExtractionParams& params = {});

  // points (camera frame, NaN where invalid) and rgb have the intrinsics' size. Deterministic.
  // Throws Error on a size mismatch or an empty point image. The cells mode also takes a depth
  // camera's frame without colour (rgb empty): planes apart are then joined on their geometry
  // alone, where the view between them shows no surface in front (see-through test); the
  // regions mode grows colour regions and throws Error naming the missing colour.
  PlaneSet extract(const PointImage& points, const RgbImage& rgb);

  const PlaneExtractionParams& params() const { return params_; }

 private:
  const compute::Context* context_;
  PinholeIntrinsics intrinsics_;
  PlaneExtractionParams params_;
  // Grows the frame's segments (segments_, statistics_' colours) with their moments about
  // moments.origin; returns the segment count.
  std::uint32_t grow_segments(const PointImage& points, geometry::SegmentMomentSet& moments);
  // pixel_plane_: each pixel's merged plane, refined (params_.refine_pixels).
  void assign_pixels(const PointImage& points, MergedPlanes& merged);
  PlaneSet extract_regions(const PointImage& points, const RgbImage& rgb);
  PlaneSet extract_cells(const PointImage& points, const RgbImage& rgb);
  void add_leftover_planes(const PointImage& points, const detail::CellGrid& cells,
                           std::vector<SegmentPlane>& planes,
                           std::vector<detail::PlanePixelSums>& sums);

  RegionGrower grower_;
  compute::Buffer<Point4f> points_;             // the frame's points on the context
  LabCodeImage lab_;                            // the frame's colours (host)
  SegmentLabelImage segments_;                  // the frame's segments (host)
  std::vector<std::uint32_t> pixel_plane_;      // scratch: merged plane per pixel
  std::vector<std::uint32_t> flood_queue_;      // scratch: pixels to grow planes from
  std::vector<std::uint8_t> flood_sources_;     // scratch: which pixels start the growth
  std::vector<std::uint32_t> leftover_pixels_;  // scratch: pixels of the leftover regions
  std::vector<std::uint32_t> open_cells_;       // scratch: cells with pixels no plane took
  SegmentStatistics statistics_;                // scratch: colours and moments per segment
  CellBuffers cell_buffers_;                    // the cells mode's pass on the context
  RgbImage no_colour_;  // what the cells' pass reads for a frame without colour (black)
};

}  // namespace kartograf::segmentation
