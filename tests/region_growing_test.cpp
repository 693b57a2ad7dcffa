// CIE-Lab conversion (known answers) and the paper's Lab region growing on hand-built images:
// colour blocks, the running-mean behaviour on a ramp, invalid pixels, and the depth-jump and
// tile variants.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/segmentation/region_growing.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using segmentation::LabImage;
using segmentation::RegionGrowingParams;
using segmentation::SegmentLabelImage;

void expect_lab(const Rgb8& rgb, const Eigen::Vector3f& expected) {
  const Eigen::Vector3f lab = segmentation::rgb_to_lab(rgb);
  EXPECT_NEAR(lab.x(), expected.x(), 0.01)
      << int{rgb[0]} << "," << int{rgb[1]} << "," << int{rgb[2]};
  EXPECT_NEAR(lab.y(), expected.y(), 0.01)
      << int{rgb[0]} << "," << int{rgb[1]} << "," << int{rgb[2]};
  EXPECT_NEAR(lab.z(), expected.z(), 0.01)
      << int{rgb[0]} << "," << int{rgb[1]} << "," << int{rgb[2]};
}

TEST(LabColor, KnownAnswers) {
  expect_lab({255, 255, 255}, {100.0f, 0.0f, 0.0f});
  expect_lab({0, 0, 0}, {0.0f, 0.0f, 0.0f});
  expect_lab({255, 0, 0}, {53.24f, 80.09f, 67.20f});
  expect_lab({0, 255, 0}, {87.73f, -86.18f, 83.18f});
  expect_lab({0, 0, 255}, {32.30f, 79.19f, -107.86f});
  // Greys have a* = b* = 0; sRGB 119 is L* 50.03 (CIE tables).
  const Eigen::Vector3f grey = segmentation::rgb_to_lab({119, 119, 119});
  EXPECT_NEAR(grey.x(), 50.03, 0.05);
  EXPECT_NEAR(grey.y(), 0.0, 1e-3);
  EXPECT_NEAR(grey.z(), 0.0, 1e-3);
}

TEST(LabColor, ImageConversionMatchesPerPixelConversion) {
  RgbImage rgb(32, 32);
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      rgb(x, y) = {static_cast<std::uint8_t>(x * 8 + 3), static_cast<std::uint8_t>(y * 8),
                   static_cast<std::uint8_t>((x * 37 + y * 11) % 256)};
    }
  }
  const LabImage lab = segmentation::to_lab(rgb);
  double worst = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      worst = std::max(
          worst,
          double(
              (lab(x, y).head<3>() - segmentation::rgb_to_lab(rgb(x, y))).cwiseAbs().maxCoeff()));
      EXPECT_EQ(lab(x, y).w(), 0.0f);
    }
  }
  EXPECT_LT(worst, 2e-3);
}

PointImage flat_points(int width, int height, float depth = 1.0f) {
  PointImage points(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) points(x, y) = Point4f(0.001f * x, 0.001f * y, depth, 1.0f);
  }
  return points;
}

LabImage uniform_lab(int width, int height, const Eigen::Vector4f& colour) {
  return LabImage(width, height, colour);
}

TEST(RegionGrowing, TwoColourBlocksGiveTwoSegmentsInScanOrder) {
  RgbImage rgb(8, 6);
  for (int y = 0; y < 6; ++y) {
    for (int x = 0; x < 8; ++x) rgb(x, y) = x < 3 ? Rgb8{200, 30, 30} : Rgb8{30, 30, 200};
  }
  const SegmentLabelImage labels =
      segmentation::grow_regions_lab(segmentation::to_lab(rgb), flat_points(8, 6), {});
  EXPECT_EQ(segmentation::segment_count(labels), 2u);
  for (int y = 0; y < 6; ++y) {
    for (int x = 0; x < 8; ++x) EXPECT_EQ(labels(x, y), x < 3 ? 0u : 1u) << x << "," << y;
  }
}

