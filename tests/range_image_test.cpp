// Range images of unorganized clouds (geometry/range_image.hpp): where points land, occlusion of
// far points seen through a sparse near surface, bad input; and the M2 labelling of a range image
// made from a merged map of two synthetic laser scans against the world's exact labels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/semantic_metrics.hpp"
#include "kartograf/geometry/range_image.hpp"
#include "kartograf/semantic/classify.hpp"
#include "kartograf/synth/laser_scan.hpp"
#include "kartograf/synth/ray_caster.hpp"

namespace kartograf::geometry {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

int count_valid(const RangeImage& image) {
  return static_cast<int>(std::count_if(image.index.pixels().begin(), image.index.pixels().end(),
                                        [](std::int32_t i) { return i >= 0; }));
}

TEST(RangeImage, PlacesPointsByAzimuthAndElevationAroundTheViewpoint) {
  RangeImageParams params;
  params.angular_step_deg = 1.0;
  params.min_elevation_deg = -45, params.max_elevation_deg = 45;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(1, 2, 3);
  const double a = 30.3 * kDegree, e = 10.4 * kDegree;
  const std::vector<Eigen::Vector3f> points = {
      Eigen::Vector3f(3.5f, 2, 3),  // straight ahead
      (pose * (2.0 * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a),
                                     std::sin(e))))
          .cast<float>(),           // 30 deg left, 10 deg up
      Eigen::Vector3f(1, 2, 8),     // above the elevation range: left out
      Eigen::Vector3f(NAN, 0, 0)};  // not finite: skipped
  const RangeImage image = make_range_image(points, pose, params);
  ASSERT_EQ(image.points.width(), 360);
  ASSERT_EQ(image.points.height(), 90);
  EXPECT_EQ(count_valid(image), 2);
  EXPECT_EQ(image.index(180, 45), 0);  // azimuth 0 is the middle column, elevation 0 row 45
  EXPECT_NEAR(image.points(180, 45).x(), 2.5f, 1e-6f);
  EXPECT_EQ(image.index(180 - 31, 45 - 11), 1);  // left turns towards column 0
  EXPECT_NEAR(image.points(180 - 31, 45 - 11).head<3>().norm(), 2.0f, 1e-5f);
}

TEST(RangeImage, ANearSparseSurfaceHidesWhatLiesBehindIt) {
  // A square of 0.5 m 1 m ahead sampled every 2 cm, and a dense wall 4 m ahead behind it.
  std::vector<Eigen::Vector3f> points;
  for (float y = -0.25f; y <= 0.25f; y += 0.02f)
    for (float z = -0.25f; z <= 0.25f; z += 0.02f) points.emplace_back(1.0f, y, z);
  const std::size_t near_count = points.size();
  for (float y = -2.0f; y <= 2.0f; y += 0.004f)
    for (float z = -2.0f; z <= 2.0f; z += 0.004f) points.emplace_back(4.0f, y, z);
  RangeImageParams params;
  params.angular_step_deg = 0.25;  // 0.44 cm at 1 m: most pixels of the near wall get no sample
  const RangeImage image = make_range_image(points, Eigen::Isometry3d::Identity(), params);
  int near_pixels = 0, far_inside = 0, far_outside = 0;
  for (int y = 0; y < image.points.height(); ++y) {
    for (int x = 0; x < image.points.width(); ++x) {
      const std::int32_t i = image.index(x, y);
      if (i < 0) continue;
      const Point4f& p = image.points(x, y);
      if (static_cast<std::size_t>(i) < near_count) {
        ++near_pixels;
      } else if (std::fabs(p.y() / p.x()) < 0.22 && std::fabs(p.z() / p.x()) < 0.22) {
        ++far_inside;  // behind the near wall
      } else {
        ++far_outside;
      }
    }
  }
  EXPECT_GT(near_pixels, 500);
  EXPECT_EQ(far_inside, 0);
  EXPECT_GT(far_outside, 10000);

  params.surface_radius = 0;  // without occlusion the far wall shows through the gaps
  const RangeImage see_through = make_range_image(points, Eigen::Isometry3d::Identity(), params);
  EXPECT_GT(count_valid(see_through), count_valid(image) + 10000);
}

