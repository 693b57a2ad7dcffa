// Loop closure (mapping/loop_closure.hpp): candidate selection by frame gap, distance, view angle
// and view overlap; verification by ICP that recovers a true loop from a drifted estimate and
// rejects a wrong candidate (another place that the estimate claims is the same).
#include <gtest/gtest.h>

#include <numbers>

#include <Eigen/Eigenvalues>

#include "icp_test_scene.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/mapping/loop_closure.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using mapping::LoopCandidate;
using mapping::LoopClosureDetector;

constexpr double kDegree = std::numbers::pi / 180.0;

Eigen::Isometry3d turned(const Eigen::Isometry3d& pose, double yaw_deg,
                         const Eigen::Vector3d& shift) {
  // Yaw about the world's vertical (z up in the synthetic world), then a shift in the world.
  Eigen::Isometry3d result = pose;
  result.linear() = Eigen::AngleAxisd(yaw_deg * kDegree, Eigen::Vector3d::UnitZ()) * pose.linear();
  result.translation() += shift;
  return result;
}

// Keyframes at frames 0 (A), 100 (B: A moved 6 cm and turned 4 degrees), 120 (C: A turned
// around), 140 (D: another room), 150 (E: next to D, too soon after it for a loop).
struct Scenario {
  std::vector<std::size_t> frames{0, 100, 120, 140, 150};
  std::vector<Eigen::Isometry3d> truth;  // per keyframe
  testing::RenderedSequence rendered;

  Scenario() {
    const Trajectory tour = synth::robot_tour(testing::test_world(), 300);
    const Eigen::Isometry3d a = tour[60].pose;
    const Eigen::Isometry3d d = tour[240].pose;
    truth = {a, turned(a, 4, Eigen::Vector3d(0.05, -0.03, 0.0)),
             turned(a, 180, Eigen::Vector3d::Zero()), d,
             turned(d, 2, Eigen::Vector3d(0.02, 0.0, 0.0))};
    rendered = testing::render_sequence(truth, testing::qvga_kinect());
  }
  // Poses indexed by frame (frames without a keyframe keep the identity).
  std::vector<Eigen::Isometry3d> poses_by_frame(
      const std::vector<Eigen::Isometry3d>& keyframe_poses) const {
    std::vector<Eigen::Isometry3d> poses(frames.back() + 1, Eigen::Isometry3d::Identity());
    for (std::size_t k = 0; k < frames.size(); ++k) poses[frames[k]] = keyframe_poses[k];
    return poses;
  }
};

const Scenario& scenario() {
  static const Scenario s;
  return s;
}

class LoopClosureTest : public ::testing::Test {
 protected:
  LoopClosureTest() : detector_(context_, testing::qvga_kinect(), range(), params()) {
    // Path lengths: the loop A -> B travelled 10 m.
    const double path[] = {0.0, 10.0, 10.5, 11.0, 11.1};
    for (std::size_t k = 0; k < scenario().frames.size(); ++k) {
      detector_.add_keyframe(scenario().frames[k], scenario().rendered.frames[k].depth, path[k]);
    }
  }
  static geometry::DepthRange range() {
    geometry::DepthRange r;
    r.units_per_metre = testing::kSynthUnitsPerMetre;
    return r;
  }
  static mapping::LoopClosureParams params() {
    mapping::LoopClosureParams p;
    p.min_frame_gap = 60;
    return p;
  }

  compute::Context context_ = compute::Context::cpu();
  LoopClosureDetector detector_;
};

TEST_F(LoopClosureTest, SelectsTheOverlappingKeyframeOnly) {
  const auto poses = scenario().poses_by_frame(scenario().truth);
  const std::vector<LoopCandidate> for_b = detector_.find_candidates(1, poses);
  ASSERT_EQ(for_b.size(), 1u);
  EXPECT_EQ(for_b[0].match, 0u);
  EXPECT_EQ(for_b[0].match_frame, 0u);
  EXPECT_EQ(for_b[0].query_frame, 100u);
  EXPECT_NEAR(for_b[0].distance_m, std::hypot(0.05, 0.03), 1e-9);
  EXPECT_NEAR(for_b[0].view_angle_deg, 4.0, 0.5);
  EXPECT_GT(for_b[0].overlap, 0.7);
  EXPECT_NEAR(for_b[0].drift_allowance_m, 0.05 * 10.0, 1e-12);
  // C stands where A stood but looks the other way: no view in common.
  EXPECT_TRUE(detector_.find_candidates(2, poses).empty());
  // D is in another room; E is next to D but only 10 frames later (odometry's business).
  EXPECT_TRUE(detector_.find_candidates(3, poses).empty());
  EXPECT_TRUE(detector_.find_candidates(4, poses).empty());
  // Overlap is directional but high both ways for A and B, and zero for A and C.
  const Eigen::Isometry3d a_to_b = scenario().truth[1].inverse() * scenario().truth[0];
  EXPECT_GT(detector_.view_overlap(0, 1, a_to_b, 0.1), 0.7);
  const Eigen::Isometry3d a_to_c = scenario().truth[2].inverse() * scenario().truth[0];
  EXPECT_LT(detector_.view_overlap(0, 2, a_to_c, 0.1), 0.05);
}

