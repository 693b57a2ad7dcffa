#pragma once
// The points of one class in the robot's height band, by grid cell: the semantic grid's steps
// that measure surfaces finer than the cells (doorway jambs, wall faces, door leaves' faces) read
// them here.
#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic::detail {

class BandPointIndex {
 public:
  // Indexes the points labelled `indexed` whose height above grid.floor_z lies in the options'
  // band.
  BandPointIndex(const SemanticGrid& grid, std::span<const Eigen::Vector3d> points,
                 std::span<const SemanticClass> labels, const SemanticGridParams& options,
                 SemanticClass indexed = SemanticClass::wall);
  // The indexed points (x, y) in cell c, which must lie in the grid.
  std::span<const Eigen::Vector2d> in_cell(const Eigen::Vector2i& c) const;

 private:
  int width_;
  std::vector<std::size_t> start_;  // compressed rows: cell k's points are [start_[k], start_[k+1])
  std::vector<Eigen::Vector2d> points_;
};

}  // namespace kartograf::semantic::detail
