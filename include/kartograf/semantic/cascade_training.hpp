#pragma once
// Training of the Haar cascade of haar_cascade.hpp (Viola-Jones): each stage is gentle AdaBoost
// over regression stumps (J. Friedman, T. Hastie, R. Tibshirani, "Additive Logistic Regression",
// Ann. Statist. 2000), stumps chosen over per-feature histograms of the feature values (256 bins
// between the feature's min and max over the stage's samples), which makes a round one pass over
// a byte matrix. A stage grows until, at the threshold that keeps min_hit_rate of the positives,
// at most max_false_alarm of its negatives pass. Negatives are bootstrapped: each stage trains on
// windows of the background images that every earlier stage lets through (found by running the
// detector on them), so later stages see the hard cases.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "kartograf/core/color.hpp"
#include "kartograf/semantic/haar_cascade.hpp"

namespace kartograf::semantic {

// An image that negatives are taken from: every window except those overlapping one of `objects`
// (boxes of the object class, in its pixels) by IoU >= CascadeTrainingParams::negative_max_iou.
// Views of the object itself then teach the cascade to reject its parts and near misses.
struct TrainingBackground {
  GrayImage image;
  std::vector<Detection> objects;
};

struct CascadeTrainingParams {
  std::string object_class = "object";
  int window = 20;
  int feature_position_step = 2;  // enumerate_haar_features steps
  int feature_size_step = 1;
  float min_stddev = 8;
  int max_stages = 12;
  int max_stumps_per_stage = 60;
  double min_hit_rate = 0.995;   // per stage, on the training positives
  double max_false_alarm = 0.5;  // per stage, on its negatives
  int negatives_per_stage = 3000;
  int max_windows_per_background = 40;  // per image and stage, for variety
  double negative_max_iou = 0.4;        // see TrainingBackground
  DetectionParams scan;                 // how backgrounds are scanned for negatives
  std::uint64_t seed = 1;
};

struct CascadeTrainingReport {
  int features_considered = 0;
  std::vector<int> stumps_per_stage;
  std::vector<double> stage_false_alarm;  // on that stage's negatives
  std::vector<double> stage_hit_rate;     // on the positives that reached it
  bool ran_out_of_negatives = false;      // stopped because the backgrounds yield too few windows
  double seconds = 0;
};

// positives: window x window grey crops of the object. backgrounds: grey images (any size >=
// window), the source of negatives. Throws Error on empty or wrongly sized
// input. `log`, when set, receives a line per stage.
HaarCascade train_cascade(const std::vector<GrayImage>& positives,
                          const std::vector<TrainingBackground>& backgrounds,
                          const CascadeTrainingParams& params,
                          CascadeTrainingReport* report = nullptr,
                          const std::function<void(const std::string&)>& log = {});

}  // namespace kartograf::semantic
