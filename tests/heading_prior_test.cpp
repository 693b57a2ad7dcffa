// The heading prior (registration/heading_prior.hpp): what it learns from a robot's steps and from
// a hand-held camera's, and how far it moves a step against what was measured.
#include "kartograf/registration/heading_prior.hpp"
#include "kartograf/registration/geometric_information.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace kartograf::registration {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// The surveys' camera, tilted 20 degrees down: it travels forward and a little up in its frame.
const Eigen::Vector3d kTravel(0, -std::sin(20 * kDegree), std::cos(20 * kDegree));

// Its vertical (up is -y in a camera's frame), about which a robot turns.
const Eigen::Vector3d kVertical(0, -std::cos(20 * kDegree), -std::sin(20 * kDegree));

// A step turning `turn_deg` about `axis` (the camera's y axis unless given), `metres` along the
// travel direction turned by half the turn (an arc), plus `offset`.
Eigen::Isometry3d arc_step(double metres, double turn_deg, const Eigen::Vector3d& offset,
                           const Eigen::Vector3d& axis = Eigen::Vector3d::UnitY()) {
  const Eigen::AngleAxisd turn(turn_deg * kDegree, axis);
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.linear() = turn.toRotationMatrix();
  step.translation() =
      metres * (Eigen::AngleAxisd(0.5 * turn.angle(), turn.axis()) * kTravel) + offset;
  return step;
}

// `count` steps of a robot (0-4 cm, turns up to 2 degrees) whose measured steps scatter by
// `noise_m` on each axis; or, with `hand_held`, of a camera moving in any direction.
HeadingPrior learned(int count, double noise_m, bool hand_held = false) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> metres(0, 0.04), turn(-2, 2), any(-0.02, 0.02);
  std::normal_distribution<double> noise(0, noise_m);
  HeadingPrior prior;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d scatter(noise(random), noise(random), noise(random));
    const Eigen::Vector3d wander =
        hand_held ? Eigen::Vector3d(any(random), any(random), 0) : Eigen::Vector3d::Zero();
    prior.learn(arc_step(metres(random), turn(random), scatter + wander));
  }
  return prior;
}

TEST(HeadingPrior, LearnsTheDirectionOfTravelAndHowFarTheStepsStrayAcrossIt) {
  EXPECT_FALSE(learned(10, 3e-4).ready());
  const HeadingPrior prior = learned(60, 3e-4);
  ASSERT_TRUE(prior.ready());
  EXPECT_LT(std::acos(prior.heading().normalized().dot(kTravel)), 1 * kDegree);
  // Two axes across the heading, 0.3 mm each: 0.42 mm.
  const double spread = std::sqrt(prior.across_variance());
  EXPECT_GT(spread, 2.5e-4);
  EXPECT_LT(spread, 6.5e-4);
  EXPECT_GT(std::sqrt(learned(60, 3e-4, true).across_variance()), 5e-3);
}

// Measured well but for the slide along the camera's x axis (a wall ahead over the floor).
se3::Matrix6d all_but_the_slide(double slide_information) {
  se3::Vector6d diagonal;
  diagonal << 1e8, 1e8, 1e8, slide_information, 1e8, 1e8;
  return diagonal.asDiagonal();
}

TEST(HeadingPrior, TakesTheSlideAcrossTheHeadingWhereTheMeasurementLeavesItFree) {
  const HeadingPrior prior = learned(60, 3e-4);
  // 3 cm along an arc turning 10 degrees, slid 1 cm along the new camera's x axis.
  const Eigen::Isometry3d truth = arc_step(0.03, 10, Eigen::Vector3d::Zero());
  const Eigen::Vector3d sideways = truth.linear() * Eigen::Vector3d::UnitX();
  const Eigen::Isometry3d slid = arc_step(0.03, 10, 0.01 * sideways);
  const Eigen::Isometry3d held = prior.combine(slid, all_but_the_slide(1e2));
  // The slide is gone; the measured directions stayed (the rotation, the distance to the wall):
  // the half turn is in the prior's heading (an unturned heading is 2.6 mm across this step).
  EXPECT_LT((held.translation() - truth.translation()).norm(), 2e-4);
  EXPECT_LT(Eigen::AngleAxisd(held.linear().transpose() * slid.linear()).angle(), 0.01 * kDegree);
  // Measured well, the slide stays.
  const Eigen::Isometry3d measured = prior.combine(slid, all_but_the_slide(1e10));
  EXPECT_GT((measured.translation() - truth.translation()).dot(sideways), 0.0095);
}

