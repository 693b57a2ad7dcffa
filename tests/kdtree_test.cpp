// The k-d tree (nanoflann) against brute force: the nearest valid point within the radius, the
// lowest index among equally near ones, the radius inclusive, the normal gate. Exact (eps = 0):
// identical indices. eps > 0: within nanoflann's (1 + eps) bound on the squared distance.
#include <algorithm>
#include <cmath>
#include <random>

#include "kartograf/registration/kdtree_correspondences.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using registration::KdTree;
using registration::kNoMatch;
using registration::NormalGate;

double squared_distance(const Eigen::Vector3d& a, const Point4f& b) {
  const double dx = a.x() - b.x(), dy = a.y() - b.y(), dz = a.z() - b.z();
  return dx * dx + dy * dy + dz * dz;
}

std::int32_t brute_force(const std::vector<Point4f>& points, const Eigen::Vector3d& query,
                         double max_distance_sq, const NormalGate* gate = nullptr) {
  std::int32_t best = kNoMatch;
  double best_distance_sq = max_distance_sq;
  for (std::size_t j = 0; j < points.size(); ++j) {
    if (!is_valid(points[j])) continue;
    const double d = squared_distance(query, points[j]);
    if (!(d < best_distance_sq || (best < 0 && d == best_distance_sq))) continue;
    if (gate && !gate->accepts(j)) continue;
    best = static_cast<std::int32_t>(j);
    best_distance_sq = d;
  }
  return best;
}

struct Cloud {
  std::vector<Point4f> points, normals;
};

// Random points with invalid ones and exact duplicates (ties for the lowest-index rule).
Cloud random_cloud(std::mt19937_64& rng, std::size_t count) {
  std::uniform_real_distribution<float> coordinate(0.0f, 1.0f);
  std::normal_distribution<double> gauss;
  Cloud cloud;
  for (std::size_t i = 0; i < count; ++i) {
    Point4f p(coordinate(rng), coordinate(rng), coordinate(rng), 1.0f);
    if (i % 10 == 9) p = cloud.points[i / 3];  // a duplicate of an earlier point
    if (i % 37 == 1) p = invalid_point();
    cloud.points.push_back(p);
    const Eigen::Vector3d n = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    cloud.normals.push_back(i % 29 == 2 ? invalid_point() : Point4f(n.x(), n.y(), n.z(), 0.0f));
  }
  return cloud;
}

TEST(KdTree, EqualsBruteForceWithTiesAndGate) {
  std::mt19937_64 rng(7);
  const Cloud cloud = random_cloud(rng, 6000);
  const KdTree tree(cloud.points, {7, 0.0f});
  EXPECT_EQ(tree.size(),
            static_cast<std::size_t>(std::count_if(cloud.points.begin(), cloud.points.end(),
                                                   [](const Point4f& p) { return is_valid(p); })));
  std::uniform_real_distribution<double> coordinate(-0.05, 1.05);
  std::size_t found = 0, ties = 0, gated = 0;
  for (int q = 0; q < 3000; ++q) {
    // Random queries, and queries exactly at a (possibly duplicated) point.
    const bool at_point = (q % 4 == 0 || q % 10 == 9) && is_valid(cloud.points[q]);
    const Eigen::Vector3d query =
        at_point ? Eigen::Vector3d(cloud.points[q].head<3>().cast<double>())
                 : Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng));
    for (double radius : {0.01, 0.04, 10.0}) {
      const std::int32_t expected = brute_force(cloud.points, query, radius * radius);
      ASSERT_EQ(tree.nearest(query, radius * radius), expected)
          << "query " << q << ", radius " << radius;
      found += expected >= 0;
      ties +=
          at_point && expected >= 0 && expected < q && cloud.points[q] == cloud.points[expected];
      const NormalGate gate{cloud.normals, Eigen::Vector3d(0.6, 0.0, 0.8), std::cos(0.6)};
      const std::int32_t expected_gated = brute_force(cloud.points, query, radius * radius, &gate);
      ASSERT_EQ(tree.nearest(query, radius * radius, &gate), expected_gated) << "gated query " << q;
      gated += expected_gated != expected;
    }
  }
  EXPECT_GT(found, 3000u);
  EXPECT_GT(ties, 10u);  // lowest index won where a duplicate came first
  EXPECT_GT(gated, 100u);
}

TEST(KdTree, RadiusIsInclusive) {
  const std::vector<Point4f> points = {Point4f(0, 0, 0, 1), Point4f(2, 0, 0, 1)};
  const KdTree tree(points);
  const Eigen::Vector3d query(0.5, 0, 0);
  EXPECT_EQ(tree.nearest(query, 0.25), 0);
  EXPECT_EQ(tree.nearest(query, std::nextafter(0.25, 0.0)), kNoMatch);
  EXPECT_EQ(tree.nearest(Eigen::Vector3d(1, 0, 0), 1.0), 0);  // equally near: the lower index
  EXPECT_EQ(KdTree(std::vector<Point4f>{invalid_point()}).nearest(query, 1e9), kNoMatch);
  EXPECT_EQ(KdTree(std::vector<Point4f>{}).nearest(query, 1e9), kNoMatch);
}

TEST(KdTree, ApproximateSearchStaysWithinItsBound) {
  std::mt19937_64 rng(11);
  const Cloud cloud = random_cloud(rng, 5000);
  const float eps = 0.5f;
  const KdTree tree(cloud.points, {10, eps});
  std::uniform_real_distribution<double> coordinate(0.0, 1.0);
  for (int q = 0; q < 2000; ++q) {
    const Eigen::Vector3d query(coordinate(rng), coordinate(rng), coordinate(rng));
    const std::int32_t exact = brute_force(cloud.points, query, 1e9);
    const std::int32_t approximate = tree.nearest(query, 1e9);
    ASSERT_GE(approximate, 0);
    EXPECT_LE(squared_distance(query, cloud.points[approximate]),
              (1 + eps) * squared_distance(query, cloud.points[exact]) * (1 + 1e-12));
  }
}

TEST(KdTree, RejectsBadParameters) {
  const std::vector<Point4f> points(3, Point4f(0, 0, 0, 1));
  EXPECT_THROW(KdTree(points, {0, 0.0f}), Error);
  EXPECT_THROW(KdTree(points, {10, -1.0f}), Error);
  EXPECT_THROW(KdTree(points, {10, std::nanf("")}), Error);
}

}  // namespace
}  // namespace kartograf
