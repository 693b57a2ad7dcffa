// CIE-Lab conversion (known answers, codes) and the paper's Lab region growing: hand-built images
// (colour blocks, the running mean on a ramp, invalid pixels, the depth-jump and tile variants),
// an independent floating-point implementation of the paper on random images, and the tiled
// growing on every backend against the CPU reference (labels and colours identical) on random,
// synthetic and real frames.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/segment_moments.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/segmentation/region_growing.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "real_data.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using segmentation::LabCode;
using segmentation::LabCodeImage;
using segmentation::LabImage;
using segmentation::RegionGrowingParams;
using segmentation::SegmentLabelImage;
using testing::BackendTest;

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

// The image is converted four pixels at a time: a colour gets the same code (and Lab) wherever
// it sits, in any lane, in a group cut short by the image's end or a chunk's, as alone.
TEST(LabColor, AColourGetsTheSameCodeWhereverItSits) {
  std::mt19937 random(7);
  for (const int width : {1, 3, 5, 7, 641}) {
    RgbImage rgb(width, 3);
    for (Rgb8& pixel : rgb.pixels()) {
      pixel = {static_cast<std::uint8_t>(random()), static_cast<std::uint8_t>(random()),
               static_cast<std::uint8_t>(random())};
    }
    const LabCodeImage codes = segmentation::to_lab_codes(rgb);
    const LabImage lab = segmentation::to_lab(rgb);
    for (std::size_t i = 0; i < rgb.size(); ++i) {
      const RgbImage alone(1, 1, rgb.data()[i]);
      ASSERT_EQ(codes.data()[i], segmentation::to_lab_codes(alone).data()[0]) << width << " " << i;
      ASSERT_EQ(lab.data()[i], segmentation::to_lab(alone).data()[0]) << width << " " << i;
    }
  }
}

TEST(LabColor, CodesAreTheRoundedLabInSixtyFourthsAndMarkInvalidColours) {
  RgbImage rgb(16, 16);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      rgb(x, y) = {static_cast<std::uint8_t>(x * 16), static_cast<std::uint8_t>(y * 16),
                   static_cast<std::uint8_t>(255 - x * 8)};
    }
  }
  const LabImage lab = segmentation::to_lab(rgb);
  const LabCodeImage codes = segmentation::to_lab_codes(rgb);
  EXPECT_EQ(segmentation::to_lab_codes(lab).pixels().size(), codes.size());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    EXPECT_EQ(codes.data()[i], segmentation::to_lab_codes(lab).data()[i]);
    EXPECT_EQ(codes.data()[i][3], 1);
    const Eigen::Vector3f back = segmentation::lab_of(codes.data()[i]);
    EXPECT_LE((back - lab.data()[i].head<3>()).cwiseAbs().maxCoeff(), 0.5f / 64.0f + 1e-6f);
  }
  LabImage odd(3, 1, Eigen::Vector4f(50, 0, 0, 0));
  odd(0, 0).y() = std::nanf("");
  odd(1, 0).z() = INFINITY;
  odd(2, 0) = Eigen::Vector4f(900, -900, 20, 0);  // clamped to +-255
  const LabCodeImage odd_codes = segmentation::to_lab_codes(odd);
  EXPECT_EQ(odd_codes(0, 0)[3], 0);
  EXPECT_EQ(odd_codes(1, 0)[3], 0);
  EXPECT_EQ(odd_codes(2, 0), (LabCode{255 * 64, -255 * 64, 20 * 64, 1}));
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

TEST(RegionGrowing, ThresholdIsStrict) {
  // Two pixels exactly 15 apart: the second is not below the threshold, so not joined.
  LabImage lab(2, 1);
  lab(0, 0) = Eigen::Vector4f(40, 0, 0, 0);
  lab(1, 0) = Eigen::Vector4f(55, 0, 0, 0);
  EXPECT_EQ(segmentation::segment_count(segmentation::grow_regions_lab(lab, flat_points(2, 1), {})),
            2u);
  RegionGrowingParams wider;
  wider.lab_threshold = 15.02f;  // 961 codes > 960
  EXPECT_EQ(
      segmentation::segment_count(segmentation::grow_regions_lab(lab, flat_points(2, 1), wider)),
      1u);
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
  LabImage lab = uniform_lab(7, 3, {50, 0, 0, 0});
  lab(0, 0).x() = std::nanf("");  // no colour: no segment either
  EXPECT_EQ(segmentation::grow_regions_lab(lab, flat_points(7, 3), {})(0, 0), geometry::kNoLabel);
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

TEST(RegionGrowing, TilesBoundSegmentsAndNumberThemTileByTile) {
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
                        "region growing", "4x4", "5x4");
  RegionGrowingParams bad;
  bad.lab_threshold = 0.0f;
  EXPECT_ERROR_MENTIONS(segmentation::grow_regions_lab(uniform_lab(4, 4, Eigen::Vector4f::Zero()),
                                                       flat_points(4, 4), bad),
                        "lab_threshold");
  bad = {};
  bad.max_depth_jump = std::nanf("");
  EXPECT_ERROR_MENTIONS(bad.validate(), "max_depth_jump");
  bad = {};
  bad.tile_size = -1;
  EXPECT_ERROR_MENTIONS(segmentation::grow_regions_lab(uniform_lab(4, 4, Eigen::Vector4f::Zero()),
                                                       flat_points(4, 4), bad),
                        "tile_size");
  EXPECT_EQ(segmentation::grow_regions_lab({}, {}, {}).size(), 0u);
}