TEST_F(LoopClosureTest, VerificationRecoversATrueLoopFromADriftedEstimate) {
  std::vector<Eigen::Isometry3d> estimate = scenario().truth;
  estimate[1] = estimate[1] * Eigen::Translation3d(0.06, -0.02, 0.04) *
                Eigen::AngleAxisd(2.0 * kDegree, Eigen::Vector3d(0.3, 1, 0.2).normalized());
  const auto poses = scenario().poses_by_frame(estimate);
  const std::vector<LoopCandidate> candidates = detector_.find_candidates(1, poses);
  ASSERT_EQ(candidates.size(), 1u);
  const mapping::LoopClosure closure = detector_.verify(candidates[0], poses);
  EXPECT_TRUE(closure.report.accepted()) << registration::to_string(closure.report.verdict);
  EXPECT_GT(closure.report.correction_m, 0.03);  // it did correct the estimate
  EXPECT_EQ(closure.constraint.from, 0u);
  EXPECT_EQ(closure.constraint.to, 100u);
  const Eigen::Isometry3d truth = scenario().truth[0].inverse() * scenario().truth[1];
  const Eigen::Isometry3d error = truth.inverse() * closure.constraint.motion;
  RecordProperty("translation_error_m", testing::scientific(error.translation().norm()));
  EXPECT_LT(error.translation().norm(), 0.005);
  EXPECT_LT(se3::rotation_angle(error), 0.3 * kDegree);
  // The edge is weighted: a symmetric, positive definite information.
  EXPECT_TRUE(closure.constraint.information.isApprox(closure.constraint.information.transpose()));
  EXPECT_GT(
      Eigen::SelfAdjointEigenSolver<se3::Matrix6d>(closure.constraint.information).eigenvalues()(0),
      0.0);
}

// With no memory for keyframe depth every keyframe's depth is read back from the temporary file:
// the same overlaps and the same verified loop.
TEST_F(LoopClosureTest, KeyframeDepthFromDiskGivesTheSameLoops) {
  mapping::LoopClosureParams on_disk = params();
  on_disk.keyframe_depth_memory = 0;
  LoopClosureDetector spilled(context_, testing::qvga_kinect(), range(), on_disk);
  const double path[] = {0.0, 10.0, 10.5, 11.0, 11.1};
  for (std::size_t k = 0; k < scenario().frames.size(); ++k)
    spilled.add_keyframe(scenario().frames[k], scenario().rendered.frames[k].depth, path[k]);
  std::vector<Eigen::Isometry3d> estimate = scenario().truth;
  estimate[1] = estimate[1] * Eigen::Translation3d(0.06, -0.02, 0.04);
  const auto poses = scenario().poses_by_frame(estimate);
  const std::vector<LoopCandidate> mine = detector_.find_candidates(1, poses);
  const std::vector<LoopCandidate> theirs = spilled.find_candidates(1, poses);
  ASSERT_EQ(mine.size(), 1u);
  ASSERT_EQ(theirs.size(), 1u);
  EXPECT_EQ(theirs[0].overlap, mine[0].overlap);
  const mapping::LoopClosure a = detector_.verify(mine[0], poses);
  const mapping::LoopClosure b = spilled.verify(theirs[0], poses);
  EXPECT_TRUE(b.report.accepted());
  EXPECT_TRUE(b.constraint.motion.isApprox(a.constraint.motion, 0.0));
}

