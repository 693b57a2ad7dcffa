// Trajectory metrics (eval/trajectory_metrics.hpp) on cases whose answers are known by hand: a
// trajectory against itself, against a rigidly moved or scaled copy, a perturbation of a straight
// line, a hand-computed RPE (the real TUM fr1/xyz ground truth: eval_real_data_test.cpp).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "rigid_motion.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using eval::Alignment;
using eval::DeltaUnit;
using testing::some_rigid_motion;

Eigen::Isometry3d pose(const Eigen::Vector3d& position, double yaw, double roll = 0) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  p.translation() = position;
  return p;
}

// A helix with turning orientation, 30 Hz: not degenerate for any alignment.
Trajectory helix(int n) {
  Trajectory trajectory;
  for (int k = 0; k < n; ++k) {
    const double a = 0.15 * k;
    trajectory.push_back(
        {k / 30.0, pose({std::cos(a), std::sin(a), 0.02 * k}, a + 0.3, 0.1 * std::sin(a))});
  }
  return trajectory;
}

// Poses of a straight line along x, 0.1 m apart, identity orientation.
Trajectory line(int n) {
  Trajectory trajectory;
  for (int k = 0; k < n; ++k) trajectory.push_back({k * 0.1, pose({0.1 * k, 0, 0}, 0)});
  return trajectory;
}

eval::MatchedPoses same_instants(const Trajectory& gt, const Trajectory& estimate) {
  return {gt, estimate};
}

TEST(EvalTrajectory, ATrajectoryAgainstItselfHasNoError) {
  const Trajectory gt = helix(50);
  for (Alignment alignment : {Alignment::none, Alignment::se3, Alignment::sim3}) {
    const auto result = eval::evaluate_trajectory(same_instants(gt, gt), alignment, {});
    EXPECT_LT(result.ate.translation_m.rmse, 1e-12);
    EXPECT_LT(result.ate.translation_m.max, 1e-12);
    EXPECT_EQ(result.ate.translation_m.count, 50u);
    EXPECT_LT(result.rpe.translation_m.rmse, 1e-12);
    EXPECT_LT(result.rpe.rotation_deg.rmse, 1e-6);
    EXPECT_EQ(result.rpe.translation_m.count, 49u);
    EXPECT_NEAR(result.ate.alignment.scale, 1.0, 1e-12);
  }
}

