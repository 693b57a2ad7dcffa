// Semantic metrics (eval/semantic_metrics.hpp) on an 8-pixel image whose confusion matrix, IoUs
// and accuracy are counted by hand, with and without unknown ground truth.
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/semantic_metrics.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using C = SemanticClass;

SemanticImage image_of(const std::vector<C>& classes) {
  SemanticImage image(4, 2);
  for (std::size_t i = 0; i < classes.size(); ++i) image.pixels()[i] = classes[i];
  return image;
}

// pixel:        0      1      2     3     4        5     6      7
// ground truth: floor  floor  wall  wall  unknown  door  floor  wall
// prediction:   floor  wall   wall  wall  floor    door  floor  unknown
const SemanticImage kGroundTruth =
    image_of({C::floor, C::floor, C::wall, C::wall, C::unknown, C::door, C::floor, C::wall});
const SemanticImage kPrediction =
    image_of({C::floor, C::wall, C::wall, C::wall, C::floor, C::door, C::floor, C::unknown});

int idx(C c) {
  return static_cast<int>(c);
}

TEST(EvalSemantic, CountsTheConfusionMatrixIouAndAccuracy) {
  // Pixel 4 (unknown ground truth) is not evaluated: 7 pixels, 5 right (0, 2, 3, 5, 6).
  //   floor: TP 2 (0, 6), FP 0, FN 1 (1)  -> 2/3
  //   wall:  TP 2 (2, 3), FP 1 (1), FN 1 (7) -> 2/4
  //   door:  TP 1 -> 1; ceiling and furniture appear nowhere: no IoU; unknown: not a class here.
  const auto scores = eval::evaluate_semantic_segmentation(kGroundTruth, kPrediction);
  EXPECT_EQ(scores.evaluated_pixels, 7);
  EXPECT_EQ(scores.confusion(idx(C::floor), idx(C::floor)), 2);
  EXPECT_EQ(scores.confusion(idx(C::floor), idx(C::wall)), 1);
  EXPECT_EQ(scores.confusion(idx(C::wall), idx(C::wall)), 2);
  EXPECT_EQ(scores.confusion(idx(C::wall), idx(C::unknown)), 1);
  EXPECT_EQ(scores.confusion(idx(C::door), idx(C::door)), 1);
  EXPECT_EQ(scores.confusion.row(idx(C::unknown)).sum(), 0);
  EXPECT_DOUBLE_EQ(*scores.iou[idx(C::floor)], 2.0 / 3);
  EXPECT_DOUBLE_EQ(*scores.iou[idx(C::wall)], 0.5);
  EXPECT_DOUBLE_EQ(*scores.iou[idx(C::door)], 1.0);
  EXPECT_FALSE(scores.iou[idx(C::ceiling)].has_value());
  EXPECT_FALSE(scores.iou[idx(C::furniture)].has_value());
  EXPECT_FALSE(scores.iou[idx(C::unknown)].has_value());
  EXPECT_DOUBLE_EQ(scores.mean_iou, (2.0 / 3 + 0.5 + 1.0) / 3);
  EXPECT_DOUBLE_EQ(scores.overall_accuracy, 5.0 / 7);
}

TEST(EvalSemantic, CanCountUnknownGroundTruthAsAClass) {
  // Pixel 4 now counts: floor gains FP 1 -> 2/4; unknown: TP 0, FP 1 (7), FN 1 (4) -> 0.
  const auto scores = eval::evaluate_semantic_segmentation(kGroundTruth, kPrediction,
                                                           {.include_unknown_ground_truth = true});
  EXPECT_EQ(scores.evaluated_pixels, 8);
  EXPECT_DOUBLE_EQ(*scores.iou[idx(C::floor)], 0.5);
  EXPECT_DOUBLE_EQ(*scores.iou[idx(C::unknown)], 0.0);
  EXPECT_DOUBLE_EQ(scores.mean_iou, (0.0 + 0.5 + 0.5 + 1.0) / 4);
  EXPECT_DOUBLE_EQ(scores.overall_accuracy, 5.0 / 8);
}

TEST(EvalSemantic, RejectsBadInput) {
  EXPECT_THROW(eval::evaluate_semantic_segmentation(kGroundTruth, SemanticImage(4, 3, C::floor)),
               Error);
  SemanticImage invalid = kPrediction;
  invalid(1, 1) = static_cast<C>(9);
  EXPECT_ERROR_MENTIONS(eval::evaluate_semantic_segmentation(kGroundTruth, invalid),
                        "pixel (1, 1) has value 9");
  EXPECT_THROW(eval::evaluate_semantic_segmentation(SemanticImage(4, 2, C::unknown), kPrediction),
               Error);
}

}  // namespace
}  // namespace kartograf