// An independent implementation of the paper's growing (figure 7 of the M1 paper): float Lab from
// the codes, the running mean in double by eq. 5, the scan and stack as the paper describes.
SegmentLabelImage paper_growing(const LabCodeImage& codes, const PointImage& points,
                                const RegionGrowingParams& params) {
  const int width = codes.width(), height = codes.height();
  SegmentLabelImage labels(width, height, geometry::kNoLabel);
  const int tile = params.tile_size > 0 ? params.tile_size : std::max(width, height);
  const auto valid = [&](int x, int y) { return codes(x, y)[3] != 0 && is_valid(points(x, y)); };
  std::uint32_t next = 0;
  for (int ty = 0; ty < height; ty += tile) {
    for (int tx = 0; tx < width; tx += tile) {
      for (int sy = ty; sy < std::min(height, ty + tile); ++sy) {
        for (int sx = tx; sx < std::min(width, tx + tile); ++sx) {
          if (labels(sx, sy) != geometry::kNoLabel || !valid(sx, sy)) continue;
          const std::uint32_t id = next++;
          Eigen::Vector3d mean = segmentation::lab_of(codes(sx, sy)).cast<double>();
          double t = 0;
          std::vector<std::pair<int, int>> stack{{sx, sy}};
          while (!stack.empty()) {
            const auto [x, y] = stack.back();
            stack.pop_back();
            if (labels(x, y) != geometry::kNoLabel) continue;
            const Eigen::Vector3d c = segmentation::lab_of(codes(x, y)).cast<double>();
            if ((c - mean).norm() >= params.lab_threshold) continue;
            labels(x, y) = id;
            mean += (c - mean) / (t + 1);  // eq. 5
            t += 1;
            for (int dy = -1; dy <= 1; ++dy) {
              for (int dx = -1; dx <= 1; ++dx) {
                const int nx = x + dx, ny = y + dy;
                if ((dx == 0 && dy == 0) || nx < tx || ny < ty ||
                    nx >= std::min(width, tx + tile) || ny >= std::min(height, ty + tile) ||
                    labels(nx, ny) != geometry::kNoLabel || !valid(nx, ny)) {
                  continue;
                }
                const double z = points(x, y).z(), nz = points(nx, ny).z();
                if (params.max_depth_jump > 0 && std::fabs(nz - z) > params.max_depth_jump * z)
                  continue;
                stack.emplace_back(nx, ny);
              }
            }
          }
        }
      }
    }
  }
  return labels;
}

// Random blocky colours (blocks of random size with jitter) over depth with holes and steps:
// segments of all sizes, ramps and seams.
struct RandomFrame {
  LabCodeImage codes;
  PointImage points;
};

RandomFrame random_frame(std::mt19937_64& rng, int width, int height) {
  RandomFrame frame{LabCodeImage(width, height), PointImage(width, height)};
  std::uniform_real_distribution<float> colour(-60.0f, 60.0f), jitter(-4.0f, 4.0f);
  std::uniform_real_distribution<float> depth(0.8f, 1.2f);
  std::uniform_int_distribution<int> percent(0, 99), block(3, 14);
  const int block_w = block(rng), block_h = block(rng);
  std::vector<Eigen::Vector3f> colours(4096);
  for (auto& c : colours) c = Eigen::Vector3f(50.0f + 0.8f * colour(rng), colour(rng), colour(rng));
  LabImage lab(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector3f base = colours[((y / block_h) * 64 + x / block_w) % 4096];
      lab(x, y) = Eigen::Vector4f(base.x() + jitter(rng) + 0.3f * x, base.y() + jitter(rng),
                                  base.z() + jitter(rng), 0.0f);
      frame.points(x, y) = percent(rng) < 3
                               ? invalid_point()
                               : Point4f(0.0f, 0.0f, (x / 23) % 2 ? depth(rng) : 1.0f, 1.0f);
    }
  }
  frame.codes = segmentation::to_lab_codes(lab);
  return frame;
}

