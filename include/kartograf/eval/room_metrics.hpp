#pragma once
// Room segmentation scored against ground-truth rooms, two ways.
//
// 1. Recall and precision exactly as ipa_room_segmentation evaluates its segmentations
//    (R. Bormann et al., "Room Segmentation: Survey, Implementation, and Analysis", ICRA 2016;
//    code: ipa320/ipa_coverage_planning, ipa_room_segmentation/common/src/
//    evaluation_segmentation.cpp, EvaluationSegmentation::computePrecisionRecall):
//    - regions of either image with <= 100 pixels are dropped first (`size() > 100` there);
//    - recall of a ground-truth room g = max over segments s of |g ∩ s| / |g|;
//    - precision of a segment s     = max over rooms g of |g ∩ s| / |s|;
//    - *_mean = the mean of those ratios (ipa names it "micro"), *_total = sum of the maximal
//      overlaps / sum of the areas, i.e. area-weighted (ipa's "macro").
//    Segment areas count all their pixels, walls included, so a segment spilling outside the rooms
//    loses precision. With no segment left, precision is 0 (ipa divides by zero there).
//
// 2. The Matthews correlation coefficient as MAORIS defines it for map segmentation
//    (M. Mielle, M. Magnusson, A. J. Lilienthal, "A method to segment maps from different
//    modalities using free space layout - MAORIS: MAp Of RIpples Segmentation", ICRA 2018;
//    code: MalcolmMielle/maoris, src/Evaluation/Evaluation.cpp, compareImagesUnbiased):
//    - only pixels labelled in both images count (N of them); regions are measured on them;
//    - one-to-one matching: segments in decreasing order of their largest overlap with any room;
//      each takes the room it overlaps most among those not yet taken (ties: lower label);
//    - per matched pair: TP = |g ∩ s|, FP = |s| - TP, FN = |g| - TP, TN = N - TP - FP - FN and
//      MCC = (TP TN - FP FN) / sqrt((TP+FP)(TP+FN)(TN+FP)(TN+FN)); when the denominator is 0,
//      MCC = 1 if FP = FN = 0 (the pair covers everything exactly) else 0;
//    - every room and every segment left unmatched scores 0;
//    - mcc = the mean over matched pairs and unmatched regions.
//    Deviations from that code, which has two slips the paper's text does not have: its TN is
//    N - (FP - |g|), and a segment whose rooms are all taken still gets matched to its last one.
//    Small regions are not dropped here (MAORIS does not).
#include <vector>

#include "kartograf/core/label_image.hpp"

namespace kartograf::eval {

struct RoomEvaluationParams {
  int min_region_pixels = 101;  // smaller regions are ignored by recall/precision (ipa: > 100)
};

// ipa's "> 100 pixels" is an area on its 0.05 m maps: regions of more than 0.25 m^2 count. The
// same area at another resolution (0.025 m: > 400 cells; 0.1 m: > 25), so that a finer map's
// specks of wall-side free space do not count as rooms. Throws Error unless the resolution is a
// finite positive number.
RoomEvaluationParams room_evaluation_params(double metres_per_cell);

struct RoomSegmentationScores {
  int ground_truth_rooms = 0;  // rooms with >= min_region_pixels
  int segments = 0;            // segments with >= min_region_pixels
  double recall_mean = 0;
  double recall_total = 0;
  double precision_mean = 0;
  double precision_total = 0;
  std::vector<double> room_recall;        // per kept room, ascending label
  std::vector<double> segment_precision;  // per kept segment, ascending label
  double mcc = 0;                         // MAORIS
  int mcc_matched_pairs = 0;
  int mcc_unmatched_regions = 0;
};

// Throws Error if the images differ in size or the ground truth has no room of min_region_pixels.
RoomSegmentationScores evaluate_room_segmentation(const LabelImage& ground_truth,
                                                  const LabelImage& segmentation,
                                                  const RoomEvaluationParams& options = {});

}  // namespace kartograf::eval
