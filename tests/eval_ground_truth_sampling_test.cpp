// Which ground-truth poses were measured (eval/ground_truth_sampling.hpp): a reference measured
// every 5th pose and interpolated at constant velocity between, a robot driving at constant
// velocity in runs of no fixed length, and the real references: SUN3D's (every 5th frame) and
// 7-Scenes' and TUM's (every frame).
#include <cmath>
#include <cstddef>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/ground_truth_sampling.hpp"
#include "kartograf/formats/sequence.hpp"
#include "kartograf/formats/tum.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

Eigen::Isometry3d step_of(double forward_m, double turn_deg) {
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.linear() = Eigen::AngleAxisd(turn_deg * M_PI / 180, Eigen::Vector3d::UnitY()).matrix();
  step.translation() = Eigen::Vector3d(0, 0, forward_m);
  return step;
}

// Both sides the same trajectory (the estimate does not matter here).
eval::MatchedPoses matched(const std::vector<Eigen::Isometry3d>& steps) {
  eval::MatchedPoses poses;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (std::size_t k = 0; k <= steps.size(); ++k) {
    if (k > 0) pose = pose * steps[k - 1];
    poses.ground_truth.push_back({static_cast<double>(k), pose});
    poses.estimate.push_back({static_cast<double>(k), pose});
  }
  return poses;
}

TEST(GroundTruthSampling, FindsPosesMeasuredEveryFifthWithConstantStepsBetween) {
  // A hand-held camera's motion measured at poses 0, 5, 10, ...: each run of five equal steps is a
  // fifth of the motion between two measured poses, and every run differs.
  std::vector<Eigen::Isometry3d> steps;
  for (int run = 0; run < 9; ++run) {
    const Eigen::Isometry3d fifth = step_of(0.004 + 0.002 * (run % 3), 0.3 + 0.1 * run);
    for (int k = 0; k < 5; ++k) steps.push_back(fifth);
  }
  steps.push_back(step_of(0.01, 1.0));  // a last pose after the last run
  const eval::GroundTruthSampling sampling = eval::ground_truth_sampling(matched(steps));
  EXPECT_TRUE(sampling.interpolated());
  EXPECT_EQ(sampling.period, 5u);
  ASSERT_EQ(sampling.measured.size(), 10u);  // poses 0, 5, ..., 45 of 47
  for (std::size_t i = 0; i < sampling.measured.size(); ++i) EXPECT_EQ(sampling.measured[i], 5 * i);
}

TEST(GroundTruthSampling, AConstantVelocityInRunsOfNoFixedLengthIsMeasuredEverywhere) {
  // A robot drives straight at 0.02 m a frame, turns on the spot, drives on: runs of 7, 3, 12, 5
  // and 9 equal steps. Every step a measurement.
  std::vector<Eigen::Isometry3d> steps;
  for (const int run : {7, 3, 12, 5, 9}) {
    for (int k = 0; k < run; ++k) steps.push_back(step_of(0.02, 0));
    steps.push_back(step_of(0, 15));
  }
  const eval::GroundTruthSampling sampling = eval::ground_truth_sampling(matched(steps));
  EXPECT_FALSE(sampling.interpolated());
  EXPECT_EQ(sampling.measured.size(), steps.size() + 1);
  // Straight on at one speed throughout: every period fits the steps, but no run changes.
  const std::vector<Eigen::Isometry3d> straight(40, step_of(0.02, 0));
  EXPECT_FALSE(eval::ground_truth_sampling(matched(straight)).interpolated());
}

TEST(GroundTruthSampling, ANearlyConstantStepIsNotARepeatedOne) {
  // Every 5th pose measured, but the steps between change by 1 mm each: not an interpolation.
  std::vector<Eigen::Isometry3d> steps;
  for (int k = 0; k < 40; ++k) steps.push_back(step_of(0.01 + 0.001 * (k % 5), 0.2));
  EXPECT_FALSE(eval::ground_truth_sampling(matched(steps)).interpolated());
}

TEST(GroundTruthSampling, RejectsUnmatchedPosesAndSelectsTheMeasuredOnes) {
  eval::MatchedPoses poses = matched({step_of(0.01, 0), step_of(0.02, 0)});
  const eval::MatchedPoses picked = eval::select_poses(poses, {0, 2});
  ASSERT_EQ(picked.size(), 2u);
  EXPECT_DOUBLE_EQ(picked.ground_truth[1].timestamp, 2.0);
  EXPECT_ERROR_MENTIONS(eval::select_poses(poses, {3}), "index 3");
  poses.estimate.pop_back();
  EXPECT_ERROR_MENTIONS(eval::ground_truth_sampling(poses), "match them first");
}

eval::MatchedPoses frame_poses(const std::filesystem::path& folder, std::size_t count) {
  const auto sequence = io::open_seven_scenes(folder);
  eval::MatchedPoses poses;
  for (std::size_t i = 0; i < count && i < sequence->size(); ++i) {
    const io::RgbdFrame frame = sequence->frame(i);
    poses.ground_truth.push_back({frame.timestamp, frame.pose.value()});
    poses.estimate.push_back(poses.ground_truth.back());
  }
  return poses;
}

TEST(GroundTruthSampling, RealReferences) {
  // SUN3D fragment 1: SUN3D's reconstruction measured frames 935, 940, ... (indices 0, 5, ...).
  const eval::GroundTruthSampling sun3d = eval::ground_truth_sampling(
      frame_poses(testing::data_dir() / "sun3d_studyroom_fragment1", 50));
  EXPECT_EQ(sun3d.period, 5u);
  ASSERT_EQ(sun3d.measured.size(), 10u);
  EXPECT_EQ(sun3d.measured.front(), 0u);
  EXPECT_EQ(sun3d.measured.back(), 45u);
  // 7-Scenes (KinectFusion's poses) and TUM fr1/xyz (motion capture at 100 Hz): every pose.
  EXPECT_FALSE(
      eval::ground_truth_sampling(frame_poses(testing::data_dir() / "7scenes_redkitchen", 100))
          .interpolated());
  const Trajectory tum =
      io::read_tum_trajectory(testing::data_dir() / "tum_fr1_xyz_lists_only" / "groundtruth.txt");
  eval::MatchedPoses tum_poses{tum, tum};
  EXPECT_FALSE(eval::ground_truth_sampling(tum_poses).interpolated());
}

}  // namespace
}  // namespace kartograf
