// A mesh against known surfaces (eval/mesh_metrics.hpp): the vertices' mean and the surface's.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kartograf/eval/mesh_metrics.hpp"

namespace kartograf {
namespace {

// A 1 m square 1 cm above the plane z = 0, and a 1 cm triangle half a metre above it.
TriangleMesh square_and_speck() {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0.01f}, {1, 0, 0.01f},    {1, 1, 0.01f},   {0, 1, 0.01f},
                   {0, 0, 0.5f},  {0.01f, 0, 0.5f}, {0, 0.01f, 0.5f}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}};
  return mesh;
}

TEST(MeshMetrics, TheVerticesMeanCountsVerticesTheAreaMeanCountsSurface) {
  const auto height = [](const Eigen::Vector3d& p) { return std::abs(p.z()); };
  const eval::MeshAccuracy accuracy = eval::mesh_accuracy(square_and_speck(), height);
  EXPECT_EQ(accuracy.vertices, 7u);
  EXPECT_NEAR(accuracy.mean_m, (4 * 0.01 + 3 * 0.5) / 7, 1e-6);
  // The speck is 5e-5 m^2 of 1.00005 m^2.
  EXPECT_NEAR(accuracy.area_mean_m, (1.0 * 0.01 + 5e-5 * 0.5) / (1.0 + 5e-5), 1e-6);
  EXPECT_NEAR(accuracy.max_m, 0.5, 1e-6);
  EXPECT_EQ(eval::mesh_accuracy(TriangleMesh{}, height).area_mean_m, 0.0);
}

TEST(MeshMetrics, CompletenessIsTheShareOfTruthNearAVertex) {
  const std::vector<Eigen::Vector3d> truth = {{0, 0, 0}, {1, 1, 0}, {5, 5, 0}};
  EXPECT_NEAR(eval::mesh_completeness(square_and_speck(), truth, 0.02), 2.0 / 3.0, 1e-12);
  EXPECT_EQ(eval::mesh_completeness(square_and_speck(), truth, 0.005), 0.0);
}

}  // namespace
}  // namespace kartograf
