// Parallel Lab region growing (connected components of the Lab/depth edge graph) on every backend:
// hand-built images with known components, an independent breadth-first reference on random
// images (Lab values on a 1/64 grid, so the double test of the reference and the quantised test of
// the operation decide every edge alike), and labels identical to the CPU backend on random, real
// (7-Scenes) and synthetic frames.
#include <cmath>
#include <cstdio>
#include <deque>
#include <limits>
#include <map>
#include <string>

#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/segment_moments.hpp"
#include "kartograf/io/image_io.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/segmentation/parallel_region_growing.hpp"
#include "kartograf/segmentation/region_growing.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using geometry::kNoLabel;
using segmentation::LabImage;
using segmentation::ParallelRegionGrowing;
using segmentation::RegionGrowingParams;
using segmentation::SegmentLabelImage;
using testing::BackendTest;

RegionGrowingParams lab_params(float threshold, float depth_jump = 0.0f) {
  RegionGrowingParams params;
  params.lab_threshold = threshold;
  params.max_depth_jump = depth_jump;
  return params;
}

PointImage flat_points(int width, int height, float z = 1.0f) {
  return PointImage(width, height, Point4f(0.0f, 0.0f, z, 1.0f));
}

Eigen::Vector4f lab(float l, float a = 0.0f, float b = 0.0f) {
  return {l, a, b, 0.0f};
}

// Through the device-buffer overload (what a pipeline calls), downloaded.
SegmentLabelImage run(const compute::Context& context, const LabImage& lab_image,
                      const PointImage& points, const RegionGrowingParams& params) {
  ParallelRegionGrowing growing(context, lab_image.width(), lab_image.height());
  const auto device_lab = compute::Buffer<Eigen::Vector4f>::from_host(context, lab_image.pixels());
  const auto device_points = compute::Buffer<Point4f>::from_host(context, points.pixels());
  const std::uint32_t count = growing.segment(device_lab, device_points, params);
  SegmentLabelImage labels = growing.download_labels();
  EXPECT_EQ(count, segmentation::segment_count(labels));
  return labels;
}

// Breadth-first flood fill over the same edge rule, in double, numbering in scan order.
SegmentLabelImage reference_components(const LabImage& lab_image, const PointImage& points,
                                       const RegionGrowingParams& params) {
  const int width = lab_image.width(), height = lab_image.height();
  SegmentLabelImage labels(width, height, kNoLabel);
  const auto valid = [&](int x, int y) {
    return is_valid(points(x, y)) && lab_image(x, y).head<3>().allFinite();
  };
  const auto connected = [&](int xa, int ya, int xb, int yb) {
    const Eigen::Vector3d d =
        (lab_image(xa, ya).head<3>().cast<double>() - lab_image(xb, yb).head<3>().cast<double>());
    const double threshold = params.lab_threshold;
    if (d.squaredNorm() >= threshold * threshold) return false;
    const double za = points(xa, ya).z(), zb = points(xb, yb).z();
    return params.max_depth_jump == 0.0f ||
           std::fabs(za - zb) <= static_cast<double>(params.max_depth_jump) * std::min(za, zb);
  };
  std::uint32_t next = 0;
  std::deque<std::pair<int, int>> queue;
  for (int y0 = 0; y0 < height; ++y0) {
    for (int x0 = 0; x0 < width; ++x0) {
      if (labels(x0, y0) != kNoLabel || !valid(x0, y0)) continue;
      labels(x0, y0) = next;
      queue.emplace_back(x0, y0);
      while (!queue.empty()) {
        const auto [x, y] = queue.front();
        queue.pop_front();
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            if (labels(nx, ny) != kNoLabel || !valid(nx, ny) || !connected(x, y, nx, ny)) continue;
            labels(nx, ny) = next;
            queue.emplace_back(nx, ny);
          }
        }
      }
      ++next;
    }
  }
  return labels;
}

std::size_t mismatches(const SegmentLabelImage& a, const SegmentLabelImage& b) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < a.size(); ++i) count += a.pixels()[i] != b.pixels()[i];
  return count;
}

