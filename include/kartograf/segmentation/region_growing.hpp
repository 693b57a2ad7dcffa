#pragma once
// Over-segmentation by region growing in CIE-Lab, the CPU reference of methods.md M1 step 2:
// pixels are scanned in order; each unlabelled valid pixel seeds a segment grown with an explicit
// stack over 8-neighbours, accepting a pixel while its Lab distance to the segment's running mean
// colour (paper eq. 5) stays under a threshold.
#include <cstdint>

#include "kartograf/core/image.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/geometry/segment_moments.hpp"
#include "kartograf/segmentation/lab_color.hpp"

namespace kartograf::segmentation {

// Segment id per pixel: 0..n-1 in the order their seeds were scanned, geometry::kNoLabel where the
// pixel has no point.
using SegmentLabelImage = Image<std::uint32_t>;

struct RegionGrowingParams {
  float lab_threshold = 15.0f;  // Euclidean Lab distance to the running mean (the paper's value)
  // Depth-aware variant (0 = off, the paper): reject a pixel whose depth differs from the
  // neighbour it was reached from by more than this fraction of that neighbour's depth.
  float max_depth_jump = 0.0f;
  // Tiled variant (0 = off, the paper): segments never cross the borders of tile_size x tile_size
  // pixel tiles. Colour alone cannot see a crease between two walls of one colour; small pieces
  // keep such a segment from spanning both, and the merging step joins the pieces again.
  int tile_size = 0;
};

// lab and points have the same size; a pixel with a NaN point never joins a segment. Deterministic.
// Throws Error on a size mismatch or a non-positive threshold.
SegmentLabelImage grow_regions_lab(const LabImage& lab, const PointImage& points,
                                   const RegionGrowingParams& params);

// Number of segments in a compact label image (largest label + 1; 0 when every pixel is kNoLabel).
std::uint32_t segment_count(const SegmentLabelImage& labels);

}  // namespace kartograf::segmentation
