#include "semantic/grid_phantoms.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "kartograf/core/memory_budget.hpp"

namespace kartograf::semantic::detail {

namespace {

std::size_t voxel_count(const SemanticGrid& grid) {
  const double voxels = static_cast<double>(grid.width()) * grid.height() * BandFreeSpace::kSlabs;
  require_fits_in_memory(voxels * sizeof(std::uint16_t),
                         "build_semantic_grid: the phantom points' counts for a grid of " +
                             std::to_string(grid.width()) + " x " + std::to_string(grid.height()) +
                             " cells");
  return static_cast<std::size_t>(voxels);
}

// Band points by voxel (the free space's cells and slabs), saturating.
class VoxelHits {
 public:
  VoxelHits(const SemanticGrid& grid, const SemanticGridParams& options)
      : grid_(grid), options_(options), hits_(voxel_count(grid), 0) {}

  // The voxel's index, or none outside the grid and the slabs.
  std::ptrdiff_t index(const Eigen::Vector3d& p) const {
    const Eigen::Vector2i c = grid_.cell_of(p.head<2>());
    const double slab =
        std::floor((p.z() - grid_.floor_z - options_.band_min) / options_.free_space_slab);
    if (!grid_.contains(c) || !(slab >= 0 && slab < BandFreeSpace::kSlabs)) return -1;
    return (static_cast<std::ptrdiff_t>(c.y()) * grid_.width() + c.x()) * BandFreeSpace::kSlabs +
           static_cast<std::ptrdiff_t>(slab);
  }
  void add(const Eigen::Vector3d& p) {
    const std::ptrdiff_t i = index(p);
    if (i >= 0 && hits_[static_cast<std::size_t>(i)] < std::numeric_limits<std::uint16_t>::max())
      ++hits_[static_cast<std::size_t>(i)];
  }
  int at(const Eigen::Vector3d& p) const {
    const std::ptrdiff_t i = index(p);
    return i >= 0 ? hits_[static_cast<std::size_t>(i)] : 0;
  }

 private:
  const SemanticGrid& grid_;
  const SemanticGridParams& options_;
  std::vector<std::uint16_t> hits_;
};

// The fewest rays through the voxel of p and those `margin` beside it in x and y.
int fewest_passes(const SemanticGrid& grid, const BandFreeSpace& free_space,
                  const Eigen::Vector3d& p, double margin) {
  const double height = p.z() - grid.floor_z;
  int fewest = free_space.passes(grid.cell_of(p.head<2>()), height);
  for (const double dx : {-margin, margin}) {
    for (const double dy : {-margin, margin}) {
      const Eigen::Vector2i c = grid.cell_of(p.head<2>() + Eigen::Vector2d(dx, dy));
      if (grid.contains(c)) fewest = std::min(fewest, free_space.passes(c, height));
    }
  }
  return fewest;
}

}  // namespace

std::vector<std::uint8_t> phantom_points(const SemanticGrid& grid,
                                         std::span<const Eigen::Vector3d> points,
                                         std::span<const SemanticClass> labels,
                                         const BandFreeSpace& free_space,
                                         const SemanticGridParams& options) {
  const auto in_band = [&](std::size_t i) {
    const double h = points[i].z() - grid.floor_z;
    return points[i].allFinite() && labels[i] != SemanticClass::floor &&
           labels[i] != SemanticClass::ceiling && h >= options.band_min && h <= options.band_max;
  };
  VoxelHits hits(grid, options);
  for (std::size_t i = 0; i < points.size(); ++i)
    if (in_band(i)) hits.add(points[i]);
  std::vector<std::uint8_t> phantom(points.size(), 0);
  const double stride = options.free_space_ray_stride;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!in_band(i) || labels[i] == SemanticClass::wall || labels[i] == SemanticClass::door)
      continue;
    const int passes = fewest_passes(grid, free_space, points[i], options.phantom_margin);
    phantom[i] = passes * stride > options.phantom_pass_ratio * hits.at(points[i]);
  }
  return phantom;
}

}  // namespace kartograf::semantic::detail
