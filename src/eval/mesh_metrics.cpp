#include "kartograf/eval/mesh_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/error.hpp"

namespace kartograf::eval {

namespace {

std::uint64_t cell_key(const Eigen::Vector3d& p, double size) {
  const Eigen::Array3d k = (p / size).array().floor() + double(1 << 20);
  return static_cast<std::uint64_t>(k.x()) | static_cast<std::uint64_t>(k.y()) << 21 |
         static_cast<std::uint64_t>(k.z()) << 42;
}

double area_weighted_distance(
    const TriangleMesh& mesh,
    const std::function<double(const Eigen::Vector3d&)>& distance_to_truth) {
  double area = 0, weighted = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(),
                          b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    const double triangle = 0.5 * (b - a).cross(c - a).norm();
    area += triangle;
    weighted += triangle * distance_to_truth((a + b + c) / 3.0);
  }
  return area > 0 ? weighted / area : 0.0;
}

}  // namespace

MeshAccuracy mesh_accuracy(const TriangleMesh& mesh,
                           const std::function<double(const Eigen::Vector3d&)>& distance_to_truth) {
  MeshAccuracy out;
  out.vertices = mesh.vertices.size();
  if (mesh.vertices.empty()) return out;
  std::vector<double> d;
  d.reserve(mesh.vertices.size());
  for (const Eigen::Vector3f& v : mesh.vertices) d.push_back(distance_to_truth(v.cast<double>()));
  double sum = 0;
  for (double x : d) sum += x;
  out.mean_m = sum / static_cast<double>(d.size());
  const auto p90 = d.begin() + static_cast<std::ptrdiff_t>(d.size() * 9 / 10);
  std::nth_element(d.begin(), p90, d.end());
  out.p90_m = *p90;
  out.max_m = *std::max_element(d.begin(), d.end());
  out.area_mean_m = area_weighted_distance(mesh, distance_to_truth);
  return out;
}

double mesh_completeness(const TriangleMesh& mesh, std::span<const Eigen::Vector3d> truth,
                         double radius) {
  require(std::isfinite(radius) && radius > 0, "mesh completeness: the radius must be positive");
  if (truth.empty()) return 0;
  std::unordered_map<std::uint64_t, std::vector<Eigen::Vector3d>> grid;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    grid[cell_key(v.cast<double>(), radius)].push_back(v.cast<double>());
  }
  std::size_t covered = 0;
  for (const Eigen::Vector3d& p : truth) {
    bool found = false;
    for (int i = 0; i < 27 && !found; ++i) {
      const Eigen::Vector3d q = p + radius * Eigen::Vector3d(i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1);
      const auto cell = grid.find(cell_key(q, radius));
      if (cell == grid.end()) continue;
      found = std::any_of(cell->second.begin(), cell->second.end(),
                          [&](const Eigen::Vector3d& v) { return (v - p).norm() <= radius; });
    }
    covered += found ? 1 : 0;
  }
  return static_cast<double>(covered) / static_cast<double>(truth.size());
}

}  // namespace kartograf::eval
