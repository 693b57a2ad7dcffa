// The SLAM pipeline (mapping/slam.hpp) on a rendered sequence that comes back along its way, so
// that loop closures are found, verified and kept, the pose graph lowers the
// error, and the map has points, normals and colours; plus the frame loop's error propagation and
// the odometry-only run.
#include <gtest/gtest.h>

#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

constexpr int kFrames = 60;

mapping::SlamParams loop_params() {
  mapping::SlamParams params;
  params.loops.min_frame_gap = 20;
  params.map.voxel_size = 0.05;
  return params;
}

TEST(Slam, ClosesTheLoopAndBuildsAColouredMapWithNormals) {
  const testing::MemoryFrameSource source(testing::out_and_back());
  const compute::Context context = compute::Context::cpu();
  std::size_t tracked = 0, verified = 0, odometry_progress = 0, map_progress = 0;
  mapping::SlamObserver observer;
  observer.on_frame = [&](const registration::OdometryFrame&) { ++tracked; };
  observer.on_loop_closure = [&](const mapping::LoopClosure&) { ++verified; };
  observer.on_progress = [&](std::string_view stage, std::size_t done, std::size_t total) {
    EXPECT_EQ(total, static_cast<std::size_t>(kFrames));
    (stage == "map" ? map_progress : odometry_progress) = done;
  };
  const mapping::SlamResult result = mapping::run_slam(context, source, loop_params(), observer);

  ASSERT_EQ(result.poses.size(), static_cast<std::size_t>(kFrames));
  EXPECT_EQ(tracked, static_cast<std::size_t>(kFrames));
  EXPECT_EQ(odometry_progress, static_cast<std::size_t>(kFrames));
  EXPECT_EQ(map_progress, static_cast<std::size_t>(kFrames));
  EXPECT_EQ(verified, result.loop_closures.size());
  std::size_t kept = 0, pruned = 0;
  for (const auto& record : result.loop_closures) {
    pruned += record.pruned;
    if (record.closure.report.accepted() && !record.pruned) {
      ++kept;
      EXPECT_GE(record.closure.candidate.query_frame - record.closure.candidate.match_frame, 20u);
      EXPECT_LT(record.chi2, 25.0);
    }
  }
  RecordProperty("loop_closures_kept", std::to_string(kept));
  RecordProperty("loop_closures_verified", std::to_string(result.loop_closures.size()));
  RecordProperty("loop_closures_pruned", std::to_string(pruned));
  EXPECT_GE(kept, 1u);
  EXPECT_GE(result.graph_edges, static_cast<std::size_t>(kFrames - 1) + kept);
  EXPECT_TRUE(result.final_graph.converged);

  const double odometry_ate =
      testing::ate_rmse(result.odometry.poses, testing::out_and_back().truth);
  const double slam_ate = testing::ate_rmse(result.poses, testing::out_and_back().truth);
  RecordProperty("odometry_ate_m", testing::scientific(odometry_ate));
  RecordProperty("slam_ate_m", testing::scientific(slam_ate));
  EXPECT_LT(slam_ate, 0.01);
  // The odometry's anchored re-estimates already hold this stretch to ~1-2 mm: the loops must not
  // make it worse (measured: SLAM 2.13 mm, odometry 2.09 mm; on 2026-12-07 0.60 and 1.11 mm).
  EXPECT_LE(slam_ate, odometry_ate * 1.1);

  ASSERT_GT(result.map.size(), 1000u);
  EXPECT_TRUE(result.map.has_normals());
  EXPECT_TRUE(result.map.has_colors());
  EXPECT_GE(result.map_voxels, result.map.size());
  std::size_t with_normal = 0;
  for (const Eigen::Vector3f& n : result.map.normals) with_normal += n.norm() > 0.99f;
  EXPECT_GT(with_normal, result.map.size() * 8 / 10);  // edges and thin legs may have none
  EXPECT_GT(result.timing.total_seconds, 0.0);
}

