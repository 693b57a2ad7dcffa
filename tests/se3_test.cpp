// SE(3) exp/log and adjoint (core/se3.hpp) against closed forms and round trips.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "kartograf/core/se3.hpp"
#include "se3_random.hpp"

namespace kartograf {
namespace {

using se3::Vector6d;
using testing::random_twist;

TEST(Se3, ExpLogRoundTrip) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const double scale = trial < 100 ? 1.5 : 1e-9;  // large angles and the Taylor branch
    const Vector6d xi = random_twist(rng, scale, 2.0 * scale);
    const Vector6d back = se3::log(se3::exp(xi));
    EXPECT_LT((back - xi).norm(), 1e-9 * std::max(1.0, xi.norm())) << xi.transpose();
  }
}

TEST(Se3, ExpMatchesAngleAxisRotation) {
  Vector6d xi;
  xi << 0, 0, M_PI / 2, 1, 0, 0;
  const Eigen::Isometry3d pose = se3::exp(xi);
  EXPECT_NEAR(
      (pose.linear() - Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix())
          .norm(),
      0, 1e-12);
  // Moving 1 m along x while turning 90 degrees about z traces a quarter circle of radius 2/pi.
  EXPECT_NEAR(pose.translation().x(), 2 / M_PI, 1e-12);
  EXPECT_NEAR(pose.translation().y(), 2 / M_PI, 1e-12);
}

TEST(Se3, AdjointConjugates) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Isometry3d t = se3::exp(random_twist(rng, 1.0, 3.0));
    const Vector6d xi = random_twist(rng, 0.5, 0.5);
    const Eigen::Isometry3d lhs = t * se3::exp(xi) * t.inverse();
    const Eigen::Isometry3d rhs = se3::exp(se3::adjoint(t) * xi);
    EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-10);
  }
}

}  // namespace
}  // namespace kartograf
