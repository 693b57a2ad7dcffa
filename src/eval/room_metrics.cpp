#include "kartograf/eval/room_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/label_overlap.hpp"

namespace kartograf::eval {

namespace {

constexpr char kWhat[] = "room segmentation evaluation";

// Mean of best[i] / area[i] and sum(best) / sum(area) over the kept regions.
struct RatioSummary {
  std::vector<double> ratios;
  double mean = 0, total = 0;
};

RatioSummary summarize_ratios(const std::vector<std::int64_t>& best,
                              const std::vector<LabelOverlap::Region>& regions,
                              const std::vector<bool>& kept) {
  RatioSummary summary;
  double best_sum = 0, area_sum = 0;
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (!kept[i]) continue;
    const double area = static_cast<double>(regions[i].pixels);
    summary.ratios.push_back(static_cast<double>(best[i]) / area);
    best_sum += static_cast<double>(best[i]);
    area_sum += area;
  }
  if (summary.ratios.empty()) return summary;
  for (double ratio : summary.ratios) summary.mean += ratio;
  summary.mean /= static_cast<double>(summary.ratios.size());
  summary.total = best_sum / area_sum;
  return summary;
}

double matthews(double tp, double fp, double tn, double fn) {
  const double denominator = std::sqrt((tp + fp) * (tp + fn) * (tn + fp) * (tn + fn));
  if (denominator > 0) return (tp * tn - fp * fn) / denominator;
  return fp == 0 && fn == 0 ? 1.0 : 0.0;
}

void compute_mcc(const LabelOverlap& overlap, RoomSegmentationScores& scores) {
  // Region sizes on the pixels labelled in both images.
  std::vector<std::int64_t> gt_size(overlap.ground_truth.size(), 0);
  std::vector<std::int64_t> segment_size(overlap.predicted.size(), 0);
  std::vector<std::vector<const LabelOverlap::Cell*>> cells_of_segment(overlap.predicted.size());
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    gt_size[cell.ground_truth] += cell.pixels;
    segment_size[cell.predicted] += cell.pixels;
    cells_of_segment[cell.predicted].push_back(&cell);
  }
  // Each segment's rooms by decreasing overlap (ties: lower room label, i.e. lower index).
  for (auto& cells : cells_of_segment) {
    std::stable_sort(cells.begin(), cells.end(),
                     [](const auto* a, const auto* b) { return a->pixels > b->pixels; });
  }
  std::vector<std::size_t> order;
  for (std::size_t s = 0; s < cells_of_segment.size(); ++s) {
    if (!cells_of_segment[s].empty()) order.push_back(s);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return cells_of_segment[a].front()->pixels > cells_of_segment[b].front()->pixels;
  });

  const double n = static_cast<double>(overlap.both_labeled_pixels);
  std::vector<bool> room_taken(overlap.ground_truth.size(), false);
  double mcc_sum = 0;
  for (std::size_t s : order) {
    const auto match =
        std::find_if(cells_of_segment[s].begin(), cells_of_segment[s].end(),
                     [&](const auto* cell) { return !room_taken[cell->ground_truth]; });
    if (match == cells_of_segment[s].end()) {
      ++scores.mcc_unmatched_regions;
      continue;
    }
    const LabelOverlap::Cell& cell = **match;
    room_taken[cell.ground_truth] = true;
    const double tp = static_cast<double>(cell.pixels);
    const double fp = static_cast<double>(segment_size[s]) - tp;
    const double fn = static_cast<double>(gt_size[cell.ground_truth]) - tp;
    mcc_sum += matthews(tp, fp, n - tp - fp - fn, fn);
    ++scores.mcc_matched_pairs;
  }
  for (std::size_t g = 0; g < gt_size.size(); ++g) {
    if (gt_size[g] > 0 && !room_taken[g]) ++scores.mcc_unmatched_regions;
  }
  const int regions = scores.mcc_matched_pairs + scores.mcc_unmatched_regions;
  scores.mcc = regions > 0 ? mcc_sum / regions : 0.0;
}

}  // namespace

RoomEvaluationParams room_evaluation_params(double metres_per_cell) {
  require(std::isfinite(metres_per_cell) && metres_per_cell > 0,
          std::string(kWhat) +
              ": the map's resolution must be a positive number of metres per "
              "cell, got " +
              std::to_string(metres_per_cell));
  constexpr double kIpaSpeckArea = 100 * 0.05 * 0.05;  // m^2
  // The small epsilon keeps 0.05 m at exactly 100 cells despite rounding in the division.
  const double cells = std::floor(kIpaSpeckArea / (metres_per_cell * metres_per_cell) + 1e-9);
  RoomEvaluationParams params;
  params.min_region_pixels = static_cast<int>(std::min(cells, 1e9)) + 1;
  return params;
}

RoomSegmentationScores evaluate_room_segmentation(const LabelImage& ground_truth,
                                                  const LabelImage& segmentation,
                                                  const RoomEvaluationParams& options) {
  require(options.min_region_pixels >= 1, std::string(kWhat) +
                                              ": min_region_pixels must be >= 1, got " +
                                              std::to_string(options.min_region_pixels));
  const LabelOverlap overlap = compute_label_overlap(ground_truth, segmentation, kWhat);
  const auto kept_regions = [&](const std::vector<LabelOverlap::Region>& regions) {
    std::vector<bool> kept(regions.size());
    for (std::size_t i = 0; i < regions.size(); ++i) {
      kept[i] = regions[i].pixels >= options.min_region_pixels;
    }
    return kept;
  };
  const std::vector<bool> room_kept = kept_regions(overlap.ground_truth);
  const std::vector<bool> segment_kept = kept_regions(overlap.predicted);

  RoomSegmentationScores scores;
  scores.ground_truth_rooms =
      static_cast<int>(std::count(room_kept.begin(), room_kept.end(), true));
  scores.segments = static_cast<int>(std::count(segment_kept.begin(), segment_kept.end(), true));
  require(scores.ground_truth_rooms > 0,
          std::string(kWhat) + ": the ground truth has no room of >= " +
              std::to_string(options.min_region_pixels) + " pixels (it has " +
              std::to_string(overlap.ground_truth.size()) + " labelled regions)");

  std::vector<std::int64_t> room_best(overlap.ground_truth.size(), 0);
  std::vector<std::int64_t> segment_best(overlap.predicted.size(), 0);
  for (const LabelOverlap::Cell& cell : overlap.cells) {
    if (!room_kept[cell.ground_truth] || !segment_kept[cell.predicted]) continue;
    room_best[cell.ground_truth] = std::max(room_best[cell.ground_truth], cell.pixels);
    segment_best[cell.predicted] = std::max(segment_best[cell.predicted], cell.pixels);
  }
  RatioSummary recall = summarize_ratios(room_best, overlap.ground_truth, room_kept);
  RatioSummary precision = summarize_ratios(segment_best, overlap.predicted, segment_kept);
  scores.recall_mean = recall.mean;
  scores.recall_total = recall.total;
  scores.room_recall = std::move(recall.ratios);
  scores.precision_mean = precision.mean;
  scores.precision_total = precision.total;
  scores.segment_precision = std::move(precision.ratios);

  compute_mcc(overlap, scores);
  return scores;
}

}  // namespace kartograf::eval