// With the paper's re-estimation (against frame n-5) the odometry drifts more, and the loops
// closing the way back onto the way out take at least 40 % of it out (measured: 4.1 -> 2.0 mm).
// Re-estimates judged on what their anchor sees hold this stretch to 0.6 mm even so, which leaves
// the loops nothing to take out: off here.
TEST(Slam, LoopClosuresTakeOutTheOdometrysDrift) {
  const testing::MemoryFrameSource source(testing::out_and_back());
  const compute::Context context = compute::Context::cpu();
  mapping::SlamParams params = loop_params();
  params.odometry.anchor = {0, 0, 0};
  params.odometry.reestimate_on_overlap = false;
  const mapping::SlamResult result = mapping::run_slam(context, source, params);
  const double odometry_ate =
      testing::ate_rmse(result.odometry.poses, testing::out_and_back().truth);
  const double slam_ate = testing::ate_rmse(result.poses, testing::out_and_back().truth);
  RecordProperty("odometry_ate_m", testing::scientific(odometry_ate));
  RecordProperty("slam_ate_m", testing::scientific(slam_ate));
  EXPECT_LT(slam_ate, 0.6 * odometry_ate);
}

// Without loop closures the pose graph has nothing to add to the odometry's chain: its step
// edges are the chain as the re-estimates left it (OdometryParams::steps_follow_reestimates), so
// it returns the odometry's poses. With the steps as first measured it weighed them against the
// re-estimates and moved the poses.
TEST(Slam, WithoutLoopsTheGraphReturnsTheOdometrysChain) {
  const testing::MemoryFrameSource source(testing::out_and_back());
  const compute::Context context = compute::Context::cpu();
  mapping::SlamParams params = loop_params();
  params.loop_closure = false;
  params.odometry.anchor = {0, 0, 0};  // the paper's n-5: a correction at every 5th frame
  const auto largest_move_m = [&](const mapping::SlamResult& result) {
    double move = 0;
    for (std::size_t i = 0; i < result.poses.size(); ++i) {
      move = std::max(
          move, (result.poses[i].translation() - result.odometry.poses[i].translation()).norm());
    }
    return move;
  };
  const mapping::SlamResult following = mapping::run_slam(context, source, params);
  params.odometry.steps_follow_reestimates = false;
  const mapping::SlamResult measured = mapping::run_slam(context, source, params);
  RecordProperty("graph_move_as_measured_m", testing::scientific(largest_move_m(measured)));
  EXPECT_LT(largest_move_m(following), 1e-6);
  EXPECT_GT(largest_move_m(measured), 1e-4);
}

// Known poses (the frames' ground truth): nothing estimated, the poses are the truth relative to
// the first frame, the map is fused; a pose that is not a rotation is an error naming its frame.
TEST(Slam, KnownPosesFuseTheMapWithoutEstimating) {
  const testing::MemoryFrameSource source(testing::out_and_back());
  const compute::Context context = compute::Context::cpu();
  const auto truth = [](std::size_t, const registration::RgbdImages& images) {
    require(images.ground_truth.has_value(), "no ground truth");
    return *images.ground_truth;
  };
  const mapping::SlamResult result =
      mapping::run_with_known_poses(context, source, truth, loop_params());
  EXPECT_TRUE(result.poses_given);
  ASSERT_EQ(result.poses.size(), static_cast<std::size_t>(kFrames));
  const std::vector<Eigen::Isometry3d>& expected = testing::out_and_back().truth;
  for (std::size_t i = 0; i < result.poses.size(); ++i) {
    const Eigen::Isometry3d relative = expected[0].inverse() * expected[i];
    EXPECT_LT((result.poses[i].matrix() - relative.matrix()).cwiseAbs().maxCoeff(), 1e-9) << i;
  }
  EXPECT_EQ(result.odometry.poses.size(), result.poses.size());
  EXPECT_TRUE(result.loop_closures.empty());
  EXPECT_GT(result.map.size(), 1000u);

  const auto scaled = [&](std::size_t i, const registration::RgbdImages& images) {
    Eigen::Isometry3d pose = truth(i, images);
    if (i == 3) pose.linear() *= 1.1;
    return pose;
  };
  EXPECT_ERROR_MENTIONS(mapping::run_with_known_poses(context, source, scaled, loop_params()),
                        "frame 3", "not a rotation");
  EXPECT_ERROR_MENTIONS(mapping::run_with_known_poses(context, source, {}, loop_params()),
                        "no pose lookup");
}

