// Map fusion (mapping/map_fusion.hpp): voxel counts against an independent count, normals rotated
// into the world and averaged, colours averaged with rounding half up, frames of one surface from
// two poses fusing into the same voxels, the depth limit, the point filter, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <tuple>

#include "kartograf/core/error.hpp"
#include "kartograf/mapping/map_fusion.hpp"

namespace kartograf {
namespace {

using mapping::MapFusion;
using mapping::MapFusionParams;

// A w x h organized frame of a fronto-parallel plane at depth z: points on a 1 cm grid centred on
// the optical axis, normals facing the camera.
struct PlaneFrame {
  PointImage points;
  NormalImage normals;
  PlaneFrame(int w, int h, double z) : points(w, h), normals(w, h) {
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        points(u, v) = Point4f(0.01f * (u - w / 2) + 0.005f, 0.01f * (v - h / 2) + 0.005f,
                               static_cast<float>(z), 1.0f);
        normals(u, v) = Point4f(0, 0, -1, 0);
      }
    }
  }
};

MapFusionParams params(double voxel, int min_points = 1) {
  MapFusionParams p;
  p.voxel_size = voxel;
  p.pixel_stride = 1;
  p.min_points = min_points;
  return p;
}

TEST(MapFusion, CountsOneVoxelPerOccupiedCell) {
  const PlaneFrame frame(40, 30, 1.0);  // 40 cm x 30 cm at 1 cm spacing
  const Eigen::Isometry3d pose = Eigen::Translation3d(0.3, -0.2, 0.1) *
                                 Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized());
  MapFusion fusion(params(0.05));
  fusion.add(frame.points, frame.normals, nullptr, pose);
  // The independent count: distinct floor(p / 0.05) of the moved points.
  std::set<std::tuple<long, long, long>> cells;
  for (const Point4f& p : frame.points.pixels()) {
    const Eigen::Vector3d w = pose * p.head<3>().cast<double>();
    cells.insert({std::lround(std::floor(w.x() / 0.05)), std::lround(std::floor(w.y() / 0.05)),
                  std::lround(std::floor(w.z() / 0.05))});
  }
  EXPECT_EQ(fusion.voxel_count(), cells.size());
  EXPECT_EQ(fusion.fused_points(), 1200u);
  const PointCloud cloud = fusion.cloud();
  EXPECT_EQ(cloud.size(), cells.size());
  EXPECT_TRUE(cloud.has_normals());
  EXPECT_FALSE(cloud.has_colors());
  // Every centroid lies on the moved plane, every normal is the moved plane normal.
  const Eigen::Vector3d normal = pose.linear() * Eigen::Vector3d(0, 0, -1);
  const double offset = normal.dot(pose * Eigen::Vector3d(0, 0, 1.0));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_NEAR(normal.dot(cloud.points[i].cast<double>()), offset, 1e-5);
    EXPECT_GT(cloud.normals[i].cast<double>().dot(normal), 1 - 1e-6);
  }
}

TEST(MapFusion, AveragesColoursAndFusesOneSurfaceSeenTwice) {
  const PlaneFrame frame(20, 20, 2.0);
  RgbImage dark(20, 20, Rgb8{101, 0, 10}), light(20, 20, Rgb8{102, 255, 11});
  MapFusion fusion(params(0.1));
  fusion.add(frame.points, frame.normals, &dark, Eigen::Isometry3d::Identity());
  const std::size_t voxels = fusion.voxel_count();
  // The same wall from a camera 0.5 m back: the same world points, the same voxels.
  const PlaneFrame farther(20, 20, 2.5);
  fusion.add(farther.points, farther.normals, &light,
             Eigen::Isometry3d(Eigen::Translation3d(0, 0, -0.5)));
  EXPECT_EQ(fusion.voxel_count(), voxels);
  EXPECT_EQ(fusion.fused_points(), 800u);
  const PointCloud cloud = fusion.cloud();
  ASSERT_TRUE(cloud.has_colors());
  for (const Rgb8& c : cloud.colors) {
    EXPECT_EQ(c[0], 102);  // (101 + 102) / 2 = 101.5 rounds half up
    EXPECT_EQ(c[1], 128);  // 127.5
    EXPECT_EQ(c[2], 11);   // 10.5
  }
}

TEST(MapFusion, OpposingNormalsLeaveNoNormalAndSparseVoxelsAreDropped) {
  PlaneFrame front(1, 1, 1.0), back(1, 1, 1.0);
  back.normals(0, 0) = Point4f(0, 0, 1, 0);
  PlaneFrame far(1, 1, 3.0);
  MapFusionParams p = params(0.1);
  p.max_depth = 2.0;
  MapFusion fusion(p);
  fusion.add(front.points, front.normals, nullptr, Eigen::Isometry3d::Identity());
  fusion.add(back.points, back.normals, nullptr, Eigen::Isometry3d::Identity());
  fusion.add(far.points, far.normals, nullptr, Eigen::Isometry3d::Identity());  // beyond 2 m
  EXPECT_EQ(fusion.voxel_count(), 1u);
  const PointCloud cloud = fusion.cloud();
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_EQ(cloud.normals[0], Eigen::Vector3f::Zero());  // the two sides cancel

  // min_points: a voxel needs that many points to appear.
  MapFusion strict(params(0.1, 3));
  strict.add(front.points, front.normals, nullptr, Eigen::Isometry3d::Identity());
  strict.add(front.points, front.normals, nullptr, Eigen::Isometry3d::Identity());
  EXPECT_EQ(strict.voxel_count(), 1u);
  EXPECT_TRUE(strict.cloud().empty());
  strict.add(front.points, front.normals, nullptr, Eigen::Isometry3d::Identity());
  EXPECT_EQ(strict.cloud().size(), 1u);
}

TEST(MapFusion, SkipsInvalidPointsAndKeepsPointsWithoutNormals) {
  PlaneFrame frame(2, 1, 1.0);
  frame.points(0, 0) = invalid_point();
  frame.normals(1, 0) = invalid_point();
  MapFusion fusion(params(0.1));
  fusion.add(frame.points, frame.normals, nullptr, Eigen::Isometry3d::Identity());
  EXPECT_EQ(fusion.fused_points(), 1u);
  const PointCloud cloud = fusion.cloud();
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_EQ(cloud.normals[0], Eigen::Vector3f::Zero());
}

TEST(MapFusion, ReportsBadInput) {
  EXPECT_THROW(MapFusion(params(0.0)), Error);
  EXPECT_THROW(MapFusion(params(std::nan(""))), Error);
  MapFusionParams stride = params(0.1);
  stride.pixel_stride = 0;
  EXPECT_THROW(MapFusion{stride}, Error);
  MapFusion fusion(params(0.1));
  const PlaneFrame frame(4, 4, 1.0);
  const NormalImage small(2, 2);
  EXPECT_THROW(fusion.add(frame.points, small, nullptr, Eigen::Isometry3d::Identity()), Error);
  const RgbImage colors(3, 4);
  EXPECT_THROW(fusion.add(frame.points, frame.normals, &colors, Eigen::Isometry3d::Identity()),
               Error);
  // Far outside the grid's 2^20 cells (0.1 m cells: ~105 km).
  EXPECT_THROW(fusion.add(frame.points, frame.normals, nullptr,
                          Eigen::Isometry3d(Eigen::Translation3d(2e5, 0, 0))),
               Error);
}

}  // namespace
}  // namespace kartograf