// Random blocky Lab (blocks of random size with small jitter, values on a 1/64 grid) over a
// random depth field with holes: components of all sizes, many seams between CPU chunks and
// device blocks.
void random_frame(std::mt19937_64& rng, int width, int height, LabImage& lab_image,
                  PointImage& points) {
  lab_image = LabImage(width, height);
  points = PointImage(width, height);
  std::uniform_int_distribution<int> block_colour(0, 100 * 64);
  std::uniform_int_distribution<int> jitter(-4 * 64, 4 * 64);
  std::uniform_int_distribution<int> percent(0, 99);
  std::uniform_real_distribution<float> depth(0.8f, 1.2f);
  std::vector<Eigen::Vector3f> block_colours(64 * 64);
  for (auto& c : block_colours) {
    c = Eigen::Vector3f(block_colour(rng), block_colour(rng) - 50 * 64,
                        block_colour(rng) - 50 * 64) /
        64.0f;
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector3f base = block_colours[((y / 9) % 64) * 64 + (x / 13) % 64];
      lab_image(x, y) = lab(base.x() + jitter(rng) / 64.0f, base.y() + jitter(rng) / 64.0f,
                            base.z() + jitter(rng) / 64.0f);
      points(x, y) = percent(rng) < 3 ? invalid_point()
                                      : Point4f(0.0f, 0.0f, (x / 40) % 2 ? depth(rng) : 1.0f, 1.0f);
    }
  }
}

class ParallelRegionGrowingTest : public BackendTest {};

TEST_P(ParallelRegionGrowingTest, TwoColourBlocks) {
  LabImage image(9, 6, lab(40.0f, 10.0f, 10.0f));
  for (int y = 0; y < 6; ++y)
    for (int x = 5; x < 9; ++x) image(x, y) = lab(70.0f, -20.0f, 5.0f);
  const SegmentLabelImage labels = run(context(), image, flat_points(9, 6), lab_params(15.0f));
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 9; ++x) EXPECT_EQ(labels(x, y), x < 5 ? 0u : 1u) << x << "," << y;
  // Above the blocks' distance (~42.4) they are one segment.
  EXPECT_EQ(
      segmentation::segment_count(run(context(), image, flat_points(9, 6), lab_params(43.0f))), 1u);
}

TEST_P(ParallelRegionGrowingTest, DiagonalNeighboursConnect) {
  // Every pixel far (>= 20) from its neighbours, except two diagonal pairs: (0,0)-(1,1) along the
  // main diagonal and (3,1)-(2,2) along the other.
  LabImage image(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) image(x, y) = lab(20.0f * x + 5.0f, 20.0f * y - 40.0f);
  image(1, 1) = image(0, 0) = lab(30.0f, 0.0f, 100.0f);
  image(2, 2) = image(3, 1) = lab(30.0f, 0.0f, -100.0f);
  const SegmentLabelImage labels = run(context(), image, flat_points(4, 4), lab_params(15.0f));
  const std::uint32_t expected[16] = {0,  1,  2,  3,  //
                                      4,  0,  5,  6,  //
                                      7,  8,  6,  9,  //
                                      10, 11, 12, 13};
  for (int i = 0; i < 16; ++i) EXPECT_EQ(labels.pixels()[i], expected[i]) << "pixel " << i;
}

TEST_P(ParallelRegionGrowingTest, InvalidPixelsSplitARegion) {
  const int width = 10, height = 5;
  const LabImage image(width, height, lab(50.0f));
  PointImage points = flat_points(width, height);
  for (int y = 0; y < height; ++y) points(4, y) = invalid_point();  // a wall of holes
  SegmentLabelImage labels = run(context(), image, points, lab_params(15.0f));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      EXPECT_EQ(labels(x, y), x == 4 ? kNoLabel : (x < 4 ? 0u : 1u)) << x << "," << y;
    }
  }
  // One gap in the wall reconnects through diagonal neighbours; a NaN Lab pixel is invalid too.
  points(4, 2) = Point4f(0.0f, 0.0f, 1.0f, 1.0f);
  LabImage with_nan = image;
  with_nan(0, 0) = lab(std::numeric_limits<float>::quiet_NaN());
  labels = run(context(), with_nan, points, lab_params(15.0f));
  EXPECT_EQ(labels(0, 0), kNoLabel);
  EXPECT_EQ(labels(1, 0), 0u);
  EXPECT_EQ(labels(9, 4), 0u);
  EXPECT_EQ(segmentation::segment_count(labels), 1u);
}