TEST_F(LoopClosureTest, RejectsAWrongCandidate) {
  // The estimate claims D (another room) is where A is: a false loop.
  std::vector<Eigen::Isometry3d> estimate = scenario().truth;
  estimate[3] = scenario().truth[0] * Eigen::Translation3d(0.03, 0, 0);
  const auto poses = scenario().poses_by_frame(estimate);
  // Selection already sees that D's depth does not fit A's view...
  for (const LoopCandidate& c : detector_.find_candidates(3, poses)) EXPECT_NE(c.match, 0u);
  // ...and verification, when asked anyway, rejects the registration.
  LoopCandidate forced;
  forced.query = 3;
  forced.match = 0;
  forced.query_frame = 140;
  forced.match_frame = 0;
  forced.drift_allowance_m = 0.5;
  const mapping::LoopClosure closure = detector_.verify(forced, poses);
  EXPECT_FALSE(closure.report.accepted());
  RecordProperty("verdict", std::string(registration::to_string(closure.report.verdict)));
  RecordProperty("fitness", testing::scientific(closure.report.fitness));
}

// A wall and the floor, seen again 20 cm farther along the wall: ICP measures the distances to
// the wall and the floor and the turn, not the slide along them. The loop keeps the estimate's
// slide and gives the pose graph no information about it.
TEST(LoopClosureWeakDirections, TheSlideAlongAWallIsLeftToTheEstimate) {
  const testing::Scene wall_and_floor{
      std::nullopt, {}, {{Eigen::Vector3d(0, 0, 1), 3.0}, {Eigen::Vector3d(0, 1, 0), 1.2}}};
  const PinholeIntrinsics camera = testing::qvga_camera();
  const Eigen::Isometry3d a = testing::reference_camera();
  const Eigen::Isometry3d b = Eigen::Translation3d(0.2, 0, 0.05) * a;  // world x: along the wall
  geometry::DepthRange range;
  range.units_per_metre = 1000;
  mapping::LoopClosureParams params;
  params.verification.reject_degenerate = false;  // this view is degenerate by design
  params.weak_direction_ratio = 0.01;
  params.min_correction_m = 1;  // ICP slides along the wall (0.5 m here): let it, and see it undone
  const compute::Context context = compute::Context::cpu();
  LoopClosureDetector detector(context, camera, range, params);
  detector.add_keyframe(0, testing::depth_of(testing::render(wall_and_floor, camera, a), 1000), 0);
  detector.add_keyframe(100, testing::depth_of(testing::render(wall_and_floor, camera, b), 1000),
                        1);
  // The estimate is 4 cm off along the wall (free) and 3 cm off towards it (measured).
  std::vector<Eigen::Isometry3d> poses(101, Eigen::Isometry3d::Identity());
  poses[0] = a;
  poses[100] = Eigen::Translation3d(0.04, 0, 0.03) * b;
  LoopCandidate candidate;
  candidate.query = 1;
  candidate.query_frame = 100;
  candidate.drift_allowance_m = 0.1;
  const mapping::LoopClosure closure = detector.verify(candidate, poses);
  ASSERT_TRUE(closure.report.accepted()) << registration::to_string(closure.report.verdict);
  // The constraint's camera position, in the world of keyframe A.
  const Eigen::Vector3d offset = (a * closure.constraint.motion).translation() - b.translation();
  RecordProperty("offset_m", testing::scientific(offset.norm()));
  EXPECT_NEAR(offset.x(), 0.04, 0.005);  // the estimate's slide, kept
  EXPECT_NEAR(offset.z(), 0.0, 0.005);   // the distance to the wall, measured
  // No information along the slide, in the edge's tangent coordinates (camera B's frame).
  se3::Vector6d slide = se3::Vector6d::Zero();
  slide.tail<3>() = b.linear().transpose() * Eigen::Vector3d::UnitX();
  const se3::Matrix6d& information = closure.constraint.information;
  EXPECT_LT(slide.dot(information * slide), 1e-6 * information.trace());
}

TEST_F(LoopClosureTest, ReportsBadInput) {
  const auto poses = scenario().poses_by_frame(scenario().truth);
  EXPECT_THROW(detector_.find_candidates(1, std::span(poses).first(50)), Error);
  EXPECT_THROW(detector_.add_keyframe(10, scenario().rendered.frames[0].depth, 0), Error);  // order
  EXPECT_THROW(detector_.add_keyframe(200, DepthImage(16, 16, 0), 0), Error);               // size
  mapping::LoopClosureParams bad;
  bad.min_overlap = 2;
  EXPECT_THROW(LoopClosureDetector(context_, testing::qvga_kinect(), range(), bad), Error);
}

}  // namespace
}  // namespace kartograf
