#pragma once
// Maps as Python dicts of NumPy arrays: clouds, meshes, grids, distance fields.
#include <nanobind/nanobind.h>

#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/triangle_mesh.hpp"
#include "kartograf/mapping/esdf_volume.hpp"

namespace kartograf::python {

nanobind::dict cloud_dict(const PointCloud& cloud);  // points N x 3, colors N x 3 (or 0 x 3)
nanobind::dict mesh_dict(const TriangleMesh& mesh);  // vertices, triangles, colors
nanobind::dict grid_dict(OccupancyGrid grid);        // cells H x W (0 unknown, 1 free, 2 occupied)
nanobind::dict esdf_dict(mapping::EsdfGrid grid);    // distances, occupied: [z, y, x]

}  // namespace kartograf::python