TEST(HeadingPrior, LeavesAHandHeldCamerasSlideToTheMeasurement) {
  const HeadingPrior prior = learned(60, 3e-4, true);
  ASSERT_TRUE(prior.ready());
  const Eigen::Isometry3d truth = arc_step(0.03, 10, Eigen::Vector3d::Zero());
  const Eigen::Vector3d sideways = truth.linear() * Eigen::Vector3d::UnitX();
  const Eigen::Isometry3d slid = arc_step(0.03, 10, 0.01 * sideways);
  // A slide measured to 1 mm (the odometry's motion prior is about that).
  const Eigen::Isometry3d held = prior.combine(slid, all_but_the_slide(1e6));
  EXPECT_GT((held.translation() - truth.translation()).dot(sideways), 0.0095);
}

TEST(HeadingPrior, LearnsTheAxisTheRobotTurnsAbout) {
  HeadingPrior prior;
  // Small turns (under 2 degrees) about another axis say nothing: the odometry's noise.
  for (int i = 0; i < 5; ++i)
    prior.learn(arc_step(0.3, 1.5, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()));
  EXPECT_EQ(prior.turn_axis(), Eigen::Vector3d::Zero());
  // Turns left and right about the tilted camera's vertical, the small ones in between.
  for (int i = 0; i < 20; ++i) {
    prior.learn(arc_step(0.3, (i % 2 ? -1 : 1) * (3.0 + i), Eigen::Vector3d::Zero(), kVertical));
    prior.learn(arc_step(0.3, 1.5, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()));
  }
  const Eigen::Vector3d axis = prior.turn_axis();
  EXPECT_NEAR(axis.norm(), 1.0, 1e-12);
  EXPECT_LT(std::acos(std::min(1.0, std::abs(axis.dot(kVertical)))), 0.01 * kDegree);
}

TEST(HeadingPrior, StepsAroundAStepLieAlongTheTravelOnEachTurnsArc) {
  const HeadingPrior prior = learned(60, 3e-4);
  const Eigen::Isometry3d step = arc_step(0.5, 8, Eigen::Vector3d::Zero(), kVertical);
  EXPECT_TRUE(HeadingPrior().steps_around(step, {0.2, 0.6, 0.1, kDegree, 0.5 * kDegree}).empty());
  HeadingStepGrid grid{0.2, 0.6, 0.1, kDegree, 0.5 * kDegree, kVertical};
  const std::vector<Eigen::Isometry3d> steps = prior.steps_around(step, grid);
  ASSERT_EQ(steps.size(), 5u * 5u);  // turns -1, -0.5, 0, 0.5, 1 degrees; 0.2 .. 0.6 m
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const double offset_deg = (static_cast<double>(i / 5) - 2) * 0.5;
    const Eigen::AngleAxisd offset(step.linear().transpose() * steps[i].linear());
    EXPECT_NEAR(offset.angle(), std::abs(offset_deg) * kDegree, 1e-9) << i;
    if (offset_deg != 0) {
      EXPECT_NEAR(std::abs(offset.axis().dot(kVertical)), 1.0, 1e-9) << i;
    }
    EXPECT_NEAR(steps[i].translation().norm(), 0.2 + 0.1 * static_cast<double>(i % 5), 1e-9) << i;
    EXPECT_TRUE(steps[i].translation().normalized().isApprox(prior.travel_on(steps[i]), 1e-9)) << i;
  }
  grid.backwards = true;
  const Eigen::Isometry3d reversing = prior.steps_around(step, grid)[7];
  EXPECT_TRUE(reversing.translation().isApprox(-steps[7].translation(), 1e-12));
}

TEST(HeadingPrior, HoldsNothingBeforeItHasLearned) {
  const HeadingPrior prior = learned(5, 3e-4);
  const Eigen::Isometry3d slid = arc_step(0.03, 10, Eigen::Vector3d(0.01, 0, 0));
  EXPECT_TRUE(prior.information(slid).isZero());
  EXPECT_TRUE(prior.combine(slid, all_but_the_slide(0)).isApprox(slid));
}

// The pose graph takes the prior's information only in the directions the geometry left free.
TEST(InformationAlong, KeepsWhatItSaysAboutTheDirectionsAndNothingElse) {
  se3::Matrix6d information = se3::Matrix6d::Zero();
  information.bottomRightCorner<3, 3>() = Eigen::Vector3d(4, 1, 9).asDiagonal();
  se3::Vector6d slide = se3::Vector6d::Zero(), turn_and_slide = se3::Vector6d::Zero();
  slide(3) = 1;
  turn_and_slide(1) = 1, turn_and_slide(5) = 0.5;
  const std::vector<se3::Vector6d> free{slide, turn_and_slide};
  const se3::Matrix6d along = information_along(information, free);
  for (const se3::Vector6d& a : free) {
    for (const se3::Vector6d& b : free)
      EXPECT_NEAR(a.dot(along * b), a.dot(information * b), 1e-12);
  }
  se3::Vector6d off = se3::Vector6d::Zero();
  off(4) = 1;  // the one direction the information weighs besides those
  EXPECT_NEAR(off.dot(along * off), 0, 1e-12);
  EXPECT_TRUE(information_along(information, {}).isZero());
}

}  // namespace
}  // namespace kartograf::registration
