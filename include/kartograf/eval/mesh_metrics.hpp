#pragma once
// A reconstructed mesh against the true surfaces (the TSDF's accuracy, issue 24): accuracy is how
// far its vertices lie from the truth, completeness how much of the seen truth it covers.
#include <cstddef>
#include <functional>
#include <span>

#include <Eigen/Core>

#include "kartograf/core/triangle_mesh.hpp"

namespace kartograf::eval {

struct MeshAccuracy {
  std::size_t vertices = 0;
  double mean_m = 0;  // mean distance of the vertices to the true surfaces
  double p90_m = 0;   // its 90th percentile
  double max_m = 0;
  // The mean distance over the surface: triangles' centroids weighted by their areas. Unlike the
  // vertices' mean it does not depend on how densely a mesher places vertices (marching
  // tetrahedra puts about 4 times as many as marching cubes on the same surface).
  double area_mean_m = 0;
};

// distance_to_truth(p): metres from p to the nearest true surface.
MeshAccuracy mesh_accuracy(const TriangleMesh& mesh,
                           const std::function<double(const Eigen::Vector3d&)>& distance_to_truth);

// The fraction of the true surface points that have a mesh vertex within `radius` (0 for none).
double mesh_completeness(const TriangleMesh& mesh, std::span<const Eigen::Vector3d> truth,
                         double radius);

}  // namespace kartograf::eval
