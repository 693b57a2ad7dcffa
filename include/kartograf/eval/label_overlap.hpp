#pragma once
// The overlap table of two label images of the same size: every region's pixel count and the
// pixel count of every non-empty (ground-truth region, predicted region) intersection. The
// region-matching metrics (SegComp for planes, recall/precision and MCC for rooms) all start here.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "kartograf/core/label_image.hpp"

namespace kartograf::eval {

struct LabelOverlap {
  struct Region {
    Label label = kUnlabeled;
    std::int64_t pixels = 0;  // all pixels with this label, whatever the other image says there
  };
  struct Cell {
    std::size_t ground_truth = 0;  // index into ground_truth
    std::size_t predicted = 0;     // index into predicted
    std::int64_t pixels = 0;       // > 0
  };
  std::vector<Region> ground_truth;  // labels present (0 excluded), ascending
  std::vector<Region> predicted;
  std::vector<Cell> cells;               // sorted by (ground_truth, predicted)
  std::int64_t both_labeled_pixels = 0;  // pixels labelled in both images
};

// `what` names the caller in the size-mismatch error.
LabelOverlap compute_label_overlap(const LabelImage& ground_truth, const LabelImage& predicted,
                                   std::string_view what);

}  // namespace kartograf::eval
