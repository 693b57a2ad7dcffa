// pose_at (core/trajectory.hpp): a trajectory's pose between its samples, and where it has none.
#include <gtest/gtest.h>

#include <cmath>

#include "kartograf/core/trajectory.hpp"

namespace kartograf {
namespace {

Eigen::Isometry3d pose_of(double angle_rad, const Eigen::Vector3d& translation) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(angle_rad, Eigen::Vector3d(1, 2, 2) / 3).toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

double distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).norm();
}

// Samples at 10 Hz of a motion at constant speed along a line while turning about one axis.
Trajectory ten_hertz(int samples) {
  Trajectory trajectory;
  for (int i = 0; i < samples; ++i)
    trajectory.push_back({0.1 * i, pose_of(0.4 * i, Eigen::Vector3d(0.05 * i, 1, -0.02 * i))});
  return trajectory;
}

TEST(PoseAt, BetweenSamplesFollowsTheMotionAtConstantRates) {
  const Trajectory trajectory = ten_hertz(5);
  for (double t : {0.0, 0.025, 0.1, 0.1333, 0.25, 0.399, 0.4}) {
    const auto pose = pose_at(trajectory, t);
    ASSERT_TRUE(pose.has_value()) << t;
    EXPECT_LT(distance(*pose, pose_of(4 * t, Eigen::Vector3d(0.5 * t, 1, -0.2 * t))), 1e-9) << t;
  }
}

TEST(PoseAt, TakesTheShorterArcWhateverTheQuaternionsSign) {
  // Turns of 119 and 121 degrees about an axis with negative dominant components: Eigen gives the
  // first quaternion w > 0 (trace > 0) and the second w < 0 (its largest diagonal's component made
  // positive), so the two are on opposite sides; halfway is still 120 degrees.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, -2) / 3;
  auto turn = [&](double degrees) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(degrees * M_PI / 180, axis).toRotationMatrix();
    return pose;
  };
  const Trajectory trajectory = {{0, turn(119)}, {0.1, turn(121)}};
  ASSERT_LT(Eigen::Quaterniond(turn(119).linear()).dot(Eigen::Quaterniond(turn(121).linear())), 0);
  const auto half = pose_at(trajectory, 0.05);
  ASSERT_TRUE(half.has_value());
  EXPECT_LT(distance(*half, turn(120)), 1e-9);
}

TEST(PoseAt, OutsideOrAcrossAGapOnlyTheNearestPoseCloseEnough) {
  const Trajectory trajectory = ten_hertz(4);
  const PoseAtTolerance tolerance{};  // 0.5 s gaps, 20 ms to the nearest
  EXPECT_LT(distance(*pose_at(trajectory, -0.015, tolerance), trajectory.front().pose), 1e-12);
  EXPECT_LT(distance(*pose_at(trajectory, 0.315, tolerance), trajectory.back().pose), 1e-12);
  EXPECT_FALSE(pose_at(trajectory, -0.05, tolerance).has_value());
  EXPECT_FALSE(pose_at(trajectory, 0.35, tolerance).has_value());
  const PoseAtTolerance no_gaps{0.05, 0.02};  // the samples 0.1 s apart are too far to span
  EXPECT_LT(distance(*pose_at(trajectory, 0.21, no_gaps), trajectory[2].pose), 1e-12);
  EXPECT_LT(distance(*pose_at(trajectory, 0.185, no_gaps), trajectory[2].pose), 1e-12);
  EXPECT_FALSE(pose_at(trajectory, 0.15, no_gaps).has_value());
  EXPECT_FALSE(pose_at(Trajectory{}, 0, tolerance).has_value());
}

}  // namespace
}  // namespace kartograf