TEST(EvalTrajectory, ARigidlyMovedCopyHasNoErrorAfterAlignmentOnly) {
  const Trajectory gt = helix(60);
  Trajectory moved = gt;
  const Eigen::Isometry3d motion = some_rigid_motion();
  for (StampedPose& p : moved) p.pose = motion * p.pose;

  const auto aligned = eval::compute_ate(same_instants(gt, moved), Alignment::se3);
  EXPECT_LT(aligned.translation_m.rmse, 1e-9);
  // The alignment maps the estimate back: it is the inverse motion.
  EXPECT_LT((aligned.alignment.rotation - motion.linear().transpose()).norm(), 1e-9);
  EXPECT_LT((aligned.alignment.translation - motion.inverse().translation()).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(aligned.alignment.scale, 1.0);

  const auto unaligned = eval::compute_ate(same_instants(gt, moved), Alignment::none);
  EXPECT_GT(unaligned.translation_m.rmse, 0.5);
  // Relative motion does not see a rigid change of world frame.
  const auto rpe = eval::compute_rpe(same_instants(gt, moved), {});
  EXPECT_LT(rpe.translation_m.rmse, 1e-9);
  EXPECT_LT(rpe.rotation_deg.rmse, 1e-6);
}

TEST(EvalTrajectory, PerturbedStraightLineMatchesTheHandComputation) {
  // Ground truth x_k = 0.1 k on the x axis, k = 0..9. The estimate adds d to x of every odd pose.
  // Without alignment the errors are 0 (five even poses) and d (five odd poses):
  //   RMSE = sqrt(5 d^2 / 10) = d / sqrt(2), mean = d / 2, median = (0 + d) / 2, max = d.
  // SE(3) alignment: all points lie on the x axis, so a rotation can only move them off it; the
  // best fit is the shift -d/2 along x, which leaves every pose exactly d/2 off:
  //   RMSE = mean = median = max = min = d / 2.
  constexpr double d = 0.04;
  const Trajectory gt = line(10);
  Trajectory estimate = gt;
  for (std::size_t k = 1; k < estimate.size(); k += 2) estimate[k].pose.translation().x() += d;

  const auto unaligned = eval::compute_ate(same_instants(gt, estimate), Alignment::none);
  EXPECT_NEAR(unaligned.translation_m.rmse, d / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(unaligned.translation_m.mean, d / 2, 1e-12);
  EXPECT_NEAR(unaligned.translation_m.median, d / 2, 1e-12);
  EXPECT_NEAR(unaligned.translation_m.max, d, 1e-12);
  EXPECT_NEAR(unaligned.translation_m.min, 0.0, 1e-12);
  EXPECT_NEAR(unaligned.translation_m.std_dev, d / 2, 1e-12);

  const auto aligned = eval::compute_ate(same_instants(gt, estimate), Alignment::se3);
  EXPECT_NEAR(aligned.translation_m.rmse, d / 2, 1e-9);
  EXPECT_NEAR(aligned.translation_m.min, d / 2, 1e-9);
  EXPECT_NEAR(aligned.translation_m.max, d / 2, 1e-9);
  EXPECT_NEAR(aligned.alignment.translation.x(), -d / 2, 1e-9);
}

TEST(EvalTrajectory, RelativePoseErrorMatchesTheHandComputation) {
  // Ground truth: Q_k = (k, 0, 0), no rotation. Estimate: P_0 = (0,0,0), P_1 = (1,0,0),
  // P_2 = (2.1,0,0) turned 10 deg about z, P_3 = (3.1,0,0) turned 10 deg. With delta = 1 frame,
  // E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j):
  //   (0,1): E = I                                    -> 0 m, 0 deg
  //   (1,2): E = (-1,0,0) + (1.1,0,0), Rz(10)         -> 0.1 m, 10 deg
  //   (2,3): P_2^-1 P_3 moves Rz(-10) (1,0,0) = (cos 10, -sin 10, 0), no turn;
  //          E = (cos 10 - 1, -sin 10, 0)             -> 2 sin 5 deg m, 0 deg
  //   translation RMSE = sqrt((0.1^2 + (2 sin 5)^2) / 3), rotation RMSE = sqrt(10^2 / 3) deg.
  const double ten = 10 * std::numbers::pi / 180;
  const Trajectory gt = {{0, pose({0, 0, 0}, 0)},
                         {1, pose({1, 0, 0}, 0)},
                         {2, pose({2, 0, 0}, 0)},
                         {3, pose({3, 0, 0}, 0)}};
  const Trajectory estimate = {{0, pose({0, 0, 0}, 0)},
                               {1, pose({1, 0, 0}, 0)},
                               {2, pose({2.1, 0, 0}, ten)},
                               {3, pose({3.1, 0, 0}, ten)}};
  const auto rpe = eval::compute_rpe(same_instants(gt, estimate), {1, DeltaUnit::frames});
  const double chord = 2 * std::sin(ten / 2);
  EXPECT_EQ(rpe.translation_m.count, 3u);
  EXPECT_NEAR(rpe.translation_m.rmse, std::sqrt((0.01 + chord * chord) / 3), 1e-12);
  EXPECT_NEAR(rpe.translation_m.max, chord, 1e-12);
  EXPECT_NEAR(rpe.rotation_deg.rmse, std::sqrt(100.0 / 3), 1e-9);
  EXPECT_NEAR(rpe.rotation_deg.max, 10.0, 1e-9);

  // delta = 2 frames: pairs (0,2), (1,3); both end turned 10 deg.
  const auto two = eval::compute_rpe(same_instants(gt, estimate), {2, DeltaUnit::frames});
  EXPECT_EQ(two.rotation_deg.count, 2u);
  EXPECT_NEAR(two.rotation_deg.rmse, 10.0, 1e-9);
}

TEST(EvalTrajectory, DeltaInSecondsPairsPosesByTime) {
  // 2 Hz poses; delta 1 s pairs k with k + 2, the last two poses start no pair.
  Trajectory gt = line(8);
  for (std::size_t k = 0; k < gt.size(); ++k) gt[k].timestamp = 100 + 0.5 * k;
  Trajectory estimate = gt;
  estimate[4].pose.translation().y() += 0.3;  // enters pairs (2,4) and (4,6) only
  const auto rpe = eval::compute_rpe(same_instants(gt, estimate), {1.0, DeltaUnit::seconds});
  EXPECT_EQ(rpe.translation_m.count, 6u);
  EXPECT_NEAR(rpe.translation_m.rmse, std::sqrt(2 * 0.09 / 6), 1e-12);
  // A delta of 0.7 s takes the pose nearest to t + 0.7, i.e. 0.5 s later,
  const auto near = eval::compute_rpe(same_instants(gt, estimate), {0.7, DeltaUnit::seconds});
  EXPECT_EQ(near.translation_m.count, 6u);  // from t_6 on, t + 0.7 is past the last pose
}

TEST(EvalTrajectory, Sim3RecoversAKnownScale) {
  const Trajectory gt = helix(40);
  Trajectory scaled = gt;
  const Eigen::Isometry3d motion = some_rigid_motion();
  constexpr double s = 2.5;
  for (StampedPose& p : scaled) {
    p.pose = motion * p.pose;
    p.pose.translation() *= s;
  }
  const auto sim3 = eval::evaluate_trajectory(same_instants(gt, scaled), Alignment::sim3, {});
  EXPECT_NEAR(sim3.ate.alignment.scale, 1 / s, 1e-9);
  EXPECT_LT(sim3.ate.translation_m.rmse, 1e-9);
  EXPECT_LT(sim3.rpe.translation_m.rmse, 1e-9);  // measured on the rescaled estimate
  const auto se3 = eval::compute_ate(same_instants(gt, scaled), Alignment::se3);
  EXPECT_GT(se3.translation_m.rmse, 0.1);
  EXPECT_DOUBLE_EQ(se3.alignment.scale, 1.0);
}

TEST(EvalTrajectory, RejectsWhatCannotBeEvaluated) {
  const Trajectory gt = helix(10);
  const std::vector<std::pair<std::size_t, std::size_t>> bad = {{0, 0}, {3, 10}};
  EXPECT_THROW(eval::match_poses(gt, gt, bad), Error);
  const Trajectory two(gt.begin(), gt.begin() + 2);
  EXPECT_THROW(eval::compute_ate(same_instants(two, two), Alignment::se3), Error);
  EXPECT_NO_THROW(eval::compute_ate(same_instants(two, two), Alignment::none));
  Trajectory still = gt;
  for (StampedPose& p : still) p.pose.translation().setZero();
  EXPECT_THROW(eval::compute_ate(same_instants(gt, still), Alignment::sim3), Error);
  EXPECT_THROW(eval::compute_rpe(same_instants(gt, gt), {0, DeltaUnit::frames}), Error);
  EXPECT_THROW(eval::compute_rpe(same_instants(gt, gt), {1.5, DeltaUnit::frames}), Error);
  EXPECT_THROW(eval::compute_rpe(same_instants(gt, gt), {10, DeltaUnit::frames}), Error);
  EXPECT_THROW(eval::compute_rpe(same_instants(gt, gt), {-1, DeltaUnit::seconds}), Error);
  Trajectory unordered = gt;
  std::swap(unordered[3].timestamp, unordered[4].timestamp);
  EXPECT_THROW(eval::compute_rpe(same_instants(unordered, unordered), {0.1, DeltaUnit::seconds}),
               Error);
  eval::MatchedPoses uneven{gt, two};
  EXPECT_THROW(eval::compute_rpe(uneven, {}), Error);
}

// The helix with the steps ending at `wrong` moved by `slip` in their start's frame, the poses
// after each chained on: what a lost frame does to a trajectory.
Trajectory with_slips(const Trajectory& gt, const std::vector<std::size_t>& wrong,
                      const Eigen::Vector3d& slip) {
  Trajectory estimate = gt;
  for (std::size_t k = 1; k < gt.size(); ++k) {
    Eigen::Isometry3d step = gt[k - 1].pose.inverse() * gt[k].pose;
    if (std::find(wrong.begin(), wrong.end(), k) != wrong.end()) step.pretranslate(slip);
    estimate[k].pose = estimate[k - 1].pose * step;
  }
  return estimate;
}

TEST(EvalTrajectory, TheWorstStepsAreFoundAndCarryTheirShareOfTheError) {
  const Trajectory gt = helix(60);
  const Trajectory estimate = with_slips(gt, {20, 41}, {0.10, -0.05, 0.02});
  Trajectory slightly = estimate;  // one more step 3 mm off: found third
  for (std::size_t k = 50; k < slightly.size(); ++k) {
    slightly[k].pose.translation() += slightly[49].pose.linear() * Eigen::Vector3d(0.003, 0, 0);
  }
  const eval::WorstSteps worst = eval::worst_steps(same_instants(gt, slightly), 3, Alignment::se3);
  ASSERT_EQ(worst.steps.size(), 3u);
  EXPECT_TRUE((worst.steps[0].pose == 20 && worst.steps[1].pose == 41) ||
              (worst.steps[0].pose == 41 && worst.steps[1].pose == 20));
  EXPECT_NEAR(worst.steps[0].translation_m, std::sqrt(0.0129), 1e-9);
  EXPECT_LT(worst.steps[0].rotation_deg, 1e-6);
  EXPECT_EQ(worst.steps[2].pose, 50u);
  EXPECT_NEAR(worst.steps[2].translation_m, 0.003, 1e-9);
  EXPECT_DOUBLE_EQ(worst.steps[2].timestamp, gt[50].timestamp);
  // One slip taken away leaves the other (here the two partly cancel: taking one away can raise
  // the ATE); all three taken away leave nothing.
  EXPECT_GT(worst.ate_rmse_m, 0.02);
  for (int k = 0; k < 2; ++k) EXPECT_GT(worst.steps[k].ate_rmse_with_true_step_m, 0.02);
  EXPECT_LT(worst.ate_rmse_with_true_steps_m, 1e-9);
  // A single slip carries the whole error.
  const eval::WorstSteps one = eval::worst_steps(
      same_instants(gt, with_slips(gt, {20}, {0.10, -0.05, 0.02})), 1, Alignment::se3);
  ASSERT_EQ(one.steps.size(), 1u);
  EXPECT_EQ(one.steps[0].pose, 20u);
  EXPECT_GT(one.ate_rmse_m, 0.02);
  EXPECT_LT(one.steps[0].ate_rmse_with_true_step_m, 1e-9);
}

TEST(EvalTrajectory, WorstStepsOfAScaledEstimateAreInItsOwnUnits) {
  const Trajectory gt = helix(40);
  Trajectory half = with_slips(gt, {12}, {0.08, 0, 0});
  for (StampedPose& p : half) p.pose.translation() *= 0.5;  // a monocular estimate's scale
  const eval::WorstSteps worst = eval::worst_steps(same_instants(gt, half), 1, Alignment::sim3);
  ASSERT_EQ(worst.steps.size(), 1u);
  EXPECT_EQ(worst.steps[0].pose, 12u);
  EXPECT_NEAR(worst.steps[0].translation_m, 0.04, 0.004);
  // The scale is fitted with the slip in, so the true steps are scaled a little off: not nil.
  EXPECT_GT(worst.ate_rmse_m, 0.005);
  EXPECT_LT(worst.steps[0].ate_rmse_with_true_step_m, 0.1 * worst.ate_rmse_m);
}

TEST(EvalTrajectory, WorstStepsAskForNoMoreThanThereAre) {
  const Trajectory gt = helix(5);
  const eval::WorstSteps all = eval::worst_steps(same_instants(gt, gt), 10, Alignment::none);
  EXPECT_EQ(all.steps.size(), 4u);
  EXPECT_LT(all.ate_rmse_m, 1e-12);
  const Trajectory two(gt.begin(), gt.begin() + 2);
  EXPECT_THROW(eval::worst_steps(same_instants(two, two), 1, Alignment::se3), Error);
  EXPECT_THROW(eval::worst_steps(eval::MatchedPoses{gt, two}, 1, Alignment::se3), Error);
}

TEST(EvalTrajectory, SummarizesErrors) {
  const auto stats = eval::summarize_errors({3, 1, 4, 1, 5});
  EXPECT_EQ(stats.count, 5u);
  EXPECT_DOUBLE_EQ(stats.mean, 14.0 / 5);
  EXPECT_DOUBLE_EQ(stats.median, 3);
  EXPECT_DOUBLE_EQ(stats.rmse, std::sqrt(52.0 / 5));
  EXPECT_DOUBLE_EQ(stats.min, 1);
  EXPECT_DOUBLE_EQ(stats.max, 5);
  EXPECT_NEAR(stats.std_dev, std::sqrt(52.0 / 5 - 14.0 / 5 * 14.0 / 5), 1e-12);
  EXPECT_EQ(eval::summarize_errors({}).count, 0u);
}

}  // namespace
}  // namespace kartograf
