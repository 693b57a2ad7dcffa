#include "semantic/grid_band_points.hpp"

namespace kartograf::semantic::detail {

BandPointIndex::BandPointIndex(const SemanticGrid& grid, std::span<const Eigen::Vector3d> points,
                               std::span<const SemanticClass> labels,
                               const SemanticGridParams& options, SemanticClass indexed)
    : width_(grid.width()), start_(static_cast<std::size_t>(grid.width()) * grid.height() + 1, 0) {
  const auto in_band = [&](std::size_t i) {
    const double h = points[i].z() - grid.floor_z;
    return labels[i] == indexed && points[i].allFinite() && h >= options.band_min &&
           h <= options.band_max;
  };
  const auto slot = [&](std::size_t i) {
    const Eigen::Vector2i c = grid.cell_of(points[i].head<2>());
    return static_cast<std::size_t>(c.y()) * grid.width() + c.x();
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (in_band(i)) ++start_[slot(i) + 1];
  }
  for (std::size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
  points_.resize(start_.back());
  std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (in_band(i)) points_[next[slot(i)]++] = points[i].head<2>();
  }
}

std::span<const Eigen::Vector2d> BandPointIndex::in_cell(const Eigen::Vector2i& c) const {
  const std::size_t k = static_cast<std::size_t>(c.y()) * width_ + c.x();
  return {points_.data() + start_[k], start_[k + 1] - start_[k]};
}

}  // namespace kartograf::semantic::detail
