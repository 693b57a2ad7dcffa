// estimate_clock_offset (eval/clock_offset.hpp): another sensor's clock lead, from how fast the
// camera and that sensor turned.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/clock_offset.hpp"

namespace kartograf::eval {
namespace {

// A robot base turning unevenly (two sines of yaw, a little pitch) while driving.
Eigen::Isometry3d body_at(double t) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const double yaw = 0.8 * std::sin(1.3 * t) + 0.3 * std::sin(3.1 * t);
  pose.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(0.05 * std::sin(0.7 * t), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.3 * t, 0.1 * std::sin(t), 0);
  return pose;
}

Eigen::Isometry3d constant_turn_at(double t) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.5 * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

// The camera's poses at 30 Hz for 20 s as odometry gives them: mounted on the body (rotated and
// shifted), each pose turned by noise of 0.03 deg, every 50th by 3 deg more (a failed step).
template <class Motion>
Trajectory camera_frames(Motion&& motion) {
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = Eigen::AngleAxisd(1.9, Eigen::Vector3d(1, -1, 2).normalized()).matrix();
  mount.translation() = Eigen::Vector3d(0.2, 0, 0.4);
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.03 * M_PI / 180);
  Trajectory frames;
  for (int k = 0; k < 600; ++k) {
    const double t = k / 30.0;
    Eigen::Isometry3d pose = motion(t) * mount;
    const Eigen::Vector3d turn(noise(random), noise(random), noise(random));
    const double extra = k % 50 == 25 ? 3 * M_PI / 180 : 0.0;
    pose.linear() =
        pose.linear() * (Eigen::AngleAxisd(turn.norm() + extra, turn.normalized())).matrix();
    frames.push_back({100.0 + t, pose});
  }
  return frames;
}

// The other sensor at `rate` Hz for 24 s, its clock `lead` seconds ahead of the frames', its
// translations 3 % long (wheel slip).
template <class Motion>
Trajectory other_sensor(Motion&& motion, double lead, int rate = 100) {
  Trajectory other;
  for (int j = 0; j < 24 * rate; ++j) {
    const double t = -2.0 + j / static_cast<double>(rate);  // the body's true time
    Eigen::Isometry3d pose = motion(t);
    pose.translation() *= 1.03;
    other.push_back({100.0 + t + lead, pose});
  }
  return other;
}

TEST(ClockOffset, FindsTheOtherClocksLeadDespiteNoiseMountAndScale) {
  for (const double lead : {0.037, -0.120, 0.0}) {
    const ClockOffsetEstimate e =
        estimate_clock_offset(camera_frames(body_at), other_sensor(body_at, lead));
    EXPECT_NEAR(e.offset_s, lead, 0.002) << lead;
    EXPECT_TRUE(e.observable) << lead;
    EXPECT_LT(e.sigma_s, 0.005) << lead;
    EXPECT_GT(e.steps, 500u);
    EXPECT_LT(e.rms_deg, 0.5) << lead;  // the noise and the capped failed steps
    if (lead != 0.0) {
      EXPECT_GT(e.given_rms_deg, e.rms_deg + 0.03) << lead;  // read at offset 0
    }
  }
}

// A 10 Hz odometry against 30 Hz frames: its steps are compared with the frames' poses over the
// same spans (its interpolated rates against the frames' would put the lead off by their phase).
TEST(ClockOffset, ComparesOverTheSparserTrajectorysSteps) {
  for (const double lead : {0.037, -0.020}) {
    const ClockOffsetEstimate e =
        estimate_clock_offset(camera_frames(body_at), other_sensor(body_at, lead, 10));
    EXPECT_NEAR(e.offset_s, lead, 0.002) << lead;
    EXPECT_TRUE(e.observable) << lead;
    EXPECT_GT(e.steps, 150u);
  }
}

TEST(ClockOffset, SearchesAroundTheOffsetInUseAndReportsItsAgreement) {
  ClockOffsetSearch search;
  search.given_s = 2.0;  // a clock two seconds ahead, known to within half a second
  const Trajectory frames = camera_frames(body_at);
  const ClockOffsetEstimate near =
      estimate_clock_offset(frames, other_sensor(body_at, 2.037), search);
  EXPECT_NEAR(near.offset_s, 2.037, 0.002);
  EXPECT_TRUE(near.observable);
  EXPECT_GT(near.given_rms_deg, near.rms_deg + 0.03);
  search.given_s = 2.037;
  const ClockOffsetEstimate right =
      estimate_clock_offset(frames, other_sensor(body_at, 2.037), search);
  EXPECT_NEAR(right.given_rms_deg, right.rms_deg, 0.01);
}

TEST(ClockOffset, TurningAtOneRateLeavesTheOffsetUnobservable) {
  const ClockOffsetEstimate e =
      estimate_clock_offset(camera_frames(constant_turn_at), other_sensor(constant_turn_at, 0.05));
  EXPECT_FALSE(e.observable);
  EXPECT_GT(e.sigma_s, 0.01);
}

TEST(ClockOffset, NoCommonSpanComparesNoStep) {
  Trajectory later = other_sensor(body_at, 0.0);
  for (StampedPose& p : later) p.timestamp += 100;
  const ClockOffsetEstimate e = estimate_clock_offset(camera_frames(body_at), later);
  EXPECT_EQ(e.steps, 0u);
  EXPECT_FALSE(e.observable);
}

TEST(ClockOffset, RefusesASearchThatIsNotPositive) {
  const Trajectory frames = camera_frames(body_at);
  for (const double bad : {0.0, -1.0, std::nan("")}) {
    ClockOffsetSearch search;
    search.half_range_s = bad;
    EXPECT_THROW(estimate_clock_offset(frames, frames, search), Error) << bad;
    search = {};
    search.outlier_deg = bad;
    EXPECT_THROW(estimate_clock_offset(frames, frames, search), Error) << bad;
  }
}

}  // namespace
}  // namespace kartograf::eval
