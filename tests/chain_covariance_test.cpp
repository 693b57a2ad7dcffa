// The odometry chain's covariance (loop closure's plausibility gate where features are silent).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/core/se3.hpp"
#include "kartograf/mapping/chain_covariance.hpp"
#include "se3_random.hpp"

namespace kartograf {
namespace {

using se3::Matrix6d;
using se3::Vector6d;
using testing::random_twist;

struct Chain {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<registration::RelativePose> steps;
};

// A random walk of `count` steps, each with its own diagonal covariance.
Chain random_chain(std::mt19937_64& rng, std::size_t count) {
  Chain chain;
  chain.poses.push_back(se3::exp(random_twist(rng, 1.0, 2.0)));
  std::uniform_real_distribution<double> sigma(0.002, 0.02);
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Isometry3d motion = se3::exp(random_twist(rng, 0.3, 0.5));
    chain.poses.push_back(chain.poses.back() * motion);
    Vector6d variances;
    for (int d = 0; d < 6; ++d) variances(d) = std::pow(sigma(rng), 2);
    const Matrix6d information = variances.cwiseInverse().asDiagonal();
    chain.steps.push_back({k, k + 1, motion, information, false});
  }
  return chain;
}

// The first-order covariance matches the spread of the chained motion when every step is
// perturbed by its own noise (20000 samples: within 10 % of each standard deviation, and the
// correlations within 0.05).
TEST(ChainCovariance, MatchesTheSpreadOfPerturbedChains) {
  std::mt19937_64 rng(7);
  const Chain chain = random_chain(rng, 6);
  const std::size_t from = 1, to = 6;
  const Matrix6d predicted = mapping::chain_covariance(chain.steps, chain.poses, from, to);
  const Eigen::Isometry3d nominal = chain.poses[from].inverse() * chain.poses[to];
  std::normal_distribution<double> normal;
  Matrix6d spread = Matrix6d::Zero();
  const int samples = 20000;
  for (int s = 0; s < samples; ++s) {
    Eigen::Isometry3d chained = Eigen::Isometry3d::Identity();
    for (std::size_t k = from; k < to; ++k) {
      const registration::RelativePose& step = chain.steps[k];
      Vector6d xi;
      for (int d = 0; d < 6; ++d) xi(d) = normal(rng) / std::sqrt(step.information(d, d));
      chained = chained * step.motion * se3::exp(xi);
    }
    const Vector6d error = se3::log(nominal.inverse() * chained);
    spread += error * error.transpose() / samples;
  }
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(std::sqrt(spread(i, i)), std::sqrt(predicted(i, i)),
                0.1 * std::sqrt(predicted(i, i)));
    for (int j = 0; j < i; ++j) {
      const double scale = std::sqrt(predicted(i, i) * predicted(j, j));
      EXPECT_NEAR(spread(i, j) / scale, predicted(i, j) / scale, 0.05) << i << "," << j;
    }
  }
}

// One step's chain is that step's covariance; a rotation early in a long chain moves the end
// sideways (the lever arm), so the end's translation is less certain than the steps alone say.
TEST(ChainCovariance, OneStepIsItsOwnCovarianceAndEarlyRotationsSwingTheEnd) {
  std::mt19937_64 rng(3);
  const Chain chain = random_chain(rng, 4);
  const Matrix6d one = mapping::chain_covariance(chain.steps, chain.poses, 2, 3);
  EXPECT_TRUE(one.isApprox(Matrix6d(chain.steps[2].information.inverse()), 1e-9));

  Chain straight;
  straight.poses.push_back(Eigen::Isometry3d::Identity());
  for (std::size_t k = 0; k < 10; ++k) {
    const Eigen::Isometry3d motion(Eigen::Translation3d(0, 0, 1));
    straight.poses.push_back(straight.poses.back() * motion);
    Vector6d variances;
    variances << 1e-6, 1e-6, 1e-6, 1e-8, 1e-8, 1e-8;
    straight.steps.push_back(
        {k, k + 1, motion, Matrix6d(variances.cwiseInverse().asDiagonal()), false});
  }
  const Matrix6d swing = mapping::chain_covariance(straight.steps, straight.poses, 0, 10);
  // Sideways (x) at the end: sum over steps of (lever arm)^2 x 1e-6 rad^2, far above 10 x 1e-8.
  EXPECT_GT(swing(3, 3), 100 * 10 * 1e-8);
  EXPECT_NEAR(swing(5, 5), 10 * 1e-8, 1e-12);  // along the chain: no lever arm
}

TEST(ChainCovariance, MahalanobisDistanceOfACorrection) {
  Matrix6d covariance = Matrix6d::Identity() * 1e-4;
  covariance(3, 3) = 0.25;  // 0.5 m along x
  const Eigen::Isometry3d along(Eigen::Translation3d(0.5, 0, 0));
  const Eigen::Isometry3d across(Eigen::Translation3d(0, 0.5, 0));
  EXPECT_NEAR(mapping::mahalanobis_squared(along, covariance), 1.0, 1e-9);
  EXPECT_NEAR(mapping::mahalanobis_squared(across, covariance), 2500.0, 1e-6);
}

TEST(ChainCovariance, RejectsMissingStepsBadRangesAndSingularInformation) {
  std::mt19937_64 rng(5);
  Chain chain = random_chain(rng, 4);
  EXPECT_THROW(mapping::chain_covariance(chain.steps, chain.poses, 2, 2), Error);
  EXPECT_THROW(mapping::chain_covariance(chain.steps, chain.poses, 0, 5), Error);
  std::vector<registration::RelativePose> gap = chain.steps;
  gap.erase(gap.begin() + 2);
  EXPECT_THROW(mapping::chain_covariance(gap, chain.poses, 0, 4), Error);
  EXPECT_NO_THROW(mapping::chain_covariance(gap, chain.poses, 3, 4));
  chain.steps[1].information(4, 4) = 0;
  EXPECT_THROW(mapping::chain_covariance(chain.steps, chain.poses, 0, 4), Error);
}

}  // namespace
}  // namespace kartograf
