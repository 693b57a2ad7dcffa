// The organized laser scan: DLUT-like layout, points on the surfaces they hit, range noise with
// the configured sigma.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "kartograf/synth/laser_scan.hpp"

namespace kartograf::synth {
namespace {

TEST(SynthLaserScan, LayoutLikeTheDlutScans) {
  const LidarScanParams o;
  EXPECT_EQ(o.columns, 361);
  const Eigen::Vector3d forward = laser_beam_direction(o, 180, 80);  // azimuth 0, elevation 20
  EXPECT_NEAR(forward.y(), 0.0, 1e-12);
  EXPECT_NEAR(std::asin(forward.z()) * 180 / std::numbers::pi, 20.0, 1e-9);
  EXPECT_NEAR(laser_beam_direction(o, 0, 0).y(), -std::cos(60 * std::numbers::pi / 180),
              1e-12);  // right
  EXPECT_NEAR(laser_beam_direction(o, 0, o.lines - 1).z(), std::sin(-40 * std::numbers::pi / 180),
              1e-12);
}

TEST(SynthLaserScan, PointsLieOnTheirSurfaces) {
  const World w = make_building(2);
  const RayCaster caster(w);
  const Eigen::Isometry3d pose = default_scan_pose(w);
  EXPECT_NEAR(pose.translation().z(), 0.8, 1e-12);
  LidarScanParams exact;
  exact.range_sigma = 0;
  const LaserScan scan = scan_laser(caster, pose, exact, 1);
  ASSERT_EQ(scan.points.width(), 361);
  ASSERT_EQ(scan.points.height(), 201);
  int valid = 0;
  for (int row = 0; row < scan.points.height(); ++row) {
    for (int col = 0; col < scan.points.width(); ++col) {
      const Point4f& p = scan.points(col, row);
      if (!is_valid(p)) continue;
      ++valid;
      const Eigen::Vector3d world_point = pose * p.head<3>().cast<double>();
      const Plane& plane = w.plane(scan.plane_id(col, row));
      EXPECT_LT(std::fabs(plane.signed_distance(world_point)), 1e-5);
      EXPECT_EQ(scan.semantic(col, row), plane.semantic);
    }
  }
  EXPECT_GT(valid, 0.9 * scan.points.size());

  // Noisy: the range error along each beam has the configured sigma (10 % tolerance).
  const LaserScan noisy = scan_laser(caster, pose, LidarScanParams{}, 2);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int row = 0; row < noisy.points.height(); ++row) {
    for (int col = 0; col < noisy.points.width(); ++col) {
      const Point4f& p = noisy.points(col, row);
      if (!is_valid(p)) continue;
      const double error = p.head<3>().cast<double>().norm() - noisy.range_true(col, row);
      sum += error, sum2 += error * error, ++n;
    }
  }
  ASSERT_GT(n, 10000);
  EXPECT_NEAR(sum / n, 0.0, 0.001);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.01, 0.001);
}

}  // namespace
}  // namespace kartograf::synth
