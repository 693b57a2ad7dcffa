// Trajectories: the robot tour visits every room, closes its loop, respects the per-frame limits
// and keeps clear of walls and furniture; the hand-held motion stays in its room and is smooth.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "kartograf/core/error.hpp"
#include "kartograf/synth/trajectory.hpp"

namespace kartograf::synth {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

double rotation_between(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

// Distance from p to the nearest wall (wall boxes that reach the floor; lintels do not) or
// obstacle.
double clearance(const World& w, const Eigen::Vector2d& p) {
  double d = 1e9;
  for (const Solid& s : w.solids) {
    if (s.kind == SolidKind::wall && s.box.min.z() <= 0.0)
      d = std::min(d, s.box.footprint().distance(p));
  }
  for (const Rect2& r : w.obstacle_footprints()) d = std::min(d, r.distance(p));
  return d;
}

TEST(SynthTrajectory, RobotTourVisitsEveryRoomAndClosesTheLoopWithinLimits) {
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const World w = make_building(seed);
    const TourParams options;
    ASSERT_LE(tour_frames_needed(w, options), 300) << "the default building fits a 300-frame tour";
    const Trajectory t = robot_tour(w, 300, options);
    ASSERT_EQ(t.size(), 300u);

    std::set<Label> visited;
    double worst_clearance = 1e9;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const Eigen::Vector3d p = t[i].pose.translation();
      EXPECT_NEAR(t[i].timestamp, i / 30.0, 1e-12);
      EXPECT_NEAR(p.z(), 1.0, 1e-12);
      EXPECT_NEAR(t[i].pose.linear().col(2).z(), -std::sin(12 * kDegree),
                  1e-12);                                      // pitched down 12 deg
      EXPECT_NEAR(t[i].pose.linear().col(0).z(), 0.0, 1e-12);  // no roll
      visited.insert(w.room_at(p.head<2>()));
      worst_clearance = std::min(worst_clearance, clearance(w, p.head<2>()));
      if (i == 0) continue;
      EXPECT_LE((p - t[i - 1].pose.translation()).norm(), 0.12) << "frame " << i;
      EXPECT_LE(rotation_between(t[i - 1].pose, t[i].pose), 4 * kDegree) << "frame " << i;
      if (i + 1 < t.size()) {
        // C1: speed and direction of travel change little from one frame to the next.
        const Eigen::Vector3d before = p - t[i - 1].pose.translation();
        const Eigen::Vector3d after = t[i + 1].pose.translation() - p;
        // Bounded acceleration: at most 2 mm/frame of speed change per frame (1.8 m/s^2).
        EXPECT_LE(std::fabs(after.norm() - before.norm()), 0.002 + 1e-9) << "frame " << i;
        EXPECT_LE(std::acos(std::min(1.0, before.normalized().dot(after.normalized()))),
                  6 * kDegree)
            << "frame " << i;
      }
    }
    visited.erase(0);  // in a doorway
    EXPECT_EQ(visited.size(), w.rooms.size());
    EXPECT_GE(worst_clearance, 0.4 - 1e-9);
    EXPECT_LE((t.back().pose.translation() - t.front().pose.translation()).norm(), 0.1);
    EXPECT_LE(rotation_between(t.back().pose, t.front().pose), 2 * kDegree);
  }
}

