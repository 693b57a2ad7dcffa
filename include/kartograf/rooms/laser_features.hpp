#pragma once
// Simulated laser scans in an occupancy grid and the geometric scan features of O. Martinez Mozos
// et al. ("Supervised semantic labeling of places using information extracted from sensor data",
// RAS 2007) that the feature-based room segmentation classifies (methods.md M4 step 4; the
// reference, ipa_room_segmentation's features.cpp, computes 23 of them; we add 4 more that are
// cheap: compactness, shortest and longest beam, offset of the scan area's centroid).
//
// A scan is cast from the centre of a free cell with `beams` beams at equal angles (360: 1-degree
// steps as the reference), beam k at angle 360 k / beams degrees counter-clockwise from the map's
// +x axis (image columns to the right, rows up). Like the reference, a beam samples its ray at
// whole-cell steps: its length is the first step k (in cells) whose sample falls into a cell that
// is not free, or outside the grid; beams that reach max_range_m stop there.
//
// Rays march by sphere tracing over the free space's Euclidean distance transform: from a sample
// whose cell lies d cells from the nearest non-free cell centre, the next d - 1.5 steps (at least
// 1) cannot reach a non-free cell, so they are skipped. The result is the same as stepping one
// cell at a time.
#include <array>
#include <cstddef>
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
  // Throws Error for an empty map, a resolution <= 0, beams < 8 or max_range_m <= 0.
  explicit LaserScanner(const OccupancyGrid& map, const LaserScanParams& params = {});

  int beams() const { return static_cast<int>(cos_.size()); }
  double resolution() const { return resolution_; }

  // Beam lengths [m] from the centre of cell (col, row); ranges.size() must be beams(). A cell that
  // is not free (or outside the grid) gives all zeros.
  void scan(int col, int row, std::span<double> ranges) const;

 private:
  int width_ = 0, height_ = 0;  // of the map; `clearance_` has a border of one cell around it
  double resolution_ = 0.05;
  int max_steps_ = 0;
  Image<float> clearance_;  // cells to the nearest non-free cell centre; 0 on non-free cells
  std::vector<double> cos_, sin_;
};

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
