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

enum class Side { ground_truth, predicted };

// Over-segmentations (whole = the ground truth) or under-segmentations (whole = the prediction):
// remaining regions of `whole` that two or more remaining regions of the other side fill, each
// lying (T of it) inside, together T of the whole. Marks them and their parts done; returns how
// many there are. Cells are sorted by ground-truth region.
int count_split_regions(const LabelOverlap& overlap, Side whole, double t,
                        std::vector<bool>& gt_done, std::vector<bool>& predicted_done) {
  const bool gt_whole = whole == Side::ground_truth;
  const auto& wholes = gt_whole ? overlap.ground_truth : overlap.predicted;
  const auto& parts = gt_whole ? overlap.predicted : overlap.ground_truth;
  std::vector<bool>& whole_done = gt_whole ? gt_done : predicted_done;
  std::vector<bool>& part_done = gt_whole ? predicted_done : gt_done;
  const auto whole_of = [&](const LabelOverlap::Cell& c) {
    return gt_whole ? c.ground_truth : c.predicted;
  };
  const auto part_of = [&](const LabelOverlap::Cell& c) {
    return gt_whole ? c.predicted : c.ground_truth;
  };
  const auto contains_t_of = [t](std::int64_t part, std::int64_t all) {
    return static_cast<double>(part) >= t * static_cast<double>(all);
  };
  std::vector<std::int64_t> inside_sum(wholes.size(), 0);
  std::vector<int> inside_count(wholes.size(), 0);
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    if (whole_done[whole_of(cell)] || part_done[part_of(cell)]) continue;
    if (!contains_t_of(cell.pixels, parts[part_of(cell)].pixels)) continue;
    inside_sum[whole_of(cell)] += cell.pixels;
    ++inside_count[whole_of(cell)];
  }
  std::vector<bool> split(wholes.size(), false);
  for (std::size_t w = 0; w < wholes.size(); ++w) {
    split[w] =
        !whole_done[w] && inside_count[w] >= 2 && contains_t_of(inside_sum[w], wholes[w].pixels);
  }
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    if (!split[whole_of(cell)] || part_done[part_of(cell)]) continue;
    if (contains_t_of(cell.pixels, parts[part_of(cell)].pixels)) part_done[part_of(cell)] = true;
  }
  int count = 0;
  for (std::size_t w = 0; w < wholes.size(); ++w) {
    if (!split[w]) continue;
    whole_done[w] = true;
    ++count;
  }
  return count;
}

}  // namespace

SegCompResult compare_plane_segmentations(const LabelImage& ground_truth,
                                          const LabelImage& predicted,
                                          const SegCompParams& options) {
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

  result.over_segmented =
      count_split_regions(overlap, Side::ground_truth, t, gt_done, predicted_done);
  result.under_segmented =
      count_split_regions(overlap, Side::predicted, t, gt_done, predicted_done);

  result.missed = static_cast<int>(std::count(gt_done.begin(), gt_done.end(), false));
  result.noise = static_cast<int>(std::count(predicted_done.begin(), predicted_done.end(), false));
  return result;
}

SegCompResult compare_plane_segmentations(const LabelImage& ground_truth,
                                          const LabelImage& predicted,
                                          const SegCompParams& options,
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
