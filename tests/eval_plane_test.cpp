// SegComp (eval/plane_metrics.hpp) on hand-drawn label images, one per Hoover et al. instance
// type, with the threshold deciding between them, and the normal-angle average.
#include <cmath>
#include <numbers>
#include <ostream>
#include <utility>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/plane_metrics.hpp"
#include "label_image_builders.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using testing::label_rectangles;

// Two 10x10 ground-truth planes side by side in a 30x10 frame; the right third has no label.
LabelImage two_planes() {
  return label_rectangles(30, 10, {{0, 0, 10, 10, 1}, {10, 0, 20, 10, 2}});
}

// The five instance counts of a comparison, checked together so that a failure shows them all.
struct Counts {
  int correct, over_segmented, under_segmented, missed, noise;
  bool operator==(const Counts&) const = default;
};

Counts counts_of(const eval::SegCompResult& result) {
  return {result.correct, result.over_segmented, result.under_segmented, result.missed,
          result.noise};
}

void PrintTo(const Counts& c, std::ostream* out) {
  *out << "correct " << c.correct << ", over-segmented " << c.over_segmented << ", under-segmented "
       << c.under_segmented << ", missed " << c.missed << ", noise " << c.noise;
}

TEST(EvalPlanes, IdenticalSegmentationsAreAllCorrect) {
  const LabelImage gt = two_planes();
  LabelImage renamed = gt;  // labels need not agree, only regions
  for (Label& l : renamed.pixels()) l = l == 1 ? 7 : l == 2 ? 3 : l;
  const auto result = eval::compare_plane_segmentations(gt, renamed);
  EXPECT_EQ(result.ground_truth_regions, 2);
  EXPECT_EQ(result.predicted_regions, 2);
  EXPECT_EQ(counts_of(result), (Counts{2, 0, 0, 0, 0}));
  ASSERT_EQ(result.correct_pairs.size(), 2u);
  EXPECT_EQ(result.correct_pairs[0], (std::pair<Label, Label>{1, 7}));
  EXPECT_EQ(result.correct_pairs[1], (std::pair<Label, Label>{2, 3}));
}

TEST(EvalPlanes, ASplitPlaneIsOverSegmented) {
  LabelImage predicted = two_planes();
  testing::paint(predicted, {{0, 5, 10, 10, 9}});  // plane 1 in two halves: each wholly inside it
  const auto result = eval::compare_plane_segmentations(two_planes(), predicted);
  EXPECT_EQ(counts_of(result), (Counts{1, 1, 0, 0, 0}));
}

TEST(EvalPlanes, MergedPlanesAreUnderSegmented) {
  const LabelImage predicted = label_rectangles(30, 10, {{0, 0, 20, 10, 4}});
  const auto result = eval::compare_plane_segmentations(two_planes(), predicted);
  EXPECT_EQ(counts_of(result), (Counts{0, 0, 1, 0, 0}));
}

TEST(EvalPlanes, UnmatchedRegionsAreMissedOrNoise) {
  const LabelImage predicted = label_rectangles(30, 10,
                                                {
                                                    {0, 0, 10, 10, 1},  // plane 1 found
                                                    {22, 2, 28, 8, 5},  // where the truth has none
                                                });
  const auto result = eval::compare_plane_segmentations(two_planes(), predicted);
  EXPECT_EQ(counts_of(result), (Counts{1, 0, 0, 1, 1}));  // plane 2 missed, region 5 noise
}

TEST(EvalPlanes, TheThresholdDecidesWhatCountsAsCorrect) {
  // Predicted region: 85 of plane 1's 100 pixels and nothing else. O = 85 >= 0.8 * 100 and
  // >= 0.8 * 85: correct at T = 0.8. At T = 0.9, 85 < 90: not correct, not part of a split (one
  // region) nor a merge (plane 1 is not 90 % inside it): plane 1 missed, the region noise.
  const LabelImage predicted = label_rectangles(30, 10, {{0, 0, 10, 8, 1}, {0, 8, 5, 9, 1}});
  const LabelImage gt = two_planes();
  const auto loose = eval::compare_plane_segmentations(gt, predicted, {0.8});
  EXPECT_EQ(counts_of(loose), (Counts{1, 0, 0, 1, 0}));  // plane 2 missed
  const auto strict = eval::compare_plane_segmentations(gt, predicted, {0.9});
  EXPECT_EQ(counts_of(strict), (Counts{0, 0, 0, 2, 1}));
}

TEST(EvalPlanes, AFragmentOutsideThePlaneDoesNotMakeASplit) {
  // Plane 1 = regions 1 (left 60 %) and 6 (right 40 %, but 6 also covers 60 pixels of no label):
  // region 6 is only 40 % inside plane 1, so no over-segmentation; region 1 holds 60 < 80 of
  // plane 1. Plane 1 missed; regions 1 and 6 are noise.
  const LabelImage predicted = label_rectangles(
      30, 10, {{0, 0, 6, 10, 1}, {6, 0, 10, 10, 6}, {20, 0, 26, 10, 6}, {10, 0, 20, 10, 2}});
  const auto result = eval::compare_plane_segmentations(two_planes(), predicted);
  EXPECT_EQ(counts_of(result), (Counts{1, 0, 0, 1, 2}));  // plane 2 correct
}

TEST(EvalPlanes, AveragesTheAngleBetweenNormalsOfCorrectDetections) {
  const LabelImage gt = two_planes();
  const eval::PlaneNormals gt_normals = {{1, {0, 0, 1}}, {2, {1, 0, 0}}};
  // Plane 1 exact but flipped (0 deg: sign-free), plane 2 off by 10 deg.
  const double ten = 10 * std::numbers::pi / 180;
  const eval::PlaneNormals predicted_normals = {{1, {0, 0, -2}},
                                                {2, {std::cos(ten), std::sin(ten), 0}}};
  const auto result = eval::compare_plane_segmentations(gt, gt, {}, gt_normals, predicted_normals);
  EXPECT_EQ(result.normal_pairs, 2);
  ASSERT_TRUE(result.mean_normal_error_deg.has_value());
  EXPECT_NEAR(*result.mean_normal_error_deg, 5.0, 1e-9);
  const auto without = eval::compare_plane_segmentations(gt, gt, {}, gt_normals, {});
  EXPECT_FALSE(without.mean_normal_error_deg.has_value());
  EXPECT_THROW(eval::compare_plane_segmentations(gt, gt, {}, {{1, {0, 0, 0}}}, {}), Error);
}

TEST(EvalPlanes, RejectsBadInput) {
  const LabelImage gt = two_planes();
  EXPECT_THROW(eval::compare_plane_segmentations(gt, gt, {0.5}), Error);
  EXPECT_THROW(eval::compare_plane_segmentations(gt, gt, {1.01}), Error);
  EXPECT_THROW(eval::compare_plane_segmentations(gt, LabelImage(30, 11, 0)), Error);
}

}  // namespace
}  // namespace kartograf
