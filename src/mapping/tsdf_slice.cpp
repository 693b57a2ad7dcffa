#include "kartograf/mapping/tsdf_slice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/geometry/distance_transform.hpp"

namespace kartograf::mapping {

namespace {

// The centres of the surface voxels, in the level frame.
std::vector<Eigen::Vector3d> surface_points(const TsdfBlocks& blocks,
                                            const TsdfSliceParams& params) {
  std::vector<Eigen::Vector3d> out;
  const double near = blocks.voxel_size / blocks.truncation;  // one voxel, in tsdf units
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (std::size_t i = 0; i < kTsdfBlockVoxels; ++i) {
      const TsdfVoxel& v = blocks.voxels[b * kTsdfBlockVoxels + i];
      if (v.weight < params.min_weight || v.tsdf >= near) continue;
      const Eigen::Vector3i local(static_cast<int>(i % 8), static_cast<int>(i / 8 % 8),
                                  static_cast<int>(i / 64));
      const Eigen::Vector3d centre =
          ((blocks.coords[b] * kTsdfBlockSide + local).cast<double>().array() + 0.5) *
          blocks.voxel_size;
      out.push_back(params.world_to_level * centre);
    }
  }
  return out;
}

}  // namespace

void TsdfSliceParams::validate() const {
  require(world_to_level.matrix().allFinite(), "TSDF slice: world_to_level is not finite");
  require(std::isfinite(floor_z) && floor_tolerance >= 0, "TSDF slice: bad floor_z or tolerance");
  require(band_min < band_max, "TSDF slice: band_min must be below band_max");
  require(resolution > 0 && std::isfinite(resolution), "TSDF slice: resolution must be > 0");
}

OccupancyGrid tsdf_occupancy(const TsdfBlocks& blocks, const TsdfSliceParams& params) {
  params.validate();
  OccupancyGrid grid;
  grid.resolution = params.resolution;
  const std::vector<Eigen::Vector3d> points = surface_points(blocks, params);
  if (points.empty()) return grid;
  Eigen::Vector2d lo = points.front().head<2>(), hi = lo;
  for (const Eigen::Vector3d& p : points) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  const auto cols = static_cast<int>(std::floor((hi.x() - lo.x()) / params.resolution)) + 1;
  const auto rows = static_cast<int>(std::floor((hi.y() - lo.y()) / params.resolution)) + 1;
  require(static_cast<double>(cols) * rows <= 1e8, "TSDF slice: the grid would exceed 1e8 cells");
  grid.origin = Eigen::Vector3d(lo.x(), lo.y(), 0);
  grid.cells = Image<CellState>(cols, rows);
  std::fill(grid.cells.pixels().begin(), grid.cells.pixels().end(), CellState::unknown);
  for (const Eigen::Vector3d& p : points) {
    const double h = p.z() - params.floor_z;
    const bool in_band = h >= params.band_min && h <= params.band_max;
    const bool floor = std::abs(h) <= params.floor_tolerance;
    if (!in_band && !floor) continue;
    const Eigen::Vector2i cell = grid.cell_of(p.head<2>());
    if (!grid.contains(cell)) continue;
    CellState& state = grid.cells(cell.x(), cell.y());
    if (in_band)
      state = CellState::occupied;
    else if (state == CellState::unknown)
      state = CellState::free;
  }
  return grid;
}

Image<float> occupancy_esdf(const OccupancyGrid& grid) {
  const int w = grid.width(), h = grid.height();
  Image<std::uint8_t> to_obstacle(w, h), to_outside(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool occupied = grid.cells(x, y) == CellState::occupied;
      to_obstacle(x, y) = occupied ? 0 : 1;
      to_outside(x, y) = occupied ? 1 : 0;
    }
  }
  const Image<float> outside = geometry::distance_to_zero(to_obstacle);
  const Image<float> inside = geometry::distance_to_zero(to_outside);
  Image<float> esdf(w, h);
  const auto r = static_cast<float>(grid.resolution);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool occupied = grid.cells(x, y) == CellState::occupied;
      esdf(x, y) = occupied ? -r * inside(x, y) : r * outside(x, y);
    }
  }
  return esdf;
}

}  // namespace kartograf::mapping
