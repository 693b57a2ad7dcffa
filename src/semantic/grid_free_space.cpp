#include "grid_free_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kartograf/core/memory_budget.hpp"
#include "semantic/grid_cells.hpp"

namespace kartograf::semantic::detail {

namespace {

std::size_t cell_count(const SemanticGrid& grid) {
  const double bytes = static_cast<double>(grid.width()) * grid.height() *
                       (2 * sizeof(std::uint64_t) + BandFreeSpace::kSlabs * sizeof(std::uint16_t));
  require_fits_in_memory(bytes, "build_semantic_grid: the free space of a grid of " +
                                    std::to_string(grid.width()) + " x " +
                                    std::to_string(grid.height()) + " cells");
  return static_cast<std::size_t>(grid.width()) * static_cast<std::size_t>(grid.height());
}

}  // namespace

BandFreeSpace::BandFreeSpace(const SemanticGrid& grid, double band_min, double slab_height)
    : grid_(grid),
      band_min_(band_min),
      slab_height_(slab_height),
      cells_(cell_count(grid)),
      passes_(cells_.size() * kSlabs, 0) {}

// The segment, in lattice units (x along columns, y up the rows, z along the slabs), clipped to
// the lattice; then walked voxel by voxel.
void BandFreeSpace::add_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
                            double end_margin) {
  const Eigen::Vector3d delta = end - origin;
  const double length = delta.norm();
  if (!(length > end_margin)) return;
  const Eigen::Vector3d scale(grid_.resolution, grid_.resolution, slab_height_);
  const Eigen::Vector3d base(grid_.origin.x(), grid_.origin.y(), grid_.floor_z + band_min_);
  const Eigen::Vector3d a = (origin - base).cwiseQuotient(scale);
  const Eigen::Vector3d d = (delta * ((length - end_margin) / length)).cwiseQuotient(scale);
  const Eigen::Vector3d size(grid_.width(), grid_.height(), kSlabs);
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 3; ++k) {
    if (std::fabs(d[k]) < 1e-12) {
      if (a[k] < 0 || a[k] >= size[k]) return;
      continue;
    }
    double enter = -a[k] / d[k], leave = (size[k] - a[k]) / d[k];
    if (enter > leave) std::swap(enter, leave);
    t0 = std::max(t0, enter), t1 = std::min(t1, leave);
  }
  if (t0 < t1) walk(a + t0 * d, d, t0, t1);
}

// Voxel traversal (Amanatides and Woo) from `entry` (at parameter t0) to parameter t1.
void BandFreeSpace::walk(const Eigen::Vector3d& entry, const Eigen::Vector3d& d, double t0,
                         double t1) {
  const int size[3] = {grid_.width(), grid_.height(), kSlabs};
  int voxel[3], step[3];
  double next[3], delta[3];
  for (int k = 0; k < 3; ++k) {
    voxel[k] = std::clamp(static_cast<int>(std::floor(entry[k])), 0, size[k] - 1);
    step[k] = d[k] > 0 ? 1 : (d[k] < 0 ? -1 : 0);
    delta[k] = step[k] != 0 ? 1.0 / std::fabs(d[k]) : std::numeric_limits<double>::infinity();
    const double boundary = voxel[k] + (step[k] > 0 ? 1 : 0);
    next[k] = step[k] != 0 ? t0 + (boundary - entry[k]) / d[k] : delta[k];
  }
  for (;;) {
    const std::size_t index =
        static_cast<std::size_t>(size[1] - 1 - voxel[1]) * static_cast<std::size_t>(size[0]) +
        static_cast<std::size_t>(voxel[0]);
    Slabs& cell = cells_[index];
    std::uint16_t& passes = passes_[index * kSlabs + static_cast<std::size_t>(voxel[2])];
    if (passes < std::numeric_limits<std::uint16_t>::max()) ++passes;
    const std::uint64_t bit = std::uint64_t{1} << voxel[2];
    cell.twice |= cell.once & bit;
    cell.once |= bit;
    const int axis =
        next[0] <= next[1] ? (next[0] <= next[2] ? 0 : 2) : (next[1] <= next[2] ? 1 : 2);
    if (next[axis] > t1) return;
    voxel[axis] += step[axis];
    if (voxel[axis] < 0 || voxel[axis] >= size[axis]) return;
    next[axis] += delta[axis];
  }
}

int BandFreeSpace::slab_of(double height) const {
  return static_cast<int>(std::floor((height - band_min_) / slab_height_));
}

std::size_t BandFreeSpace::index_of(const Eigen::Vector2i& cell) const {
  return static_cast<std::size_t>(cell.y()) * static_cast<std::size_t>(grid_.width()) +
         static_cast<std::size_t>(cell.x());
}

std::uint64_t BandFreeSpace::crossed_twice(const Eigen::Vector2i& cell) const {
  return cells_[index_of(cell)].twice;
}

std::optional<std::size_t> BandFreeSpace::voxel(const Eigen::Vector2i& cell, double height) const {
  const int slab = slab_of(height);
  if (!grid_.contains(cell) || slab < 0 || slab >= kSlabs) return std::nullopt;
  return index_of(cell) * kSlabs + static_cast<std::size_t>(slab);
}

int BandFreeSpace::passes(const Eigen::Vector2i& cell, double height) const {
  const std::optional<std::size_t> v = voxel(cell, height);
  return v ? passes_[*v] : 0;
}

int BandFreeSpace::fewest_passes(const Eigen::Vector2i& cell, double low, double high) const {
  const int bottom = std::max(slab_of(low), 0), top = slab_of(high);
  if (!grid_.contains(cell) || top < bottom || top >= kSlabs) return 0;
  const std::size_t first = index_of(cell) * kSlabs;
  int fewest = std::numeric_limits<int>::max();
  for (int slab = bottom; slab <= top; ++slab)
    fewest = std::min<int>(fewest, passes_[first + static_cast<std::size_t>(slab)]);
  return fewest;
}

