#pragma once
// Phantom points (a step of build_semantic_grid): a depth camera's pixel on an object's outline
// returns a mix of the object and what lies behind it, a point floating in the air behind the
// object. Pooled over many views these pile up into fans of false obstacles beside every table.
// They are told from surfaces by the free space: rays of the views cross a phantom's voxel far
// more often than points fall in it, where a surface stops the rays that reach it.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "kartograf/semantic/semantic_grid.hpp"
#include "semantic/grid_free_space.hpp"

namespace kartograf::semantic::detail {

// Per point: 1 where it is a phantom. A band point not labelled wall or door (their faces, seen
// at grazing angles, are crossed beside them) is one when the rays crossed its voxel more than
// options.phantom_pass_ratio times as often as band points fell in it (free_space counts every
// free_space_ray_stride-th ray), and so did the voxels options.phantom_margin beside it in x and
// y: a surface on a cell boundary (the lattice follows the walls) has rays crossing the open
// cell beside it, but not the solid cell behind it.
std::vector<std::uint8_t> phantom_points(const SemanticGrid& grid,
                                         std::span<const Eigen::Vector3d> points,
                                         std::span<const SemanticClass> labels,
                                         const BandFreeSpace& free_space,
                                         const SemanticGridParams& options);

}  // namespace kartograf::semantic::detail
