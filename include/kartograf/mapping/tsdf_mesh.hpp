#pragma once
// The zero surface of a TSDF (tsdf_volume.hpp) as a triangle mesh, on the host from a downloaded
// copy of the field.
//
// Cells are the cubes between 8 neighbouring voxel centres; a cell with an unobserved corner is
// skipped. Marching cubes: a vertex lies on every cell edge whose ends differ in sign, placed by
// linear interpolation, and is shared by the triangles that use that edge; its colour is
// interpolated alike. Each cell's triangles come from its corners' signs by one rule
// (kernels/tsdf/tsdf_mesh.h, tsdf_mc_triangles): on each face the surface cuts off every run of
// corners below zero, so two on a diagonal stay apart, and the cells on both sides of a face cut
// it alike (no cracks); the cuts join into loops, each a fan of triangles. A triangle with a
// vertex on an edge whose two values are both at the truncation (|value| >= max_jump) lies on a
// jump in the field, not a surface (the boundary between what a view saw in front of a surface
// and what it saw behind another), and is left out. Triangles face the + side (the viewer).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/triangle_mesh.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"

namespace kartograf::mapping {

struct MeshParams {
  float min_weight = 1;     // corners observed at least this much
  float max_jump = 0.999f;  // see above
};

TriangleMesh extract_mesh(const TsdfBlocks& blocks, const MeshParams& params = {});
// The same on the field's device (kernels/tsdf/tsdf_mesh.h: each cell appends its triangles with
// their vertices' edges); the host joins the shared vertices and puts the triangles in the order
// above. Equal to the host's on a downloaded copy: bit for bit on the CPU backend, within float
// rounding on devices that fuse multiply-adds.
TriangleMesh extract_mesh(const TsdfVolume& volume, const MeshParams& params = {});

}  // namespace kartograf::mapping
