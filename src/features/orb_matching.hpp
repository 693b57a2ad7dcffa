#pragma once
// Descriptor matching between two ORB descriptions (private to the features layer): brute-force
// Hamming nearest neighbours with Lowe's ratio test, optionally cross-checked.
#include <vector>

#include <opencv2/core.hpp>

namespace kartograf::features {

struct DescriptorMatch {
  int source = 0;  // row in the source descriptors
  int target = 0;  // row in the target descriptors
};

// For each source row, its nearest target row when it is nearer than ratio x the second nearest
// (a target with a single row: no second nearest, no test); with cross_check, only when that
// source row is also the target row's nearest. Empty when either side has no rows.
std::vector<DescriptorMatch> ratio_matches(const cv::Mat& source, const cv::Mat& target,
                                           double ratio, bool cross_check);

}  // namespace kartograf::features