std::size_t mismatches(const SegmentLabelImage& a, const SegmentLabelImage& b) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < a.size(); ++i) count += a.pixels()[i] != b.pixels()[i];
  return count;
}

TEST(RegionGrowing, EqualsAnIndependentImplementationOfThePaperOnRandomImages) {
  std::mt19937_64 rng(5);
  for (int round = 0; round < 6; ++round) {
    const RandomFrame frame = random_frame(rng, 97, 61);
    for (const RegionGrowingParams& params :
         {RegionGrowingParams{}, RegionGrowingParams{10.0f, 0.05f, 0},
          RegionGrowingParams{20.0f, 0.0f, 16}, RegionGrowingParams{15.0f, 0.02f, 7}}) {
      SegmentLabelImage labels;
      const std::uint32_t count =
          segmentation::grow_regions(frame.codes, frame.points, params, labels);
      const SegmentLabelImage expected = paper_growing(frame.codes, frame.points, params);
      EXPECT_EQ(mismatches(labels, expected), 0u)
          << "round " << round << " threshold " << params.lab_threshold << " tile "
          << params.tile_size;
      EXPECT_EQ(count, segmentation::segment_count(expected));
      EXPECT_GT(count, 20u);
    }
  }
}

TEST(RegionGrowing, LabelsAndStatisticsDoNotDependOnTheThreadCount) {
  std::mt19937_64 rng(9);
  const RandomFrame frame = random_frame(rng, 320, 240);
  const RegionGrowingParams params{15.0f, 0.02f, 16};
  const Eigen::Vector3d origin(0, 0, 1);
  SegmentLabelImage one, two;
  segmentation::SegmentStatistics stats_one, stats_two;
  {
    const testing::ScopedCpuThreads threads("1");
    segmentation::grow_regions(frame.codes, frame.points, params, one, &stats_one, &origin);
  }
  {
    const testing::ScopedCpuThreads threads("3");
    segmentation::grow_regions(frame.codes, frame.points, params, two, &stats_two, &origin);
  }
  EXPECT_EQ(mismatches(one, two), 0u);
  EXPECT_EQ(stats_one.colours, stats_two.colours);
  ASSERT_EQ(stats_one.moments.size(), stats_two.moments.size());
  for (std::size_t s = 0; s < stats_one.moments.size(); ++s) {
    EXPECT_EQ(stats_one.moments[s].count, stats_two.moments[s].count);
    EXPECT_EQ(stats_one.moments[s].sum, stats_two.moments[s].sum);
    EXPECT_EQ(stats_one.moments[s].sum_outer, stats_two.moments[s].sum_outer);
  }
  // The colours are the segments' mean colours.
  std::vector<Eigen::Vector4d> sums(stats_one.colours.size(), Eigen::Vector4d::Zero());
  for (std::size_t i = 0; i < one.size(); ++i) {
    if (one.data()[i] == geometry::kNoLabel) continue;
    sums[one.data()[i]] +=
        (Eigen::Vector4d() << segmentation::lab_of(frame.codes.data()[i]).cast<double>(), 1.0)
            .finished();
  }
  for (std::size_t s = 0; s < sums.size(); ++s) {
    EXPECT_LT((stats_one.colours[s].cast<double>() - sums[s].head<3>() / sums[s].w()).norm(), 1e-4)
        << s;
  }
}

