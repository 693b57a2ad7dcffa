#include "map_dicts.hpp"

#include <nanobind/stl/array.h>

#include <array>
#include <vector>

#include "convert.hpp"

namespace kartograf::python {

nb::dict cloud_dict(const PointCloud& cloud) {
  std::vector<float> points;
  for (const Eigen::Vector3f& p : cloud.points) points.insert(points.end(), p.data(), p.data() + 3);
  std::vector<std::uint8_t> colors;
  for (const Rgb8& c : cloud.colors) colors.insert(colors.end(), c.begin(), c.end());
  nb::dict d;
  d["points"] = owned_array(std::move(points), {cloud.size(), 3});
  d["colors"] = owned_array(std::move(colors), {cloud.colors.size(), 3});
  return d;
}

nb::dict mesh_dict(const TriangleMesh& mesh) {
  std::vector<float> vertices;
  for (const Eigen::Vector3f& v : mesh.vertices)
    vertices.insert(vertices.end(), v.data(), v.data() + 3);
  std::vector<std::int32_t> triangles;
  for (const Eigen::Vector3i& t : mesh.triangles)
    triangles.insert(triangles.end(), t.data(), t.data() + 3);
  std::vector<std::uint8_t> colors;
  for (const std::uint32_t c : mesh.colors)
    colors.insert(colors.end(), {std::uint8_t(c), std::uint8_t(c >> 8), std::uint8_t(c >> 16)});
  nb::dict d;
  d["vertices"] = owned_array(std::move(vertices), {mesh.vertices.size(), 3});
  d["triangles"] = owned_array(std::move(triangles), {mesh.triangles.size(), 3});
  d["colors"] = owned_array(std::move(colors), {mesh.colors.size(), 3});
  return d;
}

nb::dict esdf_dict(mapping::EsdfGrid grid) {
  const auto x = std::size_t(grid.dims.x()), y = std::size_t(grid.dims.y()),
             z = std::size_t(grid.dims.z());
  nb::dict d;
  d["resolution"] = grid.resolution;
  d["max_distance"] = grid.max_distance;
  d["first_cell"] =
      std::array<int, 3>{grid.first_cell.x(), grid.first_cell.y(), grid.first_cell.z()};
  // Indexed [z, y, x], as the grid stores them.
  d["distances"] = owned_array(std::move(grid.distances), {z, y, x});
  d["occupied"] = owned_array(std::move(grid.occupied), {z, y, x});
  return d;
}

nb::dict grid_dict(OccupancyGrid grid) {
  nb::dict d;
  d["resolution"] = grid.resolution;
  d["origin"] = std::array<double, 3>{grid.origin.x(), grid.origin.y(), grid.origin.z()};
  d["cells"] = plane_array<std::uint8_t>(std::move(grid.cells));
  return d;
}

}  // namespace kartograf::python
