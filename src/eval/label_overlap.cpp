#include "kartograf/eval/label_overlap.hpp"

#include <algorithm>
#include <limits>
#include <string>
#include <unordered_map>

#include "kartograf/core/error.hpp"

namespace kartograf::eval {

namespace {

// The regions present in an image, ascending, and a label -> region index table.
std::vector<LabelOverlap::Region> regions_of(const LabelImage& image,
                                             std::vector<std::size_t>& index_of_label) {
  std::vector<std::int64_t> counts(std::size_t{std::numeric_limits<Label>::max()} + 1, 0);
  for (Label label : image.pixels()) ++counts[label];
  std::vector<LabelOverlap::Region> regions;
  index_of_label.assign(counts.size(), 0);
  for (std::size_t label = 1; label < counts.size(); ++label) {
    if (counts[label] == 0) continue;
    index_of_label[label] = regions.size();
    regions.push_back({static_cast<Label>(label), counts[label]});
  }
  return regions;
}

}  // namespace

LabelOverlap compute_label_overlap(const LabelImage& ground_truth, const LabelImage& predicted,
                                   std::string_view what) {
  require(ground_truth.width() == predicted.width() && ground_truth.height() == predicted.height(),
          std::string(what) + ": the ground truth is " + std::to_string(ground_truth.width()) +
              "x" + std::to_string(ground_truth.height()) + " but the prediction is " +
              std::to_string(predicted.width()) + "x" + std::to_string(predicted.height()));
  LabelOverlap overlap;
  std::vector<std::size_t> gt_index, predicted_index;
  overlap.ground_truth = regions_of(ground_truth, gt_index);
  overlap.predicted = regions_of(predicted, predicted_index);

  std::unordered_map<std::uint32_t, std::int64_t> pairs;  // (gt label << 16 | predicted label)
  const auto gt_pixels = ground_truth.pixels();
  const auto predicted_pixels = predicted.pixels();
  for (std::size_t i = 0; i < gt_pixels.size(); ++i) {
    if (gt_pixels[i] == kUnlabeled || predicted_pixels[i] == kUnlabeled) continue;
    ++pairs[(std::uint32_t{gt_pixels[i]} << 16) | predicted_pixels[i]];
    ++overlap.both_labeled_pixels;
  }
  overlap.cells.reserve(pairs.size());
  for (const auto& [key, pixels] : pairs) {
    overlap.cells.push_back({gt_index[key >> 16], predicted_index[key & 0xffffu], pixels});
  }
  std::sort(overlap.cells.begin(), overlap.cells.end(), [](const auto& a, const auto& b) {
    return a.ground_truth != b.ground_truth ? a.ground_truth < b.ground_truth
                                            : a.predicted < b.predicted;
  });
  return overlap;
}

}  // namespace kartograf::eval
