#pragma once
// Per-pixel semantic labelling scored against ground truth: the confusion matrix over
// SemanticClass, per-class intersection over union, their mean, and overall accuracy (the usual
// definitions, e.g. Long et al., "Fully convolutional networks for semantic segmentation", 2015).
//   IoU_c = TP_c / (TP_c + FP_c + FN_c), undefined (empty) for a class in neither image;
//   mean IoU = the mean over classes with a defined IoU (`unknown` has one only when counted);
//   overall accuracy = sum_c TP_c / pixels evaluated.
// Pixels whose ground truth is `unknown` are not evaluated unless include_unknown_ground_truth; a
// prediction of `unknown` where the ground truth knows the class is an error either way.
#include <array>
#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "kartograf/core/semantic_class.hpp"

namespace kartograf::eval {

struct SemanticEvaluationParams {
  bool include_unknown_ground_truth = false;
};

using ConfusionMatrix = Eigen::Matrix<std::int64_t, kSemanticClassCount, kSemanticClassCount>;

struct SemanticScores {
  ConfusionMatrix confusion = ConfusionMatrix::Zero();  // (ground truth, prediction) pixel counts
  std::array<std::optional<double>, kSemanticClassCount> iou;  // indexed by SemanticClass
  double mean_iou = 0;
  double overall_accuracy = 0;
  std::int64_t evaluated_pixels = 0;
};

// Throws Error on different sizes, a pixel value that is no SemanticClass, or no pixel to evaluate.
SemanticScores evaluate_semantic_segmentation(const SemanticImage& ground_truth,
                                              const SemanticImage& predicted,
                                              const SemanticEvaluationParams& options = {});

}  // namespace kartograf::eval
