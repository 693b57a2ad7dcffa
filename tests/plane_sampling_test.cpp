// Point generation on planes (segmentation/plane_sampling.hpp, the M1 paper's eq. 8-10): projected
// points lie on their plane and keep their in-plane position, N are drawn without replacement
// (all when fewer), the draw is deterministic per seed, and bad input is an error.
#include "kartograf/segmentation/plane_sampling.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <tuple>

#include "kartograf/core/error.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using segmentation::PlaneSamplingParams;
using segmentation::PlaneSet;
using segmentation::sample_plane_points;

// 8x4 pixels: the left half on the plane z = 1 (with +-1 cm of off-plane noise), the right half
// on the plane x = 0.5; one pixel of each half invalid.
struct TwoPlanes {
  PointImage points{8, 4};
  RgbImage colors{8, 4};
  PlaneSet planes;
  TwoPlanes() {
    planes.labels = LabelImage(8, 4);
    for (int v = 0; v < 4; ++v) {
      for (int u = 0; u < 8; ++u) {
        const double noise = ((u + v) % 2 == 0 ? 0.01 : -0.01);
        const bool left = u < 4;
        const Eigen::Vector3d p = left ? Eigen::Vector3d(0.1 * u - 0.4, 0.1 * v, 1 + noise)
                                       : Eigen::Vector3d(0.5 + noise, 0.1 * v, 1 + 0.1 * u);
        points(u, v) = Point4f(float(p.x()), float(p.y()), float(p.z()), 1.0f);
        colors(u, v) = Rgb8{static_cast<std::uint8_t>(u), static_cast<std::uint8_t>(v), 7};
        planes.labels(u, v) = left ? 1 : 2;
      }
    }
    const float nan = std::numeric_limits<float>::quiet_NaN();
    points(0, 0) = Point4f(nan, nan, nan, nan);
    points(7, 3) = Point4f(nan, nan, nan, nan);
    planes.planes.resize(2);
    planes.planes[0].id = 1;
    planes.planes[0].normal = Eigen::Vector3d(0, 0, -1);  // -z + 1 = 0
    planes.planes[0].offset = 1;
    planes.planes[1].id = 2;
    planes.planes[1].normal = Eigen::Vector3d(-1, 0, 0);  // -x + 0.5 = 0
    planes.planes[1].offset = 0.5;
  }
};

TEST(PlaneSampling, ProjectsOntoThePlaneAndKeepsThePixelsInPlanePosition) {
  const TwoPlanes scene;
  const PointCloud cloud =
      sample_plane_points(scene.points, &scene.colors, scene.planes, PlaneSamplingParams{5, 3});
  ASSERT_EQ(cloud.size(), 10u);
  ASSERT_EQ(cloud.normals.size(), 10u);
  ASSERT_EQ(cloud.colors.size(), 10u);
  std::set<std::tuple<int, int>> drawn;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto& p = cloud.points[i];
    const bool first = i < 5;  // grouped by plane, in id order
    // Back to the pixel through its colour: the in-plane coordinates are unchanged.
    const int u = cloud.colors[i][0], v = cloud.colors[i][1];
    EXPECT_EQ(first, u < 4);
    EXPECT_TRUE(drawn.emplace(u, v).second) << "pixel drawn twice";
    EXPECT_FALSE(u == 0 && v == 0) << "invalid pixel drawn";
    EXPECT_FALSE(u == 7 && v == 3) << "invalid pixel drawn";
    const Point4f original = scene.points(u, v);
    if (first) {
      EXPECT_NEAR(p.z(), 1.0, 1e-6);
      EXPECT_NEAR(p.x(), original.x(), 1e-6);
      EXPECT_NEAR(cloud.normals[i].z(), -1.0, 1e-6);
    } else {
      EXPECT_NEAR(p.x(), 0.5, 1e-6);
      EXPECT_NEAR(p.z(), original.z(), 1e-6);
      EXPECT_NEAR(cloud.normals[i].x(), -1.0, 1e-6);
    }
    EXPECT_NEAR(p.y(), original.y(), 1e-6);
  }
}

TEST(PlaneSampling, TakesEveryPixelWhenThePlaneHasFewerAndDrawsBySeed) {
  const TwoPlanes scene;
  // 15 valid pixels per plane.
  EXPECT_EQ(sample_plane_points(scene.points, nullptr, scene.planes, {200, 1}).size(), 30u);
  const PointCloud a = sample_plane_points(scene.points, nullptr, scene.planes, {4, 1});
  const PointCloud b = sample_plane_points(scene.points, nullptr, scene.planes, {4, 1});
  const PointCloud c = sample_plane_points(scene.points, nullptr, scene.planes, {4, 2});
  EXPECT_TRUE(a.colors.empty());
  EXPECT_EQ(a.points, b.points);
  EXPECT_NE(a.points, c.points);
}

TEST(PlaneSampling, RejectsMismatchedImagesAndUnknownPlaneIds) {
  TwoPlanes scene;
  EXPECT_ERROR_MENTIONS(sample_plane_points(PointImage(4, 4), nullptr, scene.planes), "8x4");
  const RgbImage small(2, 2);
  EXPECT_ERROR_MENTIONS(sample_plane_points(scene.points, &small, scene.planes), "colour");
  scene.planes.labels(3, 3) = 9;
  EXPECT_ERROR_MENTIONS(sample_plane_points(scene.points, nullptr, scene.planes), "plane id 9");
}

}  // namespace
}  // namespace kartograf