TEST_P(ParallelRegionGrowingTest, GradientChainsIntoOneSegmentUnlikeTheRunningMean) {
  // L rises 2 per column (0..126): every step is under the threshold, so the edge graph is one
  // component; the paper's running mean drifts away from the far columns and splits the ramp.
  const int width = 64, height = 4;
  LabImage image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image(x, y) = lab(2.0f * x);
  const PointImage points = flat_points(width, height);
  const SegmentLabelImage parallel = run(context(), image, points, lab_params(15.0f));
  EXPECT_EQ(segmentation::segment_count(parallel), 1u);
  for (const std::uint32_t l : parallel.pixels()) EXPECT_EQ(l, 0u);
  EXPECT_GT(
      segmentation::segment_count(segmentation::grow_regions_lab(image, points, lab_params(15.0f))),
      1u);
}

TEST_P(ParallelRegionGrowingTest, LabThresholdIsStrict) {
  // Distance exactly 15 (a 9-12-15 triangle) does not connect at threshold 15; 14.99 does.
  LabImage image(2, 1);
  image(0, 0) = lab(10.0f, 0.0f, 0.0f);
  image(1, 0) = lab(19.0f, 12.0f, 0.0f);
  EXPECT_EQ(
      segmentation::segment_count(run(context(), image, flat_points(2, 1), lab_params(15.0f))), 2u);
  EXPECT_EQ(
      segmentation::segment_count(run(context(), image, flat_points(2, 1), lab_params(15.01f))),
      1u);
}

TEST_P(ParallelRegionGrowingTest, DepthJumpOption) {
  // Uniform colour; the right half 25 % farther.
  const int width = 8, height = 3;
  const LabImage image(width, height, lab(50.0f));
  PointImage points = flat_points(width, height, 1.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 4; x < width; ++x) points(x, y) = Point4f(0.0f, 0.0f, 1.25f, 1.0f);
  const auto count = [&](float jump) {
    return segmentation::segment_count(run(context(), image, points, lab_params(15.0f, jump)));
  };
  EXPECT_EQ(count(0.0f), 1u);   // off
  EXPECT_EQ(count(0.1f), 2u);   // 0.25 > 0.1 * 1.0
  EXPECT_EQ(count(0.25f), 1u);  // 0.25 <= 0.25 * min(1.0, 1.25): the limit is inclusive
  const SegmentLabelImage labels = run(context(), image, points, lab_params(15.0f, 0.2f));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) EXPECT_EQ(labels(x, y), x < 4 ? 0u : 1u);
}

TEST_P(ParallelRegionGrowingTest, MatchesBreadthFirstReferenceOnRandomImages) {
  for (const auto& [width, height] : {std::pair{97, 61}, std::pair{640, 480}}) {
    LabImage image;
    PointImage points;
    random_frame(rng, width, height, image, points);
    for (const RegionGrowingParams& params :
         {lab_params(3.0f), lab_params(10.0f, 0.1f), lab_params(30.0f)}) {
      const std::string what = std::to_string(width) + "x" + std::to_string(height) +
                               " threshold " + std::to_string(params.lab_threshold) + " jump " +
                               std::to_string(params.max_depth_jump);
      const SegmentLabelImage expected = reference_components(image, points, params);
      const SegmentLabelImage actual = run(context(), image, points, params);
      EXPECT_EQ(mismatches(actual, expected), 0u) << what;
      EXPECT_GT(segmentation::segment_count(expected), 1u) << what;  // a non-trivial case
    }
  }
}

TEST_P(ParallelRegionGrowingTest, TinyAndThinImages) {
  for (const auto& [width, height] :
       {std::pair{1, 1}, std::pair{1, 37}, std::pair{53, 1}, std::pair{2, 300}}) {
    LabImage image;
    PointImage points;
    random_frame(rng, width, height, image, points);
    const std::string what = std::to_string(width) + "x" + std::to_string(height);
    EXPECT_EQ(mismatches(run(context(), image, points, lab_params(6.0f)),
                         reference_components(image, points, lab_params(6.0f))),
              0u)
        << what;
  }
}

