#include "semantic/grid_phantoms.hpp"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>

#include "kartograf/core/memory_budget.hpp"

namespace kartograf::semantic::detail {

namespace {

// Band points by voxel (the free space's), saturating.
class VoxelHits {
 public:
  VoxelHits(const SemanticGrid& grid, const BandFreeSpace& free_space)
      : grid_(grid), free_space_(free_space), hits_(checked_size(grid, free_space), 0) {}

  void add(const Eigen::Vector3d& p) {
    const std::optional<std::size_t> v = voxel(p);
    if (v && hits_[*v] < std::numeric_limits<std::uint16_t>::max()) ++hits_[*v];
  }
  int at(const Eigen::Vector3d& p) const {
    const std::optional<std::size_t> v = voxel(p);
    return v ? hits_[*v] : 0;
  }

 private:
  static std::size_t checked_size(const SemanticGrid& grid, const BandFreeSpace& free_space) {
    require_fits_in_memory(static_cast<double>(free_space.voxel_count()) * sizeof(std::uint16_t),
                           "build_semantic_grid: the phantom points' counts for a grid of " +
                               std::to_string(grid.width()) + " x " +
                               std::to_string(grid.height()) + " cells");
    return free_space.voxel_count();
  }
  std::optional<std::size_t> voxel(const Eigen::Vector3d& p) const {
    return free_space_.voxel(grid_.cell_of(p.head<2>()), p.z() - grid_.floor_z);
  }

  const SemanticGrid& grid_;
  const BandFreeSpace& free_space_;
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
  VoxelHits hits(grid, free_space);
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
