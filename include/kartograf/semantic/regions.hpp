#pragma once
// Segmentation of an organized point image into smooth surface regions (docs/methods.md M2 step 2)
// and their 3-D measurements.
//
// Region growing (flood fill, 4-neighbours, seeds in raster order): a pixel joins the region of a
// neighbour (the nearest pixel with a point in each of the 4 directions, across at most
// max_gap_pixels pixels without one) when both have normals, the angle between the two normals is
// at most max_neighbour_angle_deg, the angle to the region's running mean normal is at most
// max_region_angle_deg, and their ranges (distances to the sensor at the origin) differ by at most
// max_relative_range_jump times the smaller one. Regions with fewer than min_region_pixels pixels
// are dropped (label 0). Labels are 1..count in order of their seed.
//
// Regions are also dropped when their points do not span a plane whose normal (PCA: the spread
// across it at most 1/min_plane_spread_ratio of the spread along its second axis) is within
// max_region_angle_deg of their mean normal: where normals are noise (see below) they still group
// into regions, but not into the plane their points lie on.
//
// Then a fill: pixels with a point but no region (normals too noisy - Kinect disparity steps far
// away, a tilting laser scanner's rows converging at +-90 degrees azimuth - or a seam at a crease)
// join a neighbouring region, breadth first from all regions at once, when their distance to that
// region's plane (centroid, mean normal) is at most fill_plane_distance + fill_relative_distance x
// range and the range is continuous. Planes keep their pixels; only what normals could not decide
// is filled.
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/label_image.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::semantic {

struct RegionParams {
  double max_neighbour_angle_deg = 30.0;
  double max_region_angle_deg = 25.0;
  double max_relative_range_jump = 0.04;
  int min_region_pixels = 50;
  double min_plane_spread_ratio = 10.0;
  double fill_plane_distance = 0.01;      // m
  double fill_relative_distance = 0.008;  // x range
  double fill_quadratic_distance = 0.0;   // x range^2 [1/m]
  // Neighbours are looked for across up to this many pixels without a point (sparse returns).
  int max_gap_pixels = 2;
};

struct RegionSegmentation {
  LabelImage labels;  // 0: no region
  int region_count = 0;
};

// Throws Error when points and normals differ in size or the parameters are out of range.
RegionSegmentation segment_regions(const PointImage& points, const NormalImage& normals,
                                   const RegionParams& params = {});

// Merges adjacent regions that lie in one plane: noisy normals (a dark surface with sparse
// returns, far Kinect depth) break one surface into several regions that the rules would measure
// one by one, too small for a wall or a door. Two regions are adjacent when a pixel of one is at
// most max_gap_pixels unlabelled pixels right of or below a pixel of the other; they merge when
// their fitted planes (PCA of their points, merged moments after each merge) are within
// max_angle_deg and each centroid lies within max_offset of the other's plane. max_offset stays
// below LayerSplitParams::min_offset so a door leaf (5 cm off its wall) never merges into it.
// Labels are renumbered 1..count in order of their smallest old label. Returns the merges made.
struct CoplanarMergeParams {
  double max_angle_deg = 10.0;
  double max_offset = 0.02;  // m
  int max_gap_pixels = 3;
};

int merge_coplanar_regions(const PointImage& points, RegionSegmentation& regions,
                           const CoplanarMergeParams& params = {});

// Splits layers off regions: pixels of a region lying more than min_offset in front of or behind
// the region's plane (offset: the median of n . p over the region, n its mean normal) form
// 4-connected components; those of at least min_pixels become new regions (labels after the
// existing ones). A door leaf standing open flat against a wall is 5 cm in front of it: too close
// for a range-jump test and, at a laser's 0.5 degree steps, too smooth a step for the normals once
// smoothed, but plain in the offsets of smoothed points (pass smooth_organized_points' output).
struct LayerSplitParams {
  double min_offset = 0.025;  // m
  int min_pixels = 50;
  // label_organized_points smooths the points for the offsets over (2r + 1)^2 pixels: narrower
  // than the normals' window, which blurs a 5 cm step into a band that stays with the leaf.
  int smoothing_radius = 2;
};

// Returns, for each region added, the region it was split from. Throws Error when the sizes differ.
std::vector<Label> split_offset_layers(const PointImage& smoothed_points,
                                       const NormalImage& normals, RegionSegmentation& regions,
                                       const LayerSplitParams& params = {});

enum class RegionOrientation : std::uint8_t { horizontal, vertical, other };

// Measurements of one region; heights are along `up` (metres, relative to the sensor origin).
struct RegionMeasurements {
  Label id = 0;
  int pixel_count = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_normal = Eigen::Vector3d::Zero();  // unit; faces the sensor
  // The normal of the plane fitted to the points (PCA), turned like mean_normal: averages out depth
  // noise that biases per-pixel normals, for offsets between planes.
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Zero();
  RegionOrientation orientation = RegionOrientation::other;
  double min_height = 0, max_height = 0;  // trimmed extremes of p . up
  // Horizontal extent: along up x normal for a vertical region (its in-plane horizontal axis),
  // along the major horizontal principal axis otherwise (trimmed extremes).
  double width = 0;
  // Square metres: over pixels whose right and lower neighbours are in the region, the
  // parallelogram they span projected on mean_normal (the area between pixel centres; projection
  // keeps depth noise from inflating it).
  double area = 0;
  // The region touches the image border or a pixel without a point: part of the surface may be
  // out of view (above, below, or beside the visible part).
  bool cut_above = false, cut_below = false, cut_sideways = false;
  // The region borders a nearer surface (occluder_relative_range x range nearer: furniture in
  // front of a wall) at its top, bottom or side: it may go on behind it.
  bool occluded_above = false, occluded_below = false, occluded_sideways = false;
  // How far in front of the region's plane the surface that hides its top stands (m, median over
  // its top's pixels; 0 when nothing hides it): a table's edge before a wall, a shelf's board
  // before its back.
  double occluder_offset_above = 0;
  std::vector<Label> neighbours;  // regions within adjacency_radius pixels, ascending

  double height() const { return max_height - min_height; }
};

struct MeasureParams {
  double horizontal_tolerance_deg = 15.0;  // normal within this of +-up: horizontal
  double vertical_tolerance_deg = 15.0;    // normal within this of perpendicular to up: vertical
  double trim_fraction = 0.01;             // extremes ignore this fraction of points at each end
  int adjacency_radius = 4;                // pixels; bridges the unlabelled seam at creases
  double occluder_relative_range = 0.04;   // a neighbour this much nearer (x range) hides a cut
  // Missing depth (dropouts, occluding edges, grazing surfaces) up to this fraction of the image's
  // size, with a surface on or behind the region's plane beyond it, does not cut the region;
  // wider gaps, the image border, or a nearer surface beyond (hiding it) do.
  double max_gap_fraction = 1.0;
};

// One entry per region, index = label - 1. `up` must be a unit vector.
std::vector<RegionMeasurements> measure_regions(const PointImage& points,
                                                const NormalImage& normals,
                                                const RegionSegmentation& regions,
                                                const Eigen::Vector3d& up,
                                                const MeasureParams& params = {});

}  // namespace kartograf::semantic
