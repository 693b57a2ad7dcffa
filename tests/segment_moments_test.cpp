// Per-label moments on every backend vs an all-double reference.
// Stated tolerance: counts exact; per label, |sum error| <= 1e-6 * sum |d| and
// ||sum_outer error||_F <= 1e-6 * sum |d|^2 (d = p - origin); and bit-identical to the CPU backend.
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/segment_moments.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using geometry::SegmentMomentParams;
using geometry::SegmentMomentSet;
using testing::BackendTest;

struct ReferenceMoments {
  std::uint64_t count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();
  double sum_norm = 0;     // sum |d|
  double sum_norm_sq = 0;  // sum |d|^2
};

SegmentMomentSet run(const compute::Context& context, const std::vector<Point4f>& points,
                     const std::vector<std::uint32_t>& labels, const SegmentMomentParams& params) {
  const auto device_points = compute::Buffer<Point4f>::from_host(context, points);
  const auto device_labels = compute::Buffer<std::uint32_t>::from_host(context, labels);
  return geometry::segment_moments(context, device_points, device_labels, params);
}

double check(const compute::Context& context, const std::vector<Point4f>& points,
             const std::vector<std::uint32_t>& labels, const SegmentMomentParams& params,
             const std::string& what) {
  std::vector<ReferenceMoments> expected(params.label_count);
  const Eigen::Vector3d origin = params.origin.cast<double>();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (labels[i] == geometry::kNoLabel || !is_valid(points[i])) continue;
    const Eigen::Vector3d d = points[i].head<3>().cast<double>() - origin;
    ReferenceMoments& m = expected.at(labels[i]);
    ++m.count;
    m.sum += d;
    m.sum_outer += d * d.transpose();
    m.sum_norm += d.norm();
    m.sum_norm_sq += d.squaredNorm();
  }
  const SegmentMomentSet actual = run(context, points, labels, params);
  EXPECT_EQ(actual.segments.size(), params.label_count);
  double worst = 0;
  std::size_t count_errors = 0;
  for (std::size_t label = 0; label < expected.size(); ++label) {
    const auto& e = expected[label];
    const auto& a = actual.segments[label];
    count_errors += a.count != e.count;
    if (e.count == 0) continue;
    worst = std::max({worst, (a.sum - e.sum).norm() / std::max(e.sum_norm, 1e-30),
                      (a.sum_outer - e.sum_outer).norm() / std::max(e.sum_norm_sq, 1e-30)});
  }
  EXPECT_EQ(count_errors, 0u) << what;
  EXPECT_LE(worst, 1e-6) << what;
  return worst;
}

class SegmentMomentsTest : public BackendTest {};

TEST_P(SegmentMomentsTest, MatchesReferenceOnRandomLabels) {
  for (std::uint32_t label_count : {1u, 300u, 65536u}) {
    const std::size_t count = 640 * 480;
    std::vector<Point4f> points(count);
    std::vector<std::uint32_t> labels(count);
    std::uniform_real_distribution<float> coordinate(-3.0f, 3.0f);
    std::uniform_int_distribution<std::uint32_t> label(0, label_count - 1);
    for (std::size_t i = 0; i < count; ++i) {
      points[i] = Point4f(coordinate(rng), coordinate(rng), coordinate(rng) + 3.5f, 1.0f);
      if (i % 50 == 1) points[i] = invalid_point();
      labels[i] = i % 23 == 2 ? geometry::kNoLabel : label(rng);
    }
    SegmentMomentParams params;
    params.label_count = label_count;
    params.origin = Eigen::Vector3f(0.1f, -0.2f, 3.4f);
    params.max_offset = 8.0f;
    const double worst = check(context(), points, labels, params, std::to_string(label_count) + " labels");
    RecordProperty("max_relative_error_" + std::to_string(label_count), testing::scientific(worst));
  }
}

TEST_P(SegmentMomentsTest, MatchesReferenceAndCpuBitForBitOnSevenScenes) {
  // Labels: 20x20-pixel tiles of a real frame (~770 segments of planes and clutter).
  const compute::Context cpu = compute::Context::cpu();
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_7scenes();
  const PointImage image =
      geometry::backproject(cpu, testing::read_depth(frames / "frame-000100.depth.png"), k);
  std::vector<Point4f> points(image.pixels().begin(), image.pixels().end());
  std::vector<std::uint32_t> labels(points.size());
  const int tiles_x = (k.width + 19) / 20;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) labels[v * k.width + u] = (v / 20) * tiles_x + u / 20;
  }
  SegmentMomentParams params;
  params.label_count = tiles_x * ((k.height + 19) / 20);
  params.origin = Eigen::Vector3f(0.0f, 0.0f, 2.0f);
  const double worst = check(context(), points, labels, params, "7-Scenes frame 100");
  RecordProperty("max_relative_error_7scenes", testing::scientific(worst));

  const SegmentMomentSet mine = run(context(), points, labels, params);
  const SegmentMomentSet reference = run(cpu, points, labels, params);
  for (std::size_t label = 0; label < params.label_count; ++label) {
    ASSERT_EQ(mine.segments[label].count, reference.segments[label].count) << label;
    ASSERT_EQ(mine.segments[label].sum, reference.segments[label].sum) << label;
    ASSERT_EQ(mine.segments[label].sum_outer, reference.segments[label].sum_outer) << label;
  }
}

TEST_P(SegmentMomentsTest, PlaneCovarianceHasFlatDirection) {
  // Points on the plane z = 2 + 0.5 x: the covariance's smallest eigenvector is its normal.
  std::vector<Point4f> points;
  std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    const float x = coordinate(rng), y = coordinate(rng);
    points.emplace_back(x, y, 2.0f + 0.5f * x, 1.0f);
  }
  SegmentMomentParams params;
  params.label_count = 1;
  const auto set = run(context(), points, std::vector<std::uint32_t>(points.size(), 0), params);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(set.covariance(0));
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);
  EXPECT_NEAR(std::fabs(normal.dot(Eigen::Vector3d(-0.5, 0, 1).normalized())), 1.0, 1e-6);
  EXPECT_LT(solver.eigenvalues()(0), 1e-9);
  EXPECT_NEAR(set.centroid(0).z(), 2.0, 0.01);
}

TEST_P(SegmentMomentsTest, ReportsBadLabelsAndFarPoints) {
  std::vector<Point4f> points(100, Point4f(0, 0, 1, 1));
  std::vector<std::uint32_t> labels(100, 0);
  SegmentMomentParams params;
  params.label_count = 4;
  labels[7] = 4;
  EXPECT_ERROR_MENTIONS(run(context(), points, labels, params), "label");  // out of range
  labels[7] = 0;
  points[3] = Point4f(100, 0, 1, 1);
  EXPECT_THROW(run(context(), points, labels, params), Error);
  params.label_count = 65537;
  EXPECT_THROW(run(context(), points, labels, params), Error);
  params.label_count = 4;
  EXPECT_THROW(run(context(), points, std::vector<std::uint32_t>(99, 0), params), Error);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(SegmentMomentsTest);

}  // namespace
}  // namespace kartograf
