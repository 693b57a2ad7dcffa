#pragma once
// Where the views saw through the robot's height band: each pooled point's ray, from its view's
// origin to just short of the point, marks the height slabs of the cells it crosses as seen
// through (a step of build_semantic_grid). A table top that grazing views dropped is never seen
// through, while the floor around it is crossed at the top's height by rays to farther surfaces:
// this tells the floor under a table from the floor beside it, which point counts cannot. Each
// voxel (cell by slab) also counts the rays that crossed it (grid_phantoms.hpp).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::semantic::detail {

class BandFreeSpace {
 public:
  static constexpr int kSlabs = 64;  // one bit each in a cell's masks
  // Heights this close below the views' median eye height count as unobserved: few rays pass them.
  static constexpr double kEyeMargin = 0.1;

  // Slabs of slab_height from band_min above the grid's floor.
  BandFreeSpace(const SemanticGrid& grid, double band_min, double slab_height);

  // Marks the slabs crossed by the segment origin -> end, stopping end_margin short of the end
  // (the surface it hit, with its noise). World coordinates, z up.
  void add_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& end, double end_margin);

  // Whether rays cross `height` (above the floor) over open floor: within the tracked slabs, and
  // kEyeMargin below the views' median eye height (cameras look down across what is below them;
  // above them few rays pass).
  bool observable(double height) const;
  void set_eye_height(double height) { eye_height_ = height; }
  // Whether `cell` was seen through (crossed by at least two rays: one may be noise) at every
  // observable height from `low` (clamped to the band's bottom) up to `high`. False when no such
  // height is observable.
  bool clear_between(const Eigen::Vector2i& cell, double low, double high) const;
  // The fewest rays that crossed `cell` in a slab from `low` up to `high`, at any height, the
  // unobservable ones too; 0 when a slab of them lies outside the tracked ones.
  int fewest_passes(const Eigen::Vector2i& cell, double low, double high) const;
  // ... from the band's bottom: nothing stands there below `height`.
  bool clear_below(const Eigen::Vector2i& cell, double height) const {
    return clear_between(cell, band_min_, height);
  }
  // ... at every observable height.
  bool clear_throughout(const Eigen::Vector2i& cell) const {
    return clear_below(cell, eye_height_);
  }
  // The index of the voxel (cell by slab) of `cell` at `height` above the floor, among
  // voxel_count(); none outside the grid and the slabs.
  std::optional<std::size_t> voxel(const Eigen::Vector2i& cell, double height) const;
  std::size_t voxel_count() const { return cells_.size() * kSlabs; }
  // How many rays crossed the voxel of `cell` at `height` (saturating; 0 outside the slabs).
  int passes(const Eigen::Vector2i& cell, double height) const;

 private:
  struct Slabs {
    std::uint64_t once = 0, twice = 0;  // crossed at least once / twice
  };
  void walk(const Eigen::Vector3d& entry, const Eigen::Vector3d& d, double t0, double t1);
  int slab_of(double height) const;
  std::size_t index_of(const Eigen::Vector2i& cell) const;  // row-major, rows as the grid's
  std::uint64_t crossed_twice(const Eigen::Vector2i& cell) const;

  const SemanticGrid& grid_;
  double band_min_, slab_height_;
  double eye_height_ = 0;              // above the floor
  std::vector<Slabs> cells_;           // row-major, as the grid's cells
  std::vector<std::uint16_t> passes_;  // per cell, kSlabs counts of rays (saturating)
};

// Per cell: the range from its view's origin to the nearest wall point in the robot's height band
// (infinity where there is none). Views as carve_band takes them.
Image<float> nearest_wall_ranges(const SemanticGrid& grid, std::span<const Eigen::Vector3d> points,
                                 std::span<const SemanticClass> labels,
                                 std::span<const std::uint32_t> view_ids,
                                 std::span<const Eigen::Vector3d> view_origins,
                                 const SemanticGridParams& options);

// Wall cells whose wall points were all measured from seen_through_wall_range or farther, in which
// the views saw floor and which they saw through (twice) at every height they observe, are floor;
// not next to a cell no view saw (a wall's face, which the faces' placement judges) or to
// furniture or an unclassified obstacle (a table's edge or leg takes part of a cell only, and rays
// pass beside it). Returns how many. A depth camera's error grows with range (a structured-light
// camera's disparity steps are about z^2 / 315 m: 5 cm at 4 m), and puts a far wall's points in a
// layer a cell or more in front of it, which nearer views see through. Points from nearer views
// are not overruled: two copies of a wall in a map that drifted are each seen through from the
// other copy's views, and a gap in either lets the rooms leak.
int free_seen_through_walls(SemanticGrid& grid, const BandFreeSpace& free_space,
                            const Image<float>& nearest_wall_range,
                            const Image<std::uint8_t>& floor_seen,
                            const Image<std::uint8_t>& furniture,
                            const SemanticGridParams& options);

// Unobserved cells seen through at every observable height from the band's bottom up are floor
// (SemanticGridParams::floor_seen_through), but for the `drops`, where the views saw below the
// floor (stairs down: rays pass over a drop as over lost floor). Returns how many.
int floor_seen_through(SemanticGrid& grid, const BandFreeSpace& free_space,
                       const Image<std::uint8_t>& drops, float floor_weight);

// The free space of the rays of every free_space_ray_stride-th point, each from its view's origin
// (view_origins[view_ids[i]]).
BandFreeSpace carve_band(const SemanticGrid& grid, std::span<const Eigen::Vector3d> points,
                         std::span<const std::uint32_t> view_ids,
                         std::span<const Eigen::Vector3d> view_origins,
                         const SemanticGridParams& options);

}  // namespace kartograf::semantic::detail
