// The ICP solvers and the analysis of the normal equations (registration/rigid_solvers.hpp):
// host arithmetic on sums built here in double, with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kartograf/registration/rigid_solvers.hpp"

namespace kartograf {
namespace {

using registration::PointToPlaneSystem;
using registration::PointToPointSums;

struct Pair {
  Eigen::Vector3d source = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

// The sums IcpReduction would return for these pairs (weights 1, pivot = source mean).
PointToPointSums point_sums(const std::vector<Pair>& pairs) {
  PointToPointSums sums;
  sums.pair_count = pairs.size();
  sums.weight_sum = static_cast<double>(pairs.size());
  for (const Pair& p : pairs) {
    sums.source_mean += p.source / sums.weight_sum;
    sums.target_mean += p.target / sums.weight_sum;
  }
  for (const Pair& p : pairs) {
    sums.cross_covariance +=
        (p.source - sums.source_mean) * (p.target - sums.target_mean).transpose();
    sums.source_scatter +=
        (p.source - sums.source_mean) * (p.source - sums.source_mean).transpose();
  }
  return sums;
}

PointToPlaneSystem plane_system(const std::vector<Pair>& pairs, const Eigen::Vector3d& pivot) {
  PointToPlaneSystem system;
  system.pair_count = pairs.size();
  system.weight_sum = static_cast<double>(pairs.size());
  system.pivot = pivot;
  for (const Pair& p : pairs) {
    se3::Vector6d j;
    j << (p.source - pivot).cross(p.normal), p.normal;
    const double r = (p.source - p.target).dot(p.normal);
    system.jtj += j * j.transpose();
    system.jtr += j * r;
  }
  return system;
}

Eigen::Isometry3d motion(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  return Eigen::Translation3d(t) * Eigen::AngleAxisd(angle, axis.normalized());
}

TEST(RigidSolvers, PointToPointRecoversAnExactMotion) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  const Eigen::Isometry3d truth = motion(0.7, {1, -2, 0.5}, {0.3, -0.1, 0.2});
  std::vector<Pair> pairs;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d p(coordinate(rng), coordinate(rng), 2 + coordinate(rng));
    pairs.push_back({p, truth * p, Eigen::Vector3d::Zero()});
  }
  const auto delta = registration::solve_point_to_point(point_sums(pairs));
  ASSERT_TRUE(delta.has_value());
  EXPECT_LT((delta->matrix() - truth.matrix()).norm(), 1e-12);
  pairs.resize(2);
  EXPECT_FALSE(registration::solve_point_to_point(point_sums(pairs)).has_value());
}

TEST(RigidSolvers, PointToPointGuardsAgainstReflections) {
  // Targets mirrored through the plane z = 2: the unguarded SVD answer is that reflection.
  std::vector<Pair> pairs;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(1, 0, 2.5), Eigen::Vector3d(-1, 0.5, 1.6),
                                   Eigen::Vector3d(0, -1, 2.2), Eigen::Vector3d(0.3, 0.8, 1.7)}) {
    pairs.push_back({p, Eigen::Vector3d(p.x(), p.y(), 4 - p.z()), Eigen::Vector3d::Zero()});
  }
  const PointToPointSums sums = point_sums(pairs);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sums.cross_covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  ASSERT_LT((svd.matrixV() * svd.matrixU().transpose()).determinant(), 0);  // the trap is set
  const auto delta = registration::solve_point_to_point(sums);
  ASSERT_TRUE(delta.has_value());
  EXPECT_NEAR(delta->linear().determinant(), 1.0, 1e-12);
  EXPECT_LT((delta->linear() * delta->linear().transpose() - Eigen::Matrix3d::Identity()).norm(),
            1e-12);
}