bool BandFreeSpace::observable(double height) const {
  const int slab = slab_of(height);
  return slab >= 0 && slab < kSlabs && height < eye_height_ - kEyeMargin;
}

bool BandFreeSpace::clear_between(const Eigen::Vector2i& cell, double low, double high) const {
  const int bottom = std::max(slab_of(low), 0);
  const int top = std::min({slab_of(high), slab_of(eye_height_ - kEyeMargin), kSlabs - 1});
  if (!grid_.contains(cell) || top < bottom) return false;
  const std::uint64_t upto =
      top == kSlabs - 1 ? ~std::uint64_t{0} : (std::uint64_t{1} << (top + 1)) - 1;
  const std::uint64_t slabs = upto & ~((std::uint64_t{1} << bottom) - 1);
  return (crossed_twice(cell) & slabs) == slabs;
}

namespace {

// A cell no view saw among the cell's 4 neighbours: the cell is a wall's face, whose points may
// lie on its far side (a face on the cell boundary), seen through but for them. The wall faces'
// placement judges it.
bool beside_unobserved(const SemanticGrid& grid, const Eigen::Vector2i& cell) {
  for (const Eigen::Vector2i& step : kFourNeighbours) {
    if (unobserved(grid, cell + step)) return true;
  }
  return false;
}

// Furniture (in the mask) or an unclassified obstacle among the cell's 8 neighbours.
bool beside_furniture(const SemanticGrid& grid, const Image<std::uint8_t>& furniture,
                      const Eigen::Vector2i& cell) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const Eigen::Vector2i n = cell + Eigen::Vector2i(dx, dy);
      if (grid.contains(n) && (furniture(n.x(), n.y()) || unclassified_obstacle(grid, n)))
        return true;
    }
  }
  return false;
}

}  // namespace

Image<float> nearest_wall_ranges(const SemanticGrid& grid, std::span<const Eigen::Vector3d> points,
                                 std::span<const SemanticClass> labels,
                                 std::span<const std::uint32_t> view_ids,
                                 std::span<const Eigen::Vector3d> view_origins,
                                 const SemanticGridParams& options) {
  Image<float> nearest(grid.width(), grid.height(), std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    const double h = p.z() - grid.floor_z;
    if (labels[i] != SemanticClass::wall || !p.allFinite() || h < options.band_min ||
        h > options.band_max || view_ids[i] >= view_origins.size())
      continue;
    const Eigen::Vector2i c = grid.cell_of(p.head<2>());
    if (!grid.contains(c)) continue;
    float& range = nearest(c.x(), c.y());
    range = std::min(range, static_cast<float>((p - view_origins[view_ids[i]]).norm()));
  }
  return nearest;
}

int free_seen_through_walls(SemanticGrid& grid, const BandFreeSpace& free_space,
                            const Image<float>& nearest_wall_range,
                            const Image<std::uint8_t>& floor_seen,
                            const Image<std::uint8_t>& furniture,
                            const SemanticGridParams& options) {
  std::vector<Eigen::Vector2i> freed;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Eigen::Vector2i cell(col, row);
      if (grid.classes(col, row) != SemanticClass::wall || !floor_seen(col, row) ||
          !(nearest_wall_range(col, row) >= options.seen_through_wall_range) ||
          !free_space.clear_throughout(cell) || beside_unobserved(grid, cell) ||
          beside_furniture(grid, furniture, cell))
        continue;
      freed.push_back(cell);
    }
  }
  // Judged on the cells as classified, then changed: a freed cell does not free its neighbours.
  set_class(grid, freed, SemanticClass::floor, options.weights.of(SemanticClass::floor));
  return static_cast<int>(freed.size());
}

int floor_seen_through(SemanticGrid& grid, const BandFreeSpace& free_space,
                       const Image<std::uint8_t>& drops, float floor_weight) {
  std::vector<Eigen::Vector2i> freed;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Eigen::Vector2i cell(col, row);
      if (unobserved(grid, cell) && !drops(col, row) && free_space.clear_throughout(cell))
        freed.push_back(cell);
    }
  }
  set_class(grid, freed, SemanticClass::floor, floor_weight);
  return static_cast<int>(freed.size());
}

BandFreeSpace carve_band(const SemanticGrid& grid, std::span<const Eigen::Vector3d> points,
                         std::span<const std::uint32_t> view_ids,
                         std::span<const Eigen::Vector3d> view_origins,
                         const SemanticGridParams& options) {
  BandFreeSpace free_space(grid, options.band_min, options.free_space_slab);
  const auto stride = static_cast<std::size_t>(options.free_space_ray_stride);
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const Eigen::Vector3d& end = points[i];
    if (!end.allFinite() || view_ids[i] >= view_origins.size()) continue;
    const Eigen::Vector3d& origin = view_origins[view_ids[i]];
    // The depth's noise grows with range: the last few centimetres may lie behind the surface.
    const double margin = options.free_space_end_margin * (1 + (end - origin).norm());
    free_space.add_ray(origin, end, margin);
  }
  std::vector<double> eyes;
  for (const Eigen::Vector3d& o : view_origins) eyes.push_back(o.z() - grid.floor_z);
  if (!eyes.empty()) {
    std::nth_element(eyes.begin(), eyes.begin() + eyes.size() / 2, eyes.end());
    free_space.set_eye_height(eyes[eyes.size() / 2]);
  }
  return free_space;
}

}  // namespace kartograf::semantic::detail
