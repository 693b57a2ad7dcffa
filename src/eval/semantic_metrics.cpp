#include "kartograf/eval/semantic_metrics.hpp"

#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::eval {

namespace {

constexpr char kWhat[] = "semantic evaluation";

int class_index(SemanticClass c, const char* side, std::size_t pixel, int width) {
  const int index = static_cast<int>(c);
  if (index < kSemanticClassCount) return index;  // no message built on the per-pixel path
  throw Error(std::string(kWhat) + ": the " + side + " pixel (" + std::to_string(pixel % width) +
              ", " + std::to_string(pixel / width) + ") has value " + std::to_string(index) +
              ", which is no semantic class (0.." + std::to_string(kSemanticClassCount - 1) + ")");
}

}  // namespace

SemanticScores evaluate_semantic_segmentation(const SemanticImage& ground_truth,
                                              const SemanticImage& predicted,
                                              const SemanticEvaluationParams& options) {
  require(ground_truth.width() == predicted.width() && ground_truth.height() == predicted.height(),
          std::string(kWhat) + ": the ground truth is " + std::to_string(ground_truth.width()) +
              "x" + std::to_string(ground_truth.height()) + " but the prediction is " +
              std::to_string(predicted.width()) + "x" + std::to_string(predicted.height()));
  SemanticScores scores;
  const auto gt_pixels = ground_truth.pixels();
  const auto predicted_pixels = predicted.pixels();
  for (std::size_t i = 0; i < gt_pixels.size(); ++i) {
    const int gt = class_index(gt_pixels[i], "ground-truth", i, ground_truth.width());
    const int prediction = class_index(predicted_pixels[i], "predicted", i, ground_truth.width());
    if (gt_pixels[i] == SemanticClass::unknown && !options.include_unknown_ground_truth) continue;
    ++scores.confusion(gt, prediction);
  }
  scores.evaluated_pixels = scores.confusion.sum();
  require(scores.evaluated_pixels > 0,
          std::string(kWhat) + ": no pixel to evaluate (the ground truth is all unknown)");

  double iou_sum = 0;
  int iou_count = 0;
  // Without unknown ground truth, `unknown` is only ever a wrong prediction: it has no IoU.
  const int first_class = options.include_unknown_ground_truth ? 0 : 1;
  for (int c = first_class; c < kSemanticClassCount; ++c) {
    const std::int64_t tp = scores.confusion(c, c);
    const std::int64_t union_pixels =
        scores.confusion.row(c).sum() + scores.confusion.col(c).sum() - tp;
    if (union_pixels == 0) continue;
    scores.iou[c] = static_cast<double>(tp) / static_cast<double>(union_pixels);
    iou_sum += *scores.iou[c];
    ++iou_count;
  }
  scores.mean_iou = iou_count > 0 ? iou_sum / iou_count : 0.0;
  scores.overall_accuracy =
      static_cast<double>(scores.confusion.trace()) / static_cast<double>(scores.evaluated_pixels);
  return scores;
}

}  // namespace kartograf::eval