TEST(RigidSolvers, PointToPlaneStepIsGaussNewtonAboutThePivot) {
  // Planes of a box corner; targets on the planes through the moved points: one step from a
  // small motion lands within second-order error, and iterating converges to the motion.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  const Eigen::Isometry3d truth = motion(0.01, {1, 2, 3}, {0.01, -0.005, 0.008});
  const Eigen::Vector3d pivot(0.1, 0.2, 2.0);
  std::vector<Pair> pairs;
  for (int i = 0; i < 300; ++i) {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    normal(i % 3) = 1;
    const Eigen::Vector3d p(coordinate(rng), coordinate(rng), 2 + coordinate(rng));
    pairs.push_back(
        {p,
         truth * p +
             Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng)).cross(normal) * 0.1,
         normal});
  }
  Eigen::Isometry3d estimate = Eigen::Isometry3d::Identity();
  for (int iteration = 0; iteration < 5; ++iteration) {
    std::vector<Pair> moved = pairs;
    for (Pair& p : moved) p.source = estimate * p.source;
    const auto delta = registration::solve_point_to_plane(plane_system(moved, estimate * pivot));
    ASSERT_TRUE(delta.has_value());
    estimate = *delta * estimate;
    if (iteration == 0) {
      EXPECT_LT((estimate.matrix() - truth.matrix()).norm(), 1e-3);
    }
  }
  EXPECT_LT((estimate.matrix() - truth.matrix()).norm(), 1e-12);
  pairs.resize(5);
  EXPECT_FALSE(registration::solve_point_to_plane(plane_system(pairs, pivot)).has_value());
}

TEST(RigidSolvers, RightPerturbationInformationMatchesTheCost) {
  // x^T H x for the left motion about the pivot equals xi^T H_right xi for the same new pose.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0, 1);
  se3::Matrix6d a;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) a(r, c) = normal(rng);
  }
  const se3::Matrix6d h = a * a.transpose();
  const Eigen::Vector3d pivot(0.4, -0.3, 2.5);
  const Eigen::Isometry3d pose = motion(0.4, {0.2, 1, -0.3}, {0.5, 0.1, -0.2});
  const se3::Matrix6d right = registration::to_right_perturbation(h, pivot, pose);
  se3::Vector6d xi;
  xi << 1e-6, -2e-6, 1.5e-6, 3e-6, 1e-6, -2e-6;
  const Eigen::Isometry3d moved = pose * se3::exp(xi);
  // The left motion about the pivot that gives the same pose.
  const Eigen::Translation3d to_pivot(pivot);
  const se3::Vector6d x = se3::log(to_pivot.inverse() * moved * pose.inverse() * to_pivot);
  const double left_cost = x.dot(h * x), right_cost = xi.dot(right * xi);
  EXPECT_NEAR(right_cost, left_cost, 1e-6 * left_cost);
}

se3::Matrix6d plane_hessian(const std::vector<Eigen::Vector3d>& normals, int points_per_plane,
                            std::mt19937_64& rng) {
  std::uniform_real_distribution<double> coordinate(-1, 1);
  std::vector<Pair> pairs;
  for (const Eigen::Vector3d& n : normals) {
    for (int i = 0; i < points_per_plane; ++i) {
      const Eigen::Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
      pairs.push_back(
          {p - n * n.dot(p), Eigen::Vector3d::Zero(), n});  // on the plane through the origin
    }
  }
  return plane_system(pairs, Eigen::Vector3d::Zero()).jtj;
}

TEST(RigidSolvers, DegeneracyFindsTheUnconstrainedDirection) {
  std::mt19937_64 rng(5);
  const auto corner = registration::analyse_degeneracy(
      plane_hessian({Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()},
                    200, rng),
      0.01);
  EXPECT_FALSE(corner.degenerate);
  EXPECT_GT(corner.eigenvalue_ratio, 0.1);
  EXPECT_NEAR(corner.eigenvalues.sum(), 6.0, 1e-9);

  // A corridor along z: two walls (x) and a floor (y); translation along z is free.
  const auto corridor = registration::analyse_degeneracy(
      plane_hessian({Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()},
                    200, rng),
      0.01);
  EXPECT_TRUE(corridor.degenerate);
  EXPECT_LT(corridor.eigenvalue_ratio, 1e-12);
  EXPECT_NEAR(std::fabs(corridor.weakest_direction(5)), 1.0, 1e-6);

  const auto plane =
      registration::analyse_degeneracy(plane_hessian({Eigen::Vector3d::UnitZ()}, 300, rng), 0.01);
  EXPECT_TRUE(plane.degenerate);
  EXPECT_LT(plane.eigenvalues(2), 1e-12);  // three free directions: x, y, rotation about z
  EXPECT_GT(plane.eigenvalues(3), 0.1);

  const auto empty = registration::analyse_degeneracy(se3::Matrix6d::Zero(), 0.01);
  EXPECT_TRUE(empty.degenerate);
}

}  // namespace
}  // namespace kartograf
