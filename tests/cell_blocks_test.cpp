// The cells mode's pass over a frame (kernels/cell_blocks, through detail::measure_cells) on every
// backend against a reference written here in double.
// Stated tolerance: valid counts, colour sums, jump counts, continuity and validity bits exact
// (the jump rule is a comparison of products, the same in float everywhere); per block, moments
// about the origin within 1e-5 (sum |d| + |shift| count) for the sum and 1e-5 (sum |d|^2 + 2
// |shift| sum |d|) for the sum of outer products (d: a point's offset from the block's first
// point, shift: that point's from the origin; the kernel sums d in float).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "compute/cpu/wide_lanes.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "real_data.hpp"
#include "segmentation/cell_planes.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using testing::BackendTest;

constexpr int kCellSize = 16;  // the default; the random frames try others
constexpr float kMaxDepthJump = 0.02f, kJumpPerZ2 = 0.008f;

struct ReferenceBlock {
  std::uint32_t count = 0, inside = 0, edge = 0;
  Eigen::Vector3d colour = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // about the origin
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  double norm = 0, norm_sq = 0, shift = 0;  // sum |d|, sum |d|^2, |reference - origin|
};

bool jumps(float a, float b) {
  const float z = std::min(a, b);
  return std::fabs(a - b) > z * std::max(kMaxDepthJump, kJumpPerZ2 * z);
}

// Jumps of the block [x0, x1) x [y0, y1) whose cell starts at (cx, cy): within it, and with the
// pixels left of and above it in the same cell.
void count_jumps(const PointImage& points, int x0, int y0, int x1, int y1, int cx, int cy,
                 ReferenceBlock& block) {
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const float z = points(x, y).z();
      if (x > cx) (x > x0 ? block.inside : block.edge) += jumps(z, points(x - 1, y).z());
      if (y > cy) (y > y0 ? block.inside : block.edge) += jumps(z, points(x, y - 1).z());
    }
  }
}

ReferenceBlock reference_block(const PointImage& points, const RgbImage& rgb, int bx, int by,
                               const Eigen::Vector3d& origin, int cell_size) {
  const int half = cell_size / 2;
  const int x0 = std::min(points.width(), bx * half), y0 = std::min(points.height(), by * half);
  const int x1 = std::min(points.width(), x0 + half), y1 = std::min(points.height(), y0 + half);
  ReferenceBlock block;
  count_jumps(points, x0, y0, x1, y1, bx / 2 * cell_size, by / 2 * cell_size, block);
  bool first = true;
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      if (!is_valid(points(x, y))) continue;
      const Eigen::Vector3d p = points(x, y).head<3>().cast<double>();
      if (first) reference = p, first = false;
      ++block.count;
      block.colour += Eigen::Vector3d(rgb(x, y)[0], rgb(x, y)[1], rgb(x, y)[2]);
      block.sum += p - origin;
      block.outer += (p - origin) * (p - origin).transpose();
      block.norm += (p - reference).norm();
      block.norm_sq += (p - reference).squaredNorm();
    }
  }
  block.shift = (reference - origin).norm();
  return block;
}

// Compares every block of `cells` with the reference; returns the worst relative moment error.
double check_blocks(const PointImage& points, const RgbImage& rgb, const Eigen::Vector3d& origin,
                    const segmentation::detail::CellGrid& cells, const std::string& what) {
  const int half = cells.cell_size / 2;
  double worst = 0;
  std::size_t mismatches = 0;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    std::uint32_t cell_jumps = 0;
    for (int b = 0; b < 4; ++b) {
      const int bx = 2 * static_cast<int>(c % cells.columns) + b % 2;
      const int by = 2 * static_cast<int>(c / cells.columns) + b / 2;
      const ReferenceBlock e = reference_block(points, rgb, bx, by, origin, cells.cell_size);
      cell_jumps += e.inside + e.edge;
      const std::size_t k = 4 * c + static_cast<std::size_t>(b);
      const geometry::SegmentMoments& m = cells.block_moments[k];
      mismatches += m.count != e.count || cells.block_colours[k] != e.colour ||
                    cells.block_continuous[k] != (2 * e.inside <= std::uint32_t(half));
      if (e.count == 0) continue;
      const double sum_bound = 1e-5 * (e.norm + e.shift * e.count) + 1e-12;
      const double outer_bound = 1e-5 * (e.norm_sq + 2 * e.shift * e.norm) + 1e-12;
      worst = std::max({worst, (m.sum - e.sum).norm() / sum_bound,
                        (m.sum_outer - e.outer).norm() / outer_bound});
    }
    mismatches += cells.continuous[c] != (2 * cell_jumps <= std::uint32_t(cells.cell_size));
  }
  for (int y = 0; y < points.height(); ++y) {
    for (int bx = 0; bx < cells.blocks_x; ++bx) {
      const std::uint32_t bits = cells.valid_bits(bx, y);
      for (int k = 0; k < half; ++k) {
        const int x = bx * half + k;
        const bool expected = x < points.width() && is_valid(points(x, y));
        mismatches += ((bits >> k) & 1u) != static_cast<std::uint32_t>(expected);
      }
    }
  }
  EXPECT_EQ(mismatches, 0u) << what;
  EXPECT_LE(worst, 1.0) << what << ": moment error over its bound";
  return worst;
}

