// Rigid RANSAC (registration/rigid_ransac.hpp) on synthetic point pairs with a known motion,
// Gaussian noise and gross outliers: the motion and the inlier set come back, too little
// agreement gives nothing, and a seed fixes the answer.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "kartograf/core/se3.hpp"
#include "kartograf/registration/rigid_ransac.hpp"
#include "se3_random.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using registration::estimate_rigid_ransac;
using registration::RigidRansacParams;

struct PairSet {
  std::vector<Eigen::Vector3d> source, target;
  std::vector<bool> is_inlier;
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
};

// A point where a depth camera sees: x, y within +-1.5 m, depth 0.5-4 m.
Eigen::Vector3d camera_point(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> lateral(-1.5, 1.5), depth(0.5, 4.0);
  return {lateral(rng), lateral(rng), depth(rng)};
}

// `count` pairs, the first `inliers` of them target = motion * source + N(0, noise) per axis, the
// others matched to a random point at least 0.3 m from where the source point really went.
PairSet make_pairs(std::size_t count, std::size_t inliers, double noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  PairSet set;
  set.motion = se3::exp(testing::random_twist(rng, 0.4, 0.5));
  std::normal_distribution<double> gauss(0.0, noise);
  for (std::size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d s = camera_point(rng);
    const Eigen::Vector3d moved = set.motion * s;
    Eigen::Vector3d t = moved + Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    if (i >= inliers) {
      do t = camera_point(rng);
      while ((t - moved).norm() < 0.3);
    }
    set.source.push_back(s);
    set.target.push_back(t);
    set.is_inlier.push_back(i < inliers);
  }
  return set;
}

double rotation_error_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / std::numbers::pi;
}

TEST(RigidRansac, RecoversTheMotionAndTheInliersWith40PercentOutliers) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    const PairSet set = make_pairs(200, 120, 0.002, seed);
    const auto result = estimate_rigid_ransac(set.source, set.target);
    ASSERT_TRUE(result.has_value());
    EXPECT_LT((result->source_to_target.translation() - set.motion.translation()).norm(), 0.001);
    EXPECT_LT(rotation_error_deg(result->source_to_target, set.motion), 0.05);
    EXPECT_EQ(result->inlier_mask, set.is_inlier);
    EXPECT_EQ(result->inliers, 120u);
    // 3-D noise of 2 mm per axis: an RMSE of about 2 mm * sqrt(3).
    EXPECT_GT(result->inlier_rmse_m, 0.002);
    EXPECT_LT(result->inlier_rmse_m, 0.0045);
    // 60 % inliers: about 30 samples suffice for a 1e-3 miss probability.
    EXPECT_LT(result->iterations, 200u);
  }
}

TEST(RigidRansac, TooFewAgreeingPairsGiveNothing) {
  const PairSet set = make_pairs(200, 12, 0.002, 4);
  EXPECT_FALSE(estimate_rigid_ransac(set.source, set.target).has_value());  // 12 < 15
  // The same 12 pairs are found once they are enough, given the samples that 6 % inliers need.
  RigidRansacParams lenient;
  lenient.min_inliers = 8;
  lenient.max_iterations = 100000;
  const auto found = estimate_rigid_ransac(set.source, set.target, lenient);
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->inliers, 12u);
  EXPECT_FALSE(estimate_rigid_ransac({}, {}).has_value());
}

TEST(RigidRansac, CollinearPointsGiveNothing) {
  // Every sample is degenerate: the rotation about the line is free.
  std::vector<Eigen::Vector3d> source, target;
  for (int i = 0; i < 50; ++i) {
    source.emplace_back(0.1 * i, 0.0, 2.0);
    target.emplace_back(0.1 * i, 0.5, 2.0);
  }
  EXPECT_FALSE(estimate_rigid_ransac(source, target).has_value());
}

TEST(RigidRansac, TheSeedFixesTheAnswer) {
  const PairSet set = make_pairs(200, 80, 0.003, 5);
  RigidRansacParams params;
  params.seed = 42;
  const auto a = estimate_rigid_ransac(set.source, set.target, params);
  const auto b = estimate_rigid_ransac(set.source, set.target, params);
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(a->source_to_target.matrix() == b->source_to_target.matrix());
  EXPECT_EQ(a->iterations, b->iterations);
  EXPECT_EQ(a->inlier_mask, b->inlier_mask);
  params.seed = 43;  // another stream draws other samples, and still finds the motion
  const auto c = estimate_rigid_ransac(set.source, set.target, params);
  ASSERT_TRUE(c.has_value());
  EXPECT_LT((c->source_to_target.translation() - set.motion.translation()).norm(), 0.002);
}

TEST(RigidRansac, DepthGrowsTheInlierRadius) {
  // A 5 cm error is an outlier at 1 m (radius 3 cm) and an inlier at 4 m (radius 6 cm).
  std::mt19937_64 rng(6);
  std::vector<Eigen::Vector3d> source, target;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d s = camera_point(rng);
    source.push_back(s);
    target.push_back(s);
  }
  source.emplace_back(0.2, 0.1, 1.0);
  target.emplace_back(0.25, 0.1, 1.0);
  source.emplace_back(0.2, 0.1, 4.0);
  target.emplace_back(0.25, 0.1, 4.0);
  const auto result = estimate_rigid_ransac(source, target);
  ASSERT_TRUE(result.has_value());
  EXPECT_FALSE(result->inlier_mask[40]);
  EXPECT_TRUE(result->inlier_mask[41]);
}

TEST(RigidRansac, MismatchedListsAreAnError) {
  const std::vector<Eigen::Vector3d> three(3, Eigen::Vector3d::Zero()), two(2);
  EXPECT_ERROR_MENTIONS(estimate_rigid_ransac(three, two), "3 source points", "2 target points");
  RigidRansacParams params;
  params.inlier_base_m = 0;
  EXPECT_ERROR_MENTIONS(estimate_rigid_ransac(three, three, params), "inlier_base_m");
}

}  // namespace
}  // namespace kartograf
