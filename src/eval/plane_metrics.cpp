#include "kartograf/eval/plane_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/label_overlap.hpp"

namespace kartograf::eval {

namespace {

constexpr char kWhat[] = "SegComp plane evaluation";

// Angle between two planes' normals in degrees, in [0, 90].
double plane_angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double cosine = std::min(1.0, std::fabs(a.dot(b)) / (a.norm() * b.norm()));
  return std::acos(cosine) * 180.0 / std::numbers::pi;
}

void check_normals(const PlaneNormals& normals, const char* side) {
  for (const auto& [label, normal] : normals) {
    require(normal.allFinite() && normal.norm() > 0,
            std::string(kWhat) + ": the " + side + " normal of label " + std::to_string(label) +
                " is zero or not finite");
  }
}

}  // namespace

SegCompResult compare_plane_segmentations(const LabelImage& ground_truth,
                                          const LabelImage& predicted,
                                          const SegCompOptions& options) {
  const double t = options.threshold;
  require(
      t > 0.5 && t <= 1.0,
      std::string(kWhat) + ": the overlap threshold must be in (0.5, 1], got " + std::to_string(t));
  const LabelOverlap overlap = compute_label_overlap(ground_truth, predicted, kWhat);
  const std::size_t m_count = overlap.ground_truth.size(), n_count = overlap.predicted.size();
  const auto contains_t_of = [t](std::int64_t part, std::int64_t whole) {
    return static_cast<double>(part) >= t * static_cast<double>(whole);
  };

  SegCompResult result;
  result.ground_truth_regions = static_cast<int>(m_count);
  result.predicted_regions = static_cast<int>(n_count);
  std::vector<bool> gt_done(m_count, false), predicted_done(n_count, false);

  // Correct detections: cells (m, n) that hold T of both regions.
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    if (contains_t_of(cell.pixels, overlap.ground_truth[cell.ground_truth].pixels) &&
        contains_t_of(cell.pixels, overlap.predicted[cell.predicted].pixels)) {
      gt_done[cell.ground_truth] = predicted_done[cell.predicted] = true;
      result.correct_pairs.emplace_back(overlap.ground_truth[cell.ground_truth].label,
                                        overlap.predicted[cell.predicted].label);
    }
  }
  result.correct = static_cast<int>(result.correct_pairs.size());

  // Over-segmentations: per remaining ground-truth region, the remaining predicted regions that
  // lie (T of them) inside it; cells are sorted by ground-truth region, so each is one run.
  std::vector<std::int64_t> inside_sum(m_count, 0);
  std::vector<int> inside_count(m_count, 0);
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    if (gt_done[cell.ground_truth] || predicted_done[cell.predicted]) continue;
    if (!contains_t_of(cell.pixels, overlap.predicted[cell.predicted].pixels)) continue;
    inside_sum[cell.ground_truth] += cell.pixels;
    ++inside_count[cell.ground_truth];
  }
  std::vector<bool> over(m_count, false);
  for (std::size_t m = 0; m < m_count; ++m) {
    over[m] = !gt_done[m] && inside_count[m] >= 2 &&
              contains_t_of(inside_sum[m], overlap.ground_truth[m].pixels);
  }
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    if (!over[cell.ground_truth] || predicted_done[cell.predicted]) continue;
    if (contains_t_of(cell.pixels, overlap.predicted[cell.predicted].pixels)) {
      predicted_done[cell.predicted] = true;
    }
  }
  for (std::size_t m = 0; m < m_count; ++m) {
    if (!over[m]) continue;
    gt_done[m] = true;
    ++result.over_segmented;
  }

  // Under-segmentations: per remaining predicted region, the remaining ground-truth regions that
  // lie (T of them) inside it.
  std::vector<std::int64_t> covered_sum(n_count, 0);
  std::vector<int> covered_count(n_count, 0);
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    if (gt_done[cell.ground_truth] || predicted_done[cell.predicted]) continue;
    if (!contains_t_of(cell.pixels, overlap.ground_truth[cell.ground_truth].pixels)) continue;
    covered_sum[cell.predicted] += cell.pixels;
    ++covered_count[cell.predicted];
  }
  std::vector<bool> under(n_count, false);
  for (std::size_t n = 0; n < n_count; ++n) {
    under[n] = !predicted_done[n] && covered_count[n] >= 2 &&
               contains_t_of(covered_sum[n], overlap.predicted[n].pixels);
  }
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    if (!under[cell.predicted] || gt_done[cell.ground_truth]) continue;
    if (contains_t_of(cell.pixels, overlap.ground_truth[cell.ground_truth].pixels)) {
      gt_done[cell.ground_truth] = true;
    }
  }
  for (std::size_t n = 0; n < n_count; ++n) {
    if (!under[n]) continue;
    predicted_done[n] = true;
    ++result.under_segmented;
  }

  result.missed = static_cast<int>(std::count(gt_done.begin(), gt_done.end(), false));
  result.noise = static_cast<int>(std::count(predicted_done.begin(), predicted_done.end(), false));
  return result;
}

SegCompResult compare_plane_segmentations(const LabelImage& ground_truth,
                                          const LabelImage& predicted,
                                          const SegCompOptions& options,
                                          const PlaneNormals& ground_truth_normals,
                                          const PlaneNormals& predicted_normals) {
  check_normals(ground_truth_normals, "ground-truth");
  check_normals(predicted_normals, "predicted");
  SegCompResult result = compare_plane_segmentations(ground_truth, predicted, options);
  double sum_deg = 0;
  for (const auto& [gt_label, predicted_label] : result.correct_pairs) {
    const auto gt_normal = ground_truth_normals.find(gt_label);
    const auto predicted_normal = predicted_normals.find(predicted_label);
    if (gt_normal == ground_truth_normals.end() || predicted_normal == predicted_normals.end()) {
      continue;
    }
    sum_deg += plane_angle_deg(gt_normal->second, predicted_normal->second);
    ++result.normal_pairs;
  }
  if (result.normal_pairs > 0) result.mean_normal_error_deg = sum_deg / result.normal_pairs;
  return result;
}

}  // namespace kartograf::eval