TEST_P(ParallelRegionGrowingTest, SteadyStateReuseAndRepeatability) {
  LabImage image_a, image_b;
  PointImage points_a, points_b;
  random_frame(rng, 160, 120, image_a, points_a);
  random_frame(rng, 160, 120, image_b, points_b);
  ParallelRegionGrowing growing(context(), 160, 120);
  growing.segment(image_a, points_a, lab_params(8.0f));
  const SegmentLabelImage first = growing.download_labels();
  growing.segment(image_b, points_b, lab_params(12.0f, 0.05f));
  EXPECT_EQ(mismatches(growing.download_labels(),
                       reference_components(image_b, points_b, lab_params(12.0f, 0.05f))),
            0u);
  growing.segment(image_a, points_a, lab_params(8.0f));
  EXPECT_EQ(mismatches(growing.download_labels(), first), 0u);
  EXPECT_EQ(growing.segment_count(), segmentation::segment_count(first));
}

// Real and synthetic frames: the backend's labels equal the CPU backend's, for several settings.
void expect_same_as_cpu(const compute::Context& context, const LabImage& image,
                        const PointImage& points, const std::string& what) {
  const compute::Context cpu = compute::Context::cpu();
  // Edge thresholds where real frames split into hundreds to thousands of segments (at the
  // paper's 10..30, neighbour chains percolate through whole frames).
  for (const RegionGrowingParams& params :
       {lab_params(2.0f), lab_params(4.0f), lab_params(4.0f, 0.05f)}) {
    const SegmentLabelImage expected =
        segmentation::grow_regions_lab_parallel(cpu, image, points, params);
    const SegmentLabelImage actual = run(context, image, points, params);
    EXPECT_EQ(mismatches(actual, expected), 0u) << what << " threshold " << params.lab_threshold;
    EXPECT_GT(segmentation::segment_count(expected), 10u) << what;
  }
}

TEST_P(ParallelRegionGrowingTest, SameAsCpuOnSevenScenesFrame) {
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const compute::Context cpu = compute::Context::cpu();
  const LabImage image =
      segmentation::to_lab(io::read_color_image(frames / "frame-000100.color.jpg"));
  const PointImage points =
      geometry::backproject(cpu, io::read_depth_png(frames / "frame-000100.depth.png"),
                            PinholeIntrinsics::kinect_7scenes());
  expect_same_as_cpu(context(), image, points, "7-Scenes frame 100");
}

TEST_P(ParallelRegionGrowingTest, SameAsCpuOnSyntheticFrame) {
  const PinholeIntrinsics camera = testing::qvga_kinect();
  const synth::World& world = testing::test_world();
  const synth::SyntheticFrame frame = synth::render(
      world, camera, synth::robot_tour(world, 60)[30].pose, synth::NoiseModel::kinect(), 7);
  const compute::Context cpu = compute::Context::cpu();
  const PointImage points =
      geometry::backproject(cpu, frame.depth, camera, {testing::kSynthUnitsPerMetre});
  expect_same_as_cpu(context(), segmentation::to_lab(frame.color), points, "synthetic frame");
}