// A survey stops once in every room and corridor pass and turns all the way round in place there,
// within the same per-frame limits, and still closes its loop.
TEST(SynthTrajectory, SurveyTurnsAllTheWayRoundInPlaceInEveryRoom) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const World w = make_building(seed);
    TourParams options;
    options.survey = true;
    options.pitch_deg = 20;
    const int frames = tour_frames_needed(w, options);
    ASSERT_LE(frames, 1500) << "about 150 frames per stop on top of the route";
    const Trajectory t = robot_tour(w, frames, options);
    std::set<Label> turned_in;
    int turns = 0;
    double turned = 0;  // in the current stop
    for (std::size_t i = 1; i < t.size(); ++i) {
      const Eigen::Vector3d step = t[i].pose.translation() - t[i - 1].pose.translation();
      const double rotation = rotation_between(t[i - 1].pose, t[i].pose);
      EXPECT_LE(step.norm(), 0.12) << "frame " << i;
      EXPECT_LE(rotation, 4 * kDegree + 1e-9) << "frame " << i;
      EXPECT_NEAR(t[i].pose.linear().col(2).z(), -std::sin(20 * kDegree), 1e-12);
      if (step.norm() < 1e-12) {
        turned += rotation;
        continue;
      }
      if (turned > 0) {
        EXPECT_NEAR(turned, 2 * std::numbers::pi, 8 * kDegree) << "stop before frame " << i;
        turns += turned > std::numbers::pi;
        turned_in.insert(w.room_at(t[i - 1].pose.translation().head<2>()));
      }
      turned = 0;
      if (i + 1 < t.size()) {
        const Eigen::Vector3d after = t[i + 1].pose.translation() - t[i].pose.translation();
        // Bounded acceleration; the last frame before a stop may land half a millimetre short.
        EXPECT_LE(std::fabs(after.norm() - step.norm()), 0.0025) << "frame " << i;
      }
    }
    turned_in.erase(0);
    EXPECT_EQ(turned_in.size(), w.rooms.size()) << "a turn in every room and the corridor";
    EXPECT_GE(turns, static_cast<int>(w.rooms.size()));
    EXPECT_LE((t.back().pose.translation() - t.front().pose.translation()).norm(), 1e-9);
    EXPECT_LE(rotation_between(t.back().pose, t.front().pose), 1e-6);
  }
}

TEST(SynthTrajectory, ShortToursStillLoopAndOptionsAreChecked) {
  const World w = make_building(2);
  const Trajectory t = robot_tour(w, 20);
  ASSERT_EQ(t.size(), 20u);
  EXPECT_LT((t.back().pose.translation() - t.front().pose.translation()).norm(), 1e-9);
  EXPECT_THROW(robot_tour(w, 1), Error);
  TourParams bad;
  bad.max_step = 0;
  EXPECT_THROW(robot_tour(w, 10, bad), Error);
}

TEST(SynthTrajectory, CameraPoseFollowsTheOpticalFrame) {
  // Yaw 90 degrees, no pitch: looking north (+y), the right hand points east (+x).
  const Eigen::Isometry3d pose = camera_pose({1, 2, 3}, std::numbers::pi / 2, 0.0);
  EXPECT_LT((pose.linear().col(2) - Eigen::Vector3d(0, 1, 0)).norm(), 1e-12);   // z forward
  EXPECT_LT((pose.linear().col(0) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-12);   // x right
  EXPECT_LT((pose.linear().col(1) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);  // y down
  EXPECT_NEAR(pose.linear().determinant(), 1.0, 1e-12);
}

TEST(SynthTrajectory, HandheldStaysInItsRoomAndMovesSmoothly) {
  const World w = make_building(4);
  for (Label room = 1; room <= 4; ++room) {
    const Trajectory t = handheld(w, room, 300, 17);
    const Trajectory same = handheld(w, room, 300, 17);
    const Trajectory other = handheld(w, room, 300, 18);
    ASSERT_EQ(t.size(), 300u);
    EXPECT_TRUE(t.back().pose.isApprox(same.back().pose, 0.0));
    EXPECT_FALSE(t.back().pose.isApprox(other.back().pose, 1e-6));
    double yaw_min = 1e9, yaw_max = -1e9;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const Eigen::Vector3d p = t[i].pose.translation();
      EXPECT_EQ(w.room_at(p.head<2>()), room);
      EXPECT_GE(clearance(w, p.head<2>()), 0.3);
      EXPECT_NEAR(p.z(), 1.45, 0.1);
      // Roll: the camera's x axis tilts at most a few degrees out of the horizontal.
      EXPECT_LT(std::fabs(t[i].pose.linear().col(0).z()), std::sin(5 * kDegree));
      const Eigen::Vector3d forward = t[i].pose.linear().col(2);
      const double yaw = std::atan2(forward.y(), forward.x());
      yaw_min = std::min(yaw_min, yaw), yaw_max = std::max(yaw_max, yaw);
      if (i == 0) continue;
      EXPECT_LT((p - t[i - 1].pose.translation()).norm(), 0.03);
      EXPECT_LT(rotation_between(t[i - 1].pose, t[i].pose), 3 * kDegree);
    }
    EXPECT_GT(yaw_max - yaw_min, 60 * kDegree) << "the camera looks around";
  }
}

}  // namespace
}  // namespace kartograf::synth