segmentation::detail::CellGrid measure(const compute::Context& context, const PointImage& points,
                                       const RgbImage& rgb, const Eigen::Vector3d& origin,
                                       int cell_size = kCellSize) {
  const auto device_points = compute::Buffer<Point4f>::from_host(context, points.pixels());
  segmentation::CellBuffers buffers;
  segmentation::detail::CellGrid cells;
  segmentation::detail::measure_cells(context, device_points, rgb, cell_size, kMaxDepthJump,
                                      kJumpPerZ2, origin, buffers, cells);
  return cells;
}

void expect_same_cells(const segmentation::detail::CellGrid& a,
                       const segmentation::detail::CellGrid& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.continuous, b.continuous);
  EXPECT_EQ(a.block_continuous, b.block_continuous);
  EXPECT_EQ(a.block_colours, b.block_colours);
  EXPECT_EQ(a.block_masks, b.block_masks);
  for (std::size_t k = 0; k < a.block_moments.size(); ++k) {
    ASSERT_EQ(a.block_moments[k].count, b.block_moments[k].count) << k;
  }
}

struct Frame {
  PointImage points;
  RgbImage rgb;
};

// A slanted surface with steps of 0.4 m along diagonal bands (jumps that cross some cells and
// blocks and miss others), noise, a tenth of the pixels without depth, any colour.
Frame random_frame(int width, int height, std::mt19937_64& rng) {
  Frame frame{PointImage(width, height, invalid_point()), RgbImage(width, height)};
  std::uniform_real_distribution<float> noise(-0.004f, 0.004f);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      frame.rgb(x, y) = {std::uint8_t(byte(rng)), std::uint8_t(byte(rng)), std::uint8_t(byte(rng))};
      if (byte(rng) < 26) continue;
      const float step = (x / 37 + y / 29) % 3 == 0 ? 0.4f : 0.0f;
      const float d = 1.0f + 0.002f * x + 0.003f * y + step + noise(rng);
      frame.points(x, y) = Point4f((x - width / 2) * d / 200, (y - height / 2) * d / 200, d, 1);
    }
  }
  return frame;
}

class CellBlocksTest : public BackendTest {};

// Random frames of a size that cuts the last cells.
TEST_P(CellBlocksTest, MatchesReferenceOnRandomFrames) {
  for (const auto& [width, height] : {std::pair{250, 187}, std::pair{64, 48}}) {
    const Frame frame = random_frame(width, height, rng);
    const Eigen::Vector3d origin(0.1, -0.2, 2.5);
    // 12: a block's rows of validity bits straddle 32-bit words; 4 and 64: the smallest and
    // largest cells.
    for (const int cell_size : {kCellSize, 4, 12, 64}) {
      const std::string what = std::to_string(width) + "x" + std::to_string(height) + ", " +
                               std::to_string(cell_size) + " px cells";
      const segmentation::detail::CellGrid cells =
          measure(context(), frame.points, frame.rgb, origin, cell_size);
      const double worst = check_blocks(frame.points, frame.rgb, origin, cells, what);
      RecordProperty("worst_over_bound_" + what, testing::scientific(worst));
      expect_same_cells(
          cells, measure(compute::Context::cpu(), frame.points, frame.rgb, origin, cell_size));
    }
  }
}

// The CPU's two forms of the pass, AVX2's eight lanes (blocks eight pixels wide, where the
// processor has it) and the four-lane code, each against the reference and each other.
TEST(CellBlocksCpuCode, WideAndFourLaneCodeAgree) {
  std::mt19937_64 rng(7);
  const compute::Context cpu = compute::Context::cpu();
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const std::vector<std::pair<std::string, Frame>> inputs = {
      {"random 250x187", random_frame(250, 187, rng)},
      {"7-Scenes frame 10",
       {geometry::backproject(cpu, testing::read_depth(frames / "frame-000010.depth.png"),
                              PinholeIntrinsics::kinect_7scenes()),
        testing::read_color(frames / "frame-000010.color.jpg")}}};
  RecordProperty("wide_code", compute::detail::wide_lanes_enabled() ? "AVX2" : "not available");
  const Eigen::Vector3d origin(0.0, 0.0, 2.0);
  for (const auto& [what, frame] : inputs) {
    compute::detail::allow_wide_lanes(false);
    const segmentation::detail::CellGrid four = measure(cpu, frame.points, frame.rgb, origin);
    compute::detail::allow_wide_lanes(true);
    const segmentation::detail::CellGrid wide = measure(cpu, frame.points, frame.rgb, origin);
    check_blocks(frame.points, frame.rgb, origin, four, what + ", four lanes");
    check_blocks(frame.points, frame.rgb, origin, wide, what + ", wide");
    expect_same_cells(four, wide);
  }
}

TEST_P(CellBlocksTest, MatchesReferenceAndTheCpuOnSevenScenes) {
  const compute::Context cpu = compute::Context::cpu();
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_7scenes();
  const PointImage points =
      geometry::backproject(cpu, testing::read_depth(frames / "frame-000100.depth.png"), k);
  const RgbImage rgb = testing::read_color(frames / "frame-000100.color.jpg");
  const Eigen::Vector3d origin(0.0, 0.0, 2.0);
  const segmentation::detail::CellGrid cells = measure(context(), points, rgb, origin);
  const double worst = check_blocks(points, rgb, origin, cells, "7-Scenes frame 100");
  RecordProperty("worst_over_bound_7scenes", testing::scientific(worst));
  expect_same_cells(cells, measure(cpu, points, rgb, origin));
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(CellBlocksTest);

}  // namespace
}  // namespace kartograf