class RegionGrowerTest : public BackendTest {
 protected:
  // The grower on this backend against the CPU reference: the same labels, count and colours;
  // the moments the reference sums in double as it grows agree with the fixed-point reduction of
  // the grower's labels on this backend to 1e-9 (relative to the segment's spread).
  void expect_same_as_reference(const LabCodeImage& codes, const PointImage& points,
                                const RegionGrowingParams& params, const std::string& what) {
    SCOPED_TRACE(what + ", tile " + std::to_string(params.tile_size));
    geometry::SegmentMomentParams moment_params;
    moment_params.origin = Eigen::Vector3f(0, 0, 2);
    moment_params.max_offset = 8.0f;
    const Eigen::Vector3d origin = moment_params.origin.cast<double>();
    SegmentLabelImage expected;
    segmentation::SegmentStatistics statistics;
    const std::uint32_t expected_count =
        segmentation::grow_regions(codes, points, params, expected, &statistics, &origin);
    segmentation::RegionGrower grower(context());
    const auto device_points = compute::Buffer<Point4f>::from_host(context(), points.pixels());
    std::vector<Eigen::Vector3f> colours;
    const std::uint32_t count = grower.grow(codes, device_points, params, &colours);
    EXPECT_EQ(count, expected_count);
    EXPECT_EQ(mismatches(grower.download_labels(), expected), 0u);
    EXPECT_EQ(colours, statistics.colours);
    if (count > 0 && count <= geometry::kMaxSegmentLabels) {
      moment_params.label_count = count;
      const geometry::SegmentMomentSet reduced =
          geometry::segment_moments(context(), device_points, grower.labels(), moment_params);
      ASSERT_EQ(reduced.segments.size(), statistics.moments.size());
      double worst = 0;
      for (std::size_t s = 0; s < reduced.segments.size(); ++s) {
        const geometry::SegmentMoments& fused = statistics.moments[s];
        EXPECT_EQ(reduced.segments[s].count, fused.count) << s;
        const double n = static_cast<double>(fused.count);
        const double scale = 1.0 + fused.sum_outer.trace() / n;
        worst = std::max({worst, (reduced.segments[s].sum - fused.sum).norm() / (n * scale),
                          (reduced.segments[s].sum_outer - fused.sum_outer).norm() / (n * scale)});
      }
      EXPECT_LT(worst, 1e-9);
      RecordProperty("moments_vs_reduction", testing::scientific(worst));
    }
    // Twice on the same buffers: the same again (device state reused, nothing left over).
    EXPECT_EQ(grower.grow(codes, device_points, params), expected_count);
    EXPECT_EQ(mismatches(grower.download_labels(), expected), 0u);
  }
};

TEST_P(RegionGrowerTest, SameAsTheReferenceOnRandomImages) {
  std::mt19937_64 local_rng(11);
  for (const int tile : {16, 8, 64, 5, 0, 100}) {  // 0 and 100: grown on the host
    const RandomFrame frame = random_frame(local_rng, 203, 117);
    expect_same_as_reference(frame.codes, frame.points, {15.0f, 0.02f, tile}, "random");
  }
}

TEST_P(RegionGrowerTest, SameAsTheReferenceOnSyntheticAndRealFrames) {
  const compute::Context cpu = compute::Context::cpu();
  const PinholeIntrinsics camera = testing::qvga_kinect();
  const synth::World& world = testing::test_world();
  const synth::SyntheticFrame frame = synth::render(
      world, camera, synth::robot_tour(world, 60)[30].pose, synth::NoiseModel::kinect(), 7);
  expect_same_as_reference(
      segmentation::to_lab_codes(frame.color),
      geometry::backproject(cpu, frame.depth, camera, {testing::kSynthUnitsPerMetre}),
      {15.0f, 0.02f, 16}, "synthetic frame");
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  expect_same_as_reference(
      segmentation::to_lab_codes(testing::read_color(frames / "frame-000100.color.jpg")),
      geometry::backproject(cpu, testing::read_depth(frames / "frame-000100.depth.png"),
                            PinholeIntrinsics::kinect_7scenes()),
      {15.0f, 0.02f, 16}, "7-Scenes frame 100");
}

TEST_P(RegionGrowerTest, WorstCaseStacksAndTinyImages) {
  // One colour, one depth: every pixel pushes all its neighbours, the deepest stacks possible.
  for (const auto& [width, height] :
       {std::pair{64, 64}, std::pair{1, 1}, std::pair{1, 9}, std::pair{9, 1}, std::pair{70, 3}}) {
    const LabCodeImage codes(width, height, LabCode{50 * 64, 0, 0, 1});
    expect_same_as_reference(codes, flat_points(width, height), {15.0f, 0.0f, 64},
                             std::to_string(width) + "x" + std::to_string(height));
  }
}

TEST_P(RegionGrowerTest, RejectsMismatchedInput) {
  segmentation::RegionGrower grower(context());
  const auto points = compute::Buffer<Point4f>::from_host(context(), flat_points(4, 3).pixels());
  EXPECT_ERROR_MENTIONS(grower.grow(LabCodeImage(3, 3), points, {}), "region growing", "3x3", "12");
  RegionGrowingParams bad;
  bad.lab_threshold = -1;
  EXPECT_ERROR_MENTIONS(grower.grow(LabCodeImage(4, 3), points, bad), "lab_threshold");
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(RegionGrowerTest);

}  // namespace
}  // namespace kartograf