TEST_P(ParallelRegionGrowingTest, LabelsFeedTheMomentReductionOnTheDevice) {
  // Two depth planes of one colour with the depth test on: two segments whose moments are
  // reduced straight from labels() (no host round trip of the labels).
  const int width = 32, height = 16;
  const LabImage image(width, height, lab(60.0f));
  PointImage points(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      points(x, y) = Point4f(0.01f * x, 0.01f * y, x < 20 ? 1.0f : 2.0f, 1.0f);
  points(3, 3) = invalid_point();
  ParallelRegionGrowing growing(context(), width, height);
  ASSERT_EQ(growing.segment(image, points, lab_params(15.0f, 0.1f)), 2u);
  const auto device_points = compute::Buffer<Point4f>::from_host(context(), points.pixels());
  geometry::SegmentMomentParams moment_params;
  moment_params.label_count = growing.segment_count();
  const auto moments =
      geometry::segment_moments(context(), device_points, growing.labels(), moment_params);
  EXPECT_EQ(moments.segments[0].count, 20u * height - 1);
  EXPECT_EQ(moments.segments[1].count, 12u * height);
  EXPECT_NEAR(moments.centroid(0).z(), 1.0, 1e-9);
  EXPECT_NEAR(moments.centroid(1).z(), 2.0, 1e-9);
}

TEST_P(ParallelRegionGrowingTest, RejectsBadInput) {
  EXPECT_ERROR_MENTIONS(ParallelRegionGrowing(context(), 0, 5), "size", "0x5");
  ParallelRegionGrowing growing(context(), 4, 3);
  const LabImage image(4, 3, lab(50.0f));
  const PointImage points = flat_points(4, 3);
  EXPECT_ERROR_MENTIONS(growing.segment(LabImage(3, 3), points, lab_params(15.0f)), "3x3", "4x3");
  EXPECT_ERROR_MENTIONS(growing.segment(image, points, lab_params(0.0f)), "lab_threshold");
  EXPECT_ERROR_MENTIONS(growing.segment(image, points, lab_params(std::nanf(""))), "lab_threshold");
  EXPECT_ERROR_MENTIONS(growing.segment(image, points, lab_params(15.0f, -0.1f)), "max_depth_jump");
  const auto short_buffer = compute::Buffer<Point4f>(context(), 11);
  const auto lab_buffer = compute::Buffer<Eigen::Vector4f>::from_host(context(), image.pixels());
  EXPECT_ERROR_MENTIONS(growing.segment(lab_buffer, short_buffer, lab_params(15.0f)), "11 points");
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(ParallelRegionGrowingTest);

// Of the pixels labelled in both images, the fraction whose `from` segment's best-overlapping
// `to` segment is the one they are in: 1 when every `from` segment lies inside a `to` segment.
double best_overlap_agreement(const SegmentLabelImage& from, const SegmentLabelImage& to) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::int64_t> cells;
  std::int64_t both = 0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    const std::uint32_t a = from.pixels()[i], b = to.pixels()[i];
    if (a == kNoLabel || b == kNoLabel) continue;
    ++cells[{a, b}];
    ++both;
  }
  std::map<std::uint32_t, std::int64_t> best;
  for (const auto& [key, pixels] : cells) best[key.first] = std::max(best[key.first], pixels);
  std::int64_t agreeing = 0;
  for (const auto& [label, pixels] : best) agreeing += pixels;
  return both == 0 ? 1.0 : static_cast<double>(agreeing) / static_cast<double>(both);
}

// How the parallel formulation differs from the paper's running mean on a real frame (figures
// for the docs): segment counts for Lab thresholds 10..30 and the pixel agreement both ways.
TEST(ParallelRegionGrowingVsSequential, SevenScenesFrame) {
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const compute::Context cpu = compute::Context::cpu();
  const LabImage image =
      segmentation::to_lab(io::read_color_image(frames / "frame-000100.color.jpg"));
  const PointImage points =
      geometry::backproject(cpu, io::read_depth_png(frames / "frame-000100.depth.png"),
                            PinholeIntrinsics::kinect_7scenes());
  std::uint32_t previous_parallel = std::numeric_limits<std::uint32_t>::max();
  for (const float threshold : {10.0f, 15.0f, 20.0f, 25.0f, 30.0f}) {
    const SegmentLabelImage sequential =
        segmentation::grow_regions_lab(image, points, lab_params(threshold));
    const SegmentLabelImage parallel =
        segmentation::grow_regions_lab_parallel(cpu, image, points, lab_params(threshold));
    const std::uint32_t sequential_count = segmentation::segment_count(sequential);
    const std::uint32_t parallel_count = segmentation::segment_count(parallel);
    const double sequential_in_parallel = best_overlap_agreement(sequential, parallel);
    const double parallel_in_sequential = best_overlap_agreement(parallel, sequential);
    std::string key = "t";  // (not "t" + ...: g++ 12 reports a false -Wrestrict there)
    key += std::to_string(static_cast<int>(threshold));
    RecordProperty(key + "_sequential_segments", static_cast<int>(sequential_count));
    RecordProperty(key + "_parallel_segments", static_cast<int>(parallel_count));
    RecordProperty(key + "_sequential_in_parallel", std::to_string(sequential_in_parallel));
    RecordProperty(key + "_parallel_in_sequential", std::to_string(parallel_in_sequential));
    std::printf(
        "threshold %4.1f: sequential %6u segments, parallel %6u; agreement seq->par %.4f, par->seq "
        "%.4f\n",
        threshold, sequential_count, parallel_count, sequential_in_parallel,
        parallel_in_sequential);
    // Chaining merges what the running mean splits: fewer segments, each sequential segment
    // mostly inside one parallel segment.
    EXPECT_LT(parallel_count, sequential_count) << key;
    EXPECT_GT(sequential_in_parallel, parallel_in_sequential) << key;
    EXPECT_LE(parallel_count, previous_parallel) << key;  // monotone in the threshold
    previous_parallel = parallel_count;
  }
}

}  // namespace
}  // namespace kartograf