// A source whose frame 5 cannot be read: the error reaches the caller, nothing hangs.
class BrokenSource final : public mapping::FrameSource {
 public:
  explicit BrokenSource(const testing::RenderedSequence& sequence) : inner_(sequence) {}
  std::size_t size() const override { return 10; }
  PinholeIntrinsics camera() const override { return inner_.camera(); }
  double depth_units_per_metre() const override { return inner_.depth_units_per_metre(); }
  registration::RgbdImages frame(std::size_t i) const override {
    require(i != 5, "frame 5: corrupt file");
    return inner_.frame(i);
  }

 private:
  testing::MemoryFrameSource inner_;
};

// Frame-to-model tracking under SLAM: the graph's odometry is the model's, one edge per step
// whose motion joins the model's poses, the same poses as the odometry alone with the model, and
// the loops do not make them worse.
TEST(Slam, ModelTrackingGivesTheGraphTheModelsPoses) {
  const testing::MemoryFrameSource source(testing::out_and_back());
  const compute::Context context = compute::Context::cpu();
  mapping::SlamParams params = loop_params();
  params.build_map = false;
  params.model.enabled = true;
  const mapping::SlamResult result = mapping::run_slam(context, source, params);
  const mapping::OdometryRun alone =
      mapping::run_odometry(context, source, params.odometry, {}, params.model);

  const std::vector<Eigen::Isometry3d>& poses = result.odometry.poses;
  ASSERT_TRUE(result.odometry.model_tracking);
  ASSERT_EQ(poses.size(), static_cast<std::size_t>(kFrames));
  EXPECT_GT(result.odometry.model_kept, static_cast<std::size_t>(kFrames) / 2);
  ASSERT_EQ(result.odometry.constraints.size(), poses.size() - 1);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const registration::RelativePose& edge = result.odometry.constraints[i - 1];
    EXPECT_EQ(edge.from, i - 1);
    EXPECT_EQ(edge.to, i);
    EXPECT_TRUE(edge.motion.isApprox(poses[i - 1].inverse() * poses[i], 1e-9)) << i;
    EXPECT_TRUE(poses[i].isApprox(alone.poses[i], 1e-9)) << i;
  }
  const double odometry_ate = testing::ate_rmse(poses, testing::out_and_back().truth);
  const double slam_ate = testing::ate_rmse(result.poses, testing::out_and_back().truth);
  RecordProperty("odometry_ate_m", testing::scientific(odometry_ate));
  RecordProperty("slam_ate_m", testing::scientific(slam_ate));
  EXPECT_LT(slam_ate, 0.01);
  EXPECT_LE(slam_ate, odometry_ate * 1.1);
}

TEST(Slam, PassesFrameErrorsToTheCaller) {
  const BrokenSource source(testing::out_and_back());
  const compute::Context context = compute::Context::cpu();
  try {
    mapping::run_slam(context, source, loop_params());
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("frame 5: corrupt file"), std::string::npos);
  }
  EXPECT_THROW(mapping::run_odometry(context, source, registration::OdometryParams{}), Error);
}

TEST(Slam, OdometryRunReportsTimingAndEveryFrame) {
  testing::RenderedSequence sequence = testing::out_and_back();
  sequence.frames.resize(12);
  const testing::MemoryFrameSource source(sequence);
  const compute::Context context = compute::Context::cpu();
  const mapping::OdometryRun run = mapping::run_odometry(context, source, {});
  ASSERT_EQ(run.poses.size(), 12u);
  EXPECT_EQ(run.frames.size(), 12u);
  EXPECT_EQ(run.timestamps.size(), 12u);
  EXPECT_DOUBLE_EQ(run.timestamps[3], 3 / 30.0);
  EXPECT_GT(run.compute_seconds, 0.0);
  EXPECT_GE(run.timing.wall_seconds, run.compute_seconds * 0.5);
  EXPECT_GT(run.timing.load_seconds, 0.0);
  EXPECT_EQ(run.keyframes.front(), 0u);
  EXPECT_EQ(run.constraints.size(), 11u + 2u);  // 11 frame-to-frame, frames 5 and 10 k-back
}

}  // namespace
}  // namespace kartograf
