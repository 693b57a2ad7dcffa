// The metrics on real files read through formats: the ipa_room_segmentation ground truth against
// itself (room metrics) and the TUM fr1/xyz ground truth matched through io::associate_timestamps
// as the CLI does (trajectory metrics). The hand-made cases: eval_room_test.cpp and
// eval_trajectory_test.cpp.
#include <cstddef>
#include <vector>

#include "kartograf/core/connected_components.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/tum.hpp"
#include "rigid_motion.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using eval::Alignment;
using eval::DeltaUnit;
using testing::some_rigid_motion;

TEST(EvalRooms, RealGroundTruthAgainstItselfScoresOne) {
  // lab_ipa: 11 rooms as 4-connected white regions (what the data's SOURCE.txt states); ipa's own
  // evaluation flood-fills 8-connected and sees 10, two rooms meeting at a diagonal. Scored
  // against the 4-connected truth, that 8-connected reading loses precision only.
  const auto maps = testing::data_dir() / "ipa_room_maps" / "test_maps";
  const LabelImage rooms = io::read_room_ground_truth_png(maps / "lab_ipa_gt_segmentation.png");
  const auto self = eval::evaluate_room_segmentation(rooms, rooms);
  EXPECT_EQ(self.ground_truth_rooms, 11);
  EXPECT_DOUBLE_EQ(self.recall_mean, 1);
  EXPECT_DOUBLE_EQ(self.precision_mean, 1);
  EXPECT_DOUBLE_EQ(self.precision_total, 1);
  EXPECT_DOUBLE_EQ(self.mcc, 1);

  io::RoomGroundTruthParams ipa_flood_fill;
  ipa_flood_fill.connectivity = Connectivity::eight;
  const LabelImage eight =
      io::read_room_ground_truth_png(maps / "lab_ipa_gt_segmentation.png", ipa_flood_fill);
  const auto merged = eval::evaluate_room_segmentation(rooms, eight);
  EXPECT_EQ(merged.segments, 10);
  EXPECT_DOUBLE_EQ(merged.recall_mean, 1);
  EXPECT_LT(merged.precision_mean, 1);
  EXPECT_LT(merged.mcc, 1);
}

TEST(EvalTrajectory, MatchesThroughTimestampAssociationOnRealGroundTruth) {
  // TUM fr1/xyz ground truth against a copy moved rigidly, every third pose dropped and the
  // clock shifted by 3 ms: association pairs each kept pose with its original.
  const Trajectory gt =
      io::read_tum_trajectory(testing::data_dir() / "tum_fr1_xyz_lists_only" / "groundtruth.txt");
  ASSERT_GT(gt.size(), 1000u);
  Trajectory estimate;
  const Eigen::Isometry3d motion = some_rigid_motion();
  for (std::size_t k = 0; k < gt.size(); ++k) {
    if (k % 3 == 2) continue;
    estimate.push_back({gt[k].timestamp + 0.003, motion * gt[k].pose});
  }
  std::vector<double> gt_times, estimate_times;
  for (const auto& p : gt) gt_times.push_back(p.timestamp);
  for (const auto& p : estimate) estimate_times.push_back(p.timestamp);
  const auto pairs = io::associate_timestamps(gt_times, estimate_times, 0.02);
  ASSERT_EQ(pairs.size(), estimate.size());
  const eval::MatchedPoses matched = eval::match_poses(gt, estimate, pairs);
  for (std::size_t k = 0; k < matched.size(); ++k) {
    // Timestamps near 1.3e9 s carry ~2e-7 s of double rounding.
    ASSERT_NEAR(matched.estimate[k].timestamp - matched.ground_truth[k].timestamp, 0.003, 1e-6);
  }
  const auto result = eval::evaluate_trajectory(matched, Alignment::se3, {1, DeltaUnit::seconds});
  EXPECT_LT(result.ate.translation_m.rmse, 1e-9);
  EXPECT_LT(result.rpe.translation_m.rmse, 1e-9);
  EXPECT_GT(result.rpe.translation_m.count, 1000u);
  EXPECT_GT(eval::compute_ate(matched, Alignment::none).translation_m.rmse, 1.0);
}

}  // namespace
}  // namespace kartograf