TEST(RegionGrowing, RunningMeanSplitsARampWhoseNeighboursDifferLittle) {
  // L* rises 2.1 per pixel: neighbours differ by far less than 15, but after t pixels the next
  // one is 2.1 (t + 1) / 2 from the running mean, which reaches 15 at t = 14 (eq. 5).
  LabImage lab(40, 1);
  for (int x = 0; x < 40; ++x) lab(x, 0) = Eigen::Vector4f(10.0f + 2.1f * x, 0, 0, 0);
  const SegmentLabelImage labels = segmentation::grow_regions_lab(lab, flat_points(40, 1), {});
  for (int x = 0; x < 40; ++x) EXPECT_EQ(labels(x, 0), static_cast<std::uint32_t>(x / 14)) << x;
  // A looser threshold takes longer runs: 2.1 (t + 1) / 2 < 25 up to t = 22.
  RegionGrowingParams loose;
  loose.lab_threshold = 25.0f;
  const SegmentLabelImage longer = segmentation::grow_regions_lab(lab, flat_points(40, 1), loose);
  for (int x = 0; x < 40; ++x) EXPECT_EQ(longer(x, 0), static_cast<std::uint32_t>(x / 23)) << x;
}

TEST(RegionGrowing, InvalidPixelsNeverJoinAndSplitSegments) {
  PointImage points = flat_points(7, 3);
  for (int y = 0; y < 3; ++y) points(3, y) = invalid_point();  // a wall of missing depth
  const SegmentLabelImage labels =
      segmentation::grow_regions_lab(uniform_lab(7, 3, {50, 0, 0, 0}), points, {});
  EXPECT_EQ(segmentation::segment_count(labels), 2u);
  for (int y = 0; y < 3; ++y) {
    EXPECT_EQ(labels(0, y), 0u);
    EXPECT_EQ(labels(3, y), geometry::kNoLabel);
    EXPECT_EQ(labels(6, y), 1u);
  }
}

TEST(RegionGrowing, DepthJumpOptionSplitsSameColourBlocksAtDifferentDepths) {
  PointImage points = flat_points(10, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 5; x < 10; ++x) points(x, y).z() = 2.0f;
  }
  const LabImage lab = uniform_lab(10, 4, {60, 10, -5, 0});
  EXPECT_EQ(segmentation::segment_count(segmentation::grow_regions_lab(lab, points, {})), 1u);
  RegionGrowingParams depth_aware;
  depth_aware.max_depth_jump = 0.05f;
  const SegmentLabelImage labels = segmentation::grow_regions_lab(lab, points, depth_aware);
  EXPECT_EQ(segmentation::segment_count(labels), 2u);
  EXPECT_EQ(labels(4, 3), 0u);
  EXPECT_EQ(labels(5, 0), 1u);
}

TEST(RegionGrowing, TilesBoundSegments) {
  RegionGrowingParams tiled;
  tiled.tile_size = 16;
  const SegmentLabelImage labels = segmentation::grow_regions_lab(
      uniform_lab(40, 20, {50, 0, 0, 0}), flat_points(40, 20), tiled);
  EXPECT_EQ(segmentation::segment_count(labels), 6u);  // 3 x 2 tiles, the last ones partial
  EXPECT_EQ(labels(15, 15), 0u);
  EXPECT_EQ(labels(16, 0), 1u);
  EXPECT_EQ(labels(39, 0), 2u);
  EXPECT_EQ(labels(0, 16), 3u);
  EXPECT_EQ(labels(39, 19), 5u);
}

TEST(RegionGrowing, RejectsBadInput) {
  EXPECT_ERROR_MENTIONS(segmentation::grow_regions_lab(uniform_lab(4, 4, Eigen::Vector4f::Zero()),
                                                       flat_points(5, 4), {}),
                        "grow_regions_lab", "4x4", "5x4");
  RegionGrowingParams bad;
  bad.lab_threshold = 0.0f;
  EXPECT_ERROR_MENTIONS(segmentation::grow_regions_lab(uniform_lab(4, 4, Eigen::Vector4f::Zero()),
                                                       flat_points(4, 4), bad),
                        "lab_threshold");
  bad = {};
  bad.tile_size = -1;
  EXPECT_ERROR_MENTIONS(segmentation::grow_regions_lab(uniform_lab(4, 4, Eigen::Vector4f::Zero()),
                                                       flat_points(4, 4), bad),
                        "tile_size");
  EXPECT_EQ(segmentation::grow_regions_lab({}, {}, {}).size(), 0u);
}

}  // namespace
}  // namespace kartograf
