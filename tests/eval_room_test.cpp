// Room metrics (eval/room_metrics.hpp) on hand-made label images with hand-computed answers (on the
// real ipa_room_segmentation ground truth: eval_real_data_test.cpp).
#include <cmath>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "label_image_builders.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using testing::paint;

// Rooms A (label 1) and B (label 2), 30x10 = 300 pixels each, side by side behind a 1-pixel
// wall column (label 0) in a 61x10 map.
LabelImage two_rooms() {
  return testing::label_rectangles(61, 10, {{0, 0, 30, 10, 1}, {31, 0, 61, 10, 2}});
}

TEST(EvalRooms, IdenticalSegmentationScoresOne) {
  const auto scores = eval::evaluate_room_segmentation(two_rooms(), two_rooms());
  EXPECT_EQ(scores.ground_truth_rooms, 2);
  EXPECT_EQ(scores.segments, 2);
  EXPECT_DOUBLE_EQ(scores.recall_mean, 1);
  EXPECT_DOUBLE_EQ(scores.recall_total, 1);
  EXPECT_DOUBLE_EQ(scores.precision_mean, 1);
  EXPECT_DOUBLE_EQ(scores.precision_total, 1);
  EXPECT_DOUBLE_EQ(scores.mcc, 1);
  EXPECT_EQ(scores.mcc_matched_pairs, 2);
  EXPECT_EQ(scores.mcc_unmatched_regions, 0);
}

TEST(EvalRooms, ARoomSplitInHalvesHasHalfRecallAndFullPrecision) {
  LabelImage segmentation = two_rooms();
  paint(segmentation, {{15, 0, 30, 10, 3}});  // room A: segments 1 (150 px) and 3 (150 px)
  const auto scores = eval::evaluate_room_segmentation(two_rooms(), segmentation);
  ASSERT_EQ(scores.room_recall.size(), 2u);
  EXPECT_DOUBLE_EQ(scores.room_recall[0], 0.5);
  EXPECT_DOUBLE_EQ(scores.room_recall[1], 1.0);
  EXPECT_DOUBLE_EQ(scores.recall_mean, 0.75);
  EXPECT_DOUBLE_EQ(scores.recall_total, (150.0 + 300.0) / 600.0);
  EXPECT_DOUBLE_EQ(scores.precision_mean, 1);
  EXPECT_DOUBLE_EQ(scores.precision_total, 1);
  // MCC over the N = 600 pixels labelled in both. Segment 2 takes room B (largest overlap, 300):
  // TP 300, FP 0, FN 0, TN 300 -> 1. Segment 1 (150, lower label than 3) takes room A:
  // TP 150, FP 0, FN 150, TN 300 -> 150 * 300 / sqrt(150 * 300 * 300 * 450) = 1 / sqrt(3).
  // Segment 3 finds room A taken: unmatched, 0. Mean (1 + 1/sqrt(3) + 0) / 3.
  EXPECT_NEAR(scores.mcc, (1 + 1 / std::sqrt(3.0)) / 3, 1e-12);
  EXPECT_EQ(scores.mcc_matched_pairs, 2);
  EXPECT_EQ(scores.mcc_unmatched_regions, 1);
}

TEST(EvalRooms, MergedRoomsAreTheMirrorCase) {
  const LabelImage segmentation(61, 10, 5);  // one segment over both rooms and the wall: 610 px
  const auto scores = eval::evaluate_room_segmentation(two_rooms(), segmentation);
  EXPECT_DOUBLE_EQ(scores.recall_mean, 1);
  EXPECT_DOUBLE_EQ(scores.recall_total, 1);
  EXPECT_DOUBLE_EQ(scores.precision_mean, 300.0 / 610.0);
  EXPECT_DOUBLE_EQ(scores.precision_total, 300.0 / 610.0);
  // The segment takes room A (tie with B, lower label): TP 300, FP 300, FN 0, TN 0 -> the
  // denominator is 0 with FP > 0: 0. Room B unmatched: 0.
  EXPECT_DOUBLE_EQ(scores.mcc, 0);
}

TEST(EvalRooms, SegmentsSpillingIntoWallsLosePrecisionButNotMcc) {
  LabelImage segmentation = two_rooms();
  paint(segmentation, {{30, 0, 31, 10, 1}});  // segment 1 also covers the 10 wall pixels
  const auto scores = eval::evaluate_room_segmentation(two_rooms(), segmentation);
  EXPECT_DOUBLE_EQ(scores.precision_mean, (300.0 / 310.0 + 1.0) / 2);
  EXPECT_DOUBLE_EQ(scores.precision_total, 600.0 / 610.0);
  EXPECT_DOUBLE_EQ(scores.recall_mean, 1);
  EXPECT_DOUBLE_EQ(scores.mcc, 1);  // MAORIS counts only pixels labelled in both
}

TEST(EvalRooms, RegionsOfAHundredPixelsOrLessAreIgnoredLikeIpa) {
  LabelImage segmentation = two_rooms();
  paint(segmentation, {{0, 0, 10, 10, 8}});  // 100 px: dropped; segment 1 keeps 200 px of room A
  const auto scores = eval::evaluate_room_segmentation(two_rooms(), segmentation);
  EXPECT_EQ(scores.segments, 2);
  EXPECT_DOUBLE_EQ(scores.room_recall[0], 200.0 / 300.0);
  EXPECT_DOUBLE_EQ(scores.precision_mean, 1);
  eval::RoomEvaluationParams keep_all;
  keep_all.min_region_pixels = 1;
  EXPECT_EQ(eval::evaluate_room_segmentation(two_rooms(), segmentation, keep_all).segments, 3);
}

// ipa's 100 pixels are 0.25 m^2 of its 0.05 m maps: the same area at any resolution.
TEST(EvalRooms, TheSpeckAreaHoldsAtAnyResolution) {
  EXPECT_EQ(eval::room_evaluation_params(0.05).min_region_pixels, 101);
  EXPECT_EQ(eval::room_evaluation_params(0.1).min_region_pixels, 26);
  EXPECT_EQ(eval::room_evaluation_params(0.025).min_region_pixels, 401);
  EXPECT_EQ(eval::room_evaluation_params(1.0).min_region_pixels, 1);
  // At 0.1 m the 100-pixel segment of the test above is 1 m^2: a segment of its own.
  LabelImage segmentation = two_rooms();
  paint(segmentation, {{0, 0, 10, 10, 8}});
  EXPECT_EQ(
      eval::evaluate_room_segmentation(two_rooms(), segmentation, eval::room_evaluation_params(0.1))
          .segments,
      3);
  for (const double bad : {0.0, -0.05, std::nan("")})
    EXPECT_ERROR_MENTIONS(eval::room_evaluation_params(bad), "resolution");
}

TEST(EvalRooms, RejectsBadInput) {
  EXPECT_THROW(eval::evaluate_room_segmentation(two_rooms(), LabelImage(60, 10, 0)), Error);
  EXPECT_THROW(eval::evaluate_room_segmentation(LabelImage(61, 10, 0), two_rooms()), Error);
  LabelImage empty_segmentation(61, 10, kUnlabeled);
  const auto scores = eval::evaluate_room_segmentation(two_rooms(), empty_segmentation);
  EXPECT_EQ(scores.segments, 0);
  EXPECT_DOUBLE_EQ(scores.recall_mean, 0);
  EXPECT_DOUBLE_EQ(scores.precision_mean, 0);
  EXPECT_DOUBLE_EQ(scores.mcc, 0);
}

}  // namespace
}  // namespace kartograf
