#pragma once
// Plane segmentation scored as in SegComp: A. Hoover et al., "An experimental comparison of range
// image segmentation algorithms", IEEE PAMI 18(7):673-689, 1996, section 3. One frame's predicted
// label image is compared with its ground-truth label image (0 = no region, in both). With P_m the
// pixel count of ground-truth region m, P_n that of predicted region n, O_mn their overlap and a
// threshold 0.5 < T <= 1:
//   correct detection  m and n with O_mn >= T P_m and O_mn >= T P_n;
//   over-segmentation  m and predicted n_1..n_x (x >= 2) with O_mn_i >= T P_n_i for every i and
//                      sum_i O_mn_i >= T P_m (m split into several predicted regions);
//   under-segmentation n and ground-truth m_1..m_x (x >= 2) with O_m_i n >= T P_m_i for every i and
//                      sum_i O_m_i n >= T P_n (several ground-truth regions merged into n);
//   missed             a ground-truth region in no instance above;
//   noise              a predicted region in no instance above.
// Instances are found in that order and a region joins at most one: correct detections first, then
// over-segmentations among the remaining regions, then under-segmentations. (With T > 0.5 a region
// has at most one partner that contains T of it, so each step's candidates are unambiguous.)
// Region sizes count all of a region's pixels, including those where the other image has label 0.
//
// With plane normals given for both sides, the angle between the normals of every correct
// detection is averaged (the paper's "angle difference"); sign-free, so opposite orientation
// conventions do not count as error.
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/label_image.hpp"

namespace kartograf::eval {

struct SegCompParams {
  double threshold = 0.8;  // T; the paper reports 0.51 ... 0.95, and 0.8 in most tables
};

using PlaneNormals = std::map<Label, Eigen::Vector3d>;  // label -> normal (any length > 0)

struct SegCompResult {
  int ground_truth_regions = 0;
  int predicted_regions = 0;
  int correct = 0;          // instances (one ground-truth and one predicted region each)
  int over_segmented = 0;   // ground-truth regions split
  int under_segmented = 0;  // predicted regions that merge several ground-truth regions
  int missed = 0;           // ground-truth regions
  int noise = 0;            // predicted regions
  std::vector<std::pair<Label, Label>> correct_pairs;  // (ground truth, predicted), ascending
  int normal_pairs = 0;                         // correct detections with a normal on both sides
  std::optional<double> mean_normal_error_deg;  // over those; empty when there are none
};

SegCompResult compare_plane_segmentations(const LabelImage& ground_truth,
                                          const LabelImage& predicted,
                                          const SegCompParams& options = {});

SegCompResult compare_plane_segmentations(const LabelImage& ground_truth,
                                          const LabelImage& predicted,
                                          const SegCompParams& options,
                                          const PlaneNormals& ground_truth_normals,
                                          const PlaneNormals& predicted_normals);

}  // namespace kartograf::eval
