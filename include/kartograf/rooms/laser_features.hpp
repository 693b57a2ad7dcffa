#pragma once
// Simulated laser scans in an occupancy grid and the geometric scan features of O. Martinez Mozos
// et al. ("Supervised semantic labeling of places using information extracted from sensor data",
// RAS 2007) that the feature-based room segmentation classifies (docs/methods.md M4 step 4; the
// reference, ipa_room_segmentation's features.cpp, computes 23 of them; we add 4 more that are
// cheap: compactness, shortest and longest beam, offset of the scan area's centroid).
//
// A scan is cast from the centre of a free cell with `beams` beams at equal angles (360: 1-degree
// steps as the reference), beam k at angle 360 k / beams degrees counter-clockwise from the map's
// +x axis (image columns to the right, rows up). Like the reference, a beam samples its ray at
// whole-cell steps: its length is the first step k (in cells) whose sample falls into a cell that
// is not free, or outside the grid; beams that reach max_range_m stop there.
//
// Samples are exact integer arithmetic, so that the CPU and the device backends
// (laser_scan_device.hpp) agree bit for bit: beam k's direction is (cos, -sin) of its angle in
// image axes, rounded once (in double) to 1/65536 cell; sample `step` lies at the cell centre's
// fixed-point position plus step times that direction, and its cell is the position shifted right
// by 16 bits. Against the earlier scan with directions in double, 66,081 of the 115.8 million beams
// from every free cell of office_e change (5.7e-4; 89 % of them by one step): samples within
// ~1e-3 cell of a cell edge, and exact ties such as beam 240 (cos 240 deg is -0.5 exactly here,
// -0.5000000000000004 in double), which alone accounts for 22,406.
//
// Rays march by sphere tracing over the free space's Euclidean distance transform: from a sample
// whose cell lies d cells from the nearest non-free cell centre, the next d - 1.5 steps (at least
// 1) cannot reach a non-free cell, so they are skipped. The skips are an integer image computed
// once per map; the result is the same as stepping one cell at a time.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "kartograf/core/image.hpp"
#include "kartograf/core/occupancy_grid.hpp"

namespace kartograf::rooms {

struct LaserScanParams {
  int beams = 360;
  double max_range_m = 50.0;
};

class LaserScanner {
 public:
  // Throws Error for an empty map, a map wider or higher than kMaxLaserScanMapSide cells, a
  // resolution <= 0, beams < 8 or max_range_m <= 0.
  explicit LaserScanner(const OccupancyGrid& map, const LaserScanParams& params = {});

  int beams() const { return static_cast<int>(directions_.size() / 2); }
  double resolution() const { return resolution_; }
  int map_width() const { return width_; }
  int map_height() const { return height_; }
  // The most steps a beam takes: ceil(max_range_m / resolution).
  int max_steps() const { return max_steps_; }

  // Beam lengths [m] from the centre of cell (col, row); ranges.size() must be beams(). A cell that
  // is not free (or outside the grid) gives all zeros. ranges[k] = steps[k] * resolution().
  void scan(int col, int row, std::span<double> ranges) const;
  // The same scan as whole steps (cells), at most max_steps().
  void scan_steps(int col, int row, std::span<std::int32_t> steps) const;

  // What a device implementation of the scan needs (laser_scan_device.hpp).
  // Per cell of the padded grid ((map_width() + 2) x (map_height() + 2), map cell (c, r) at
  // (c + 1, r + 1), a ring of non-free cells around the map): 0 where the cell is not free, else
  // the steps a beam may advance from a sample in it without passing a non-free cell,
  // max(1, (int)(d - 1.5f)) for its distance d [cells, float] to the nearest non-free cell centre
  // (at most 4096, so that direction rounding cannot matter; see the .cpp).
  const Image<std::int32_t>& skips() const { return skips_; }
  // Beam k's direction at [2k] (x, image columns) and [2k + 1] (y, image rows, downwards), in
  // 1/65536 cell per step.
  std::span<const std::int32_t> directions() const { return directions_; }

 private:
  int width_ = 0, height_ = 0;  // of the map; `skips_` has a border of one cell around it
  double resolution_ = 0.05;
  int max_steps_ = 0;
  Image<std::int32_t> skips_;
  std::vector<std::int32_t> directions_;
};

// Fixed-point sample positions in the padded grid must stay below 2^31: (side + 2) * 2^16 < 2^31.
inline constexpr int kMaxLaserScanMapSide = 32765;

inline constexpr std::size_t kLaserFeatureCount = 27;
using LaserFeatures = std::array<float, kLaserFeatureCount>;

struct LaserFeatureParams {
  double gap_m = 0.5;         // consecutive beams differing by more are a gap (Mozos et al.)
  double clip_m = 5.0;        // beams clipped to this for the clipped differences
  double relative_gap = 0.5;  // consecutive beams whose ratio (short / long) is below are a gap
};

// The names of the features, in order (e.g. "mean_beam", "polygon_area").
const std::array<std::string_view, kLaserFeatureCount>& laser_feature_names();

// The features of one scan: beams at equal angles as LaserScanner gives them (lengths [m], at
// least 8, all > 0). Throws Error otherwise. Lengths, areas and perimeters are in metres.
LaserFeatures laser_scan_features(std::span<const double> ranges,
                                  const LaserFeatureParams& params = {});

}  // namespace kartograf::rooms