TEST(RangeImage, RejectsBadParametersAndPoses) {
  const std::vector<Eigen::Vector3f> points = {Eigen::Vector3f(1, 0, 0)};
  RangeImageParams params;
  params.angular_step_deg = 0;
  EXPECT_THROW(make_range_image(points, Eigen::Isometry3d::Identity(), params), Error);
  params = {};
  params.min_elevation_deg = 50, params.max_elevation_deg = 40;
  EXPECT_THROW(make_range_image(points, Eigen::Isometry3d::Identity(), params), Error);
  params = {};
  params.max_range = params.min_range;
  EXPECT_THROW(make_range_image(points, Eigen::Isometry3d::Identity(), params), Error);
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = NAN;
  EXPECT_THROW(make_range_image(points, bad, {}), Error);
  EXPECT_EQ(count_valid(make_range_image({}, Eigen::Isometry3d::Identity(), {})), 0);
}

// Two scans of one room merged into an unorganized map, shuffled; labelled from a 1-degree range
// image at a third viewpoint (0.5 degrees leaves most pixels of the scans' 0.5 x 0.6 degree
// sampling empty from elsewhere): floor, wall and ceiling IoU >= 0.9, door >= 0.8, scored on the
// exact labels of the points the image shows.
TEST(RangeImage, LabelsAMapOfTwoMergedScans) {
  const synth::World world = synth::make_building(5);
  const synth::RayCaster caster(world);
  synth::LidarScanParams options;
  options.columns = 361;
  options.lines = 161;
  options.threads = 2;
  const Eigen::Isometry3d first = synth::default_scan_pose(world);
  Eigen::Isometry3d second = first;
  second.translation() += first.linear() * Eigen::Vector3d(0.6, 0.4, 0.0);
  second.rotate(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitZ()));  // looking back
  std::vector<Eigen::Vector3f> map;
  std::vector<SemanticClass> truth;
  for (const auto& [pose, seed] : {std::pair{first, 3}, std::pair{second, 4}}) {
    const synth::LaserScan scan = synth::scan_laser(caster, pose, options, seed);
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      const Point4f& p = scan.points.pixels()[i];
      if (!is_valid(p)) continue;
      map.push_back((pose * p.head<3>().cast<double>()).cast<float>());
      truth.push_back(scan.semantic.pixels()[i]);
    }
  }
  std::vector<std::size_t> order(map.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  std::vector<Eigen::Vector3f> shuffled(map.size());
  std::vector<SemanticClass> shuffled_truth(map.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    shuffled[i] = map[order[i]];
    shuffled_truth[i] = truth[order[i]];
  }
  Eigen::Isometry3d view = first;
  view.translation() += first.linear() * Eigen::Vector3d(0.3, -0.3, 0.0);
  RangeImageParams range_params;
  range_params.angular_step_deg = 1.0;
  const RangeImage image = make_range_image(shuffled, view, range_params);
  semantic::LabellingParams params;
  params.normals.smoothing_radius = 2;
  const semantic::SemanticLabelling labelling =
      semantic::label_organized_points(compute::Context::cpu(), image.points, params);
  SemanticImage expected(image.points.width(), image.points.height(), SemanticClass::unknown);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const std::int32_t k = image.index.pixels()[i];
    if (k >= 0 && shuffled_truth[static_cast<std::size_t>(k)] != SemanticClass::furniture)
      expected.pixels()[i] = shuffled_truth[static_cast<std::size_t>(k)];
  }
  const auto s = eval::evaluate_semantic_segmentation(expected, labelling.semantic);
  const auto iou = [&](SemanticClass c) {
    return s.iou[static_cast<std::size_t>(c)].value_or(-1.0);
  };
  EXPECT_GE(iou(SemanticClass::floor), 0.9);
  EXPECT_GE(iou(SemanticClass::ceiling), 0.9);
  EXPECT_GE(iou(SemanticClass::wall), 0.9);
  EXPECT_GE(iou(SemanticClass::door), 0.8);  // a leaf standing open in view
  EXPECT_GT(labelling.gravity.up.dot(view.linear().transpose() * Eigen::Vector3d::UnitZ()),
            std::cos(2 * kDegree));
}

}  // namespace
}  // namespace kartograf::geometry
