// Simulated laser scans on every backend (rooms/laser_scan_device.hpp) against a straightforward
// reference written here: each beam walked one cell at a time, its sample positions computed in
// double from the fixed-point directions (cos and sin of the beam angle rounded to 1/65536 cell;
// every position is then exact in double), no skip image, no sphere tracing.
// Stated tolerance: none. Every step count equals the reference's (0 mismatches), on random maps
// with every work split and on the real ipa map office_e.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "carved_map.hpp"
#include "kartograf/rooms/laser_features.hpp"
#include "kartograf/rooms/laser_scan_device.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using rooms::ScanCell;
using testing::BackendTest;

// The scan's definition, one cell at a time: the first step whose sample is in a cell that is not
// free or outside the map, at most ceil(max_range_m / resolution).
std::vector<std::int32_t> reference_steps(const OccupancyGrid& map, std::span<const ScanCell> cells,
                                          int beams, double max_range_m) {
  const auto max_steps = static_cast<std::int64_t>(std::ceil(max_range_m / map.resolution));
  std::vector<double> dx(static_cast<std::size_t>(beams)), dy(dx.size());
  for (int k = 0; k < beams; ++k) {
    const double angle = 2 * std::numbers::pi * k / beams;
    dx[static_cast<std::size_t>(k)] = std::round(std::cos(angle) * 65536) / 65536;
    dy[static_cast<std::size_t>(k)] = std::round(-std::sin(angle) * 65536) / 65536;
  }
  const auto free_at = [&](double x, double y) {
    const double cx = std::floor(x), cy = std::floor(y);
    return cx >= 0 && cy >= 0 && cx < map.width() && cy < map.height() &&
           map.cells(static_cast<int>(cx), static_cast<int>(cy)) == CellState::free;
  };
  std::vector<std::int32_t> steps;
  steps.reserve(cells.size() * dx.size());
  for (const ScanCell& cell : cells) {
    for (std::size_t k = 0; k < dx.size(); ++k) {
      std::int64_t step = 0;
      while (step < max_steps && free_at(cell.col + 0.5 + static_cast<double>(step) * dx[k],
                                         cell.row + 0.5 + static_cast<double>(step) * dy[k]))
        ++step;
      steps.push_back(static_cast<std::int32_t>(step));
    }
  }
  return steps;
}

std::size_t mismatches(const std::vector<std::int32_t>& expected,
                       const std::vector<std::int32_t>& actual) {
  EXPECT_EQ(expected.size(), actual.size());
  std::size_t count = 0;
  for (std::size_t i = 0; i < std::min(expected.size(), actual.size()); ++i)
    count += expected[i] != actual[i];
  return count;
}

// A map with free rectangles and random clutter (single occupied and unknown cells).
OccupancyGrid random_map(std::mt19937_64& rng, int width, int height, double clutter) {
  OccupancyGrid map = testing::carve_map(width, height, {{1, 1, width - 1, height - 1}});
  std::uniform_int_distribution<int> col(0, width - 1), row(0, height - 1);
  std::uniform_int_distribution<int> length(2, std::max(3, width / 3));
  // A few walls, some with gaps.
  for (int i = 0; i < 4; ++i) {
    const int x = col(rng), y = row(rng), n = length(rng);
    for (int j = 0; j < n; ++j) {
      if (j % 7 == 3) continue;
      if (i % 2 == 0 && x + j < width) map.cells(x + j, y) = CellState::occupied;
      if (i % 2 == 1 && y + j < height) map.cells(x, y + j) = CellState::occupied;
    }
  }
  const int clutter_cells = static_cast<int>(clutter * width * height);
  for (int i = 0; i < clutter_cells; ++i)
    map.cells(col(rng), row(rng)) = i % 3 == 0 ? CellState::unknown : CellState::occupied;
  return map;
}

std::vector<ScanCell> every_cell(const OccupancyGrid& map, int stride) {
  std::vector<ScanCell> cells;
  for (int row = 0; row < map.height(); row += stride) {
    for (int col = 0; col < map.width(); col += stride) cells.push_back({col, row});
  }
  return cells;
}

std::vector<ScanCell> free_cells(const OccupancyGrid& map, int every) {
  std::vector<ScanCell> cells;
  int n = 0;
  for (int row = 0; row < map.height(); ++row) {
    for (int col = 0; col < map.width(); ++col) {
      if (map.cells(col, row) == CellState::free && n++ % every == 0) cells.push_back({col, row});
    }
  }
  return cells;
}

class LaserScanDeviceTest : public BackendTest {};

// Random maps, beam counts and ranges (some short enough that beams stop at max range), every
// cell of the map (non-free ones give zeros), each work split of the device kernel: every step
// count as the reference's, as LaserScanner::scan_steps, and ranges = steps * resolution.
TEST_P(LaserScanDeviceTest, RandomMapsMatchTheStepByStepReference) {
  struct Case {
    int width, height;
    double clutter;
    int beams;
    double max_range_m;
  };
  const Case cases[] = {{40, 30, 0.02, 8, 50.0},
                        {97, 61, 0.01, 360, 50.0},
                        {150, 120, 0.003, 361, 50.0},
                        {120, 90, 0.005, 72, 1.3},
                        {64, 200, 0.0, 90, 4.0}};
  std::size_t compared = 0, at_max_range = 0, zeros = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(c.width) + "x" + std::to_string(c.height) + ", " +
                 std::to_string(c.beams) + " beams");
    const OccupancyGrid map = random_map(rng, c.width, c.height, c.clutter);
    const rooms::LaserScanner scanner(map, {c.beams, c.max_range_m});
    const std::vector<ScanCell> cells = every_cell(map, 1);
    const std::vector<std::int32_t> expected = reference_steps(map, cells, c.beams, c.max_range_m);

    // The host scanner (the CPU definition) first.
    std::vector<std::int32_t> host(expected.size());
    std::vector<double> ranges(static_cast<std::size_t>(c.beams));
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const auto row = std::span(host).subspan(i * ranges.size(), ranges.size());
      scanner.scan_steps(cells[i].col, cells[i].row, row);
      scanner.scan(cells[i].col, cells[i].row, ranges);
      for (std::size_t k = 0; k < ranges.size(); ++k) ASSERT_EQ(ranges[k], row[k] * map.resolution);
    }
    EXPECT_EQ(mismatches(expected, host), 0u);

    rooms::DeviceLaserScanner device(context(), scanner);
    for (const int per_item : {1, 7, c.beams}) {
      SCOPED_TRACE("beams per work-item " + std::to_string(per_item));
      device.set_beams_per_work_item(per_item);
      EXPECT_EQ(mismatches(expected, device.scan_steps(cells, 1000)), 0u);
    }
    const std::vector<double> device_ranges = device.scan_ranges(cells);
    for (std::size_t i = 0; i < expected.size(); ++i)
      ASSERT_EQ(device_ranges[i], expected[i] * map.resolution) << "entry " << i;
    compared += expected.size();
    const auto max_steps = static_cast<std::int32_t>(std::ceil(c.max_range_m / map.resolution));
    at_max_range +=
        static_cast<std::size_t>(std::count(expected.begin(), expected.end(), max_steps));
    zeros += static_cast<std::size_t>(std::count(expected.begin(), expected.end(), 0));
  }
  RecordProperty("beams_compared", std::to_string(compared));
  EXPECT_GT(at_max_range, 1000u);  // the short-range cases reach it
  EXPECT_GT(zeros, 1000u);         // wall and clutter cells
}

// More than 65535 work-groups of items (one per beam): the grid folds into two dimensions; and the
// device Buffer API, two calls in a row before one read, reusing the cell buffer.
TEST_P(LaserScanDeviceTest, LargeGridsAndChainedCalls) {
  const OccupancyGrid map = random_map(rng, 130, 110, 0.01);
  const rooms::LaserScanner scanner(map);
  std::vector<ScanCell> cells = every_cell(map, 1);  // 14,300 cells x 360 beams > 65535 x 64
  const std::vector<std::int32_t> expected = reference_steps(map, cells, 360, 50.0);
  rooms::DeviceLaserScanner device(context(), scanner);
  device.set_beams_per_work_item(1);
  compute::Buffer<std::int32_t> first, second;
  device.scan_steps(cells, first);
  const std::vector<ScanCell> tail(cells.end() - 100, cells.end());
  device.scan_steps(tail, second);
  EXPECT_EQ(mismatches(expected, first.to_vector()), 0u);
  const std::vector<std::int32_t> expected_tail(expected.end() - 100 * 360, expected.end());
  EXPECT_EQ(mismatches(expected_tail, second.to_vector()), 0u);
  // An empty call gives an empty buffer.
  device.scan_steps({}, second);
  EXPECT_EQ(second.size(), 0u);
}

// office_e (plain): every 7th free cell, 360 beams, 50 m: identical to the reference, and on the
// device backends to the CPU backend's buffer.
TEST_P(LaserScanDeviceTest, RealIpaMapMatchesTheReference) {
  const OccupancyGrid map = testing::read_occupancy_map(
      testing::data_dir() / "ipa_room_maps" / "test_maps" / "office_e.png", 0.05);
  const rooms::LaserScanner scanner(map);
  const std::vector<ScanCell> cells = free_cells(map, 7);
  ASSERT_GT(cells.size(), 2000u);
  // The same for every backend: computed once.
  static const std::vector<std::int32_t> expected = reference_steps(map, cells, 360, 50.0);
  rooms::DeviceLaserScanner device(context(), scanner);
  const std::vector<std::int32_t> actual = device.scan_steps(cells);
  const std::size_t wrong = mismatches(expected, actual);
  RecordProperty("beams_compared", std::to_string(expected.size()));
  RecordProperty("mismatches", std::to_string(wrong));
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(*std::max_element(actual.begin(), actual.end()), 200);  // long corridors
}

TEST_P(LaserScanDeviceTest, RejectsBadInput) {
  const OccupancyGrid map = testing::carve_map(30, 20, {{1, 1, 29, 19}});
  EXPECT_ERROR_MENTIONS(rooms::LaserScanner(map, {7, 50.0}), "beams", "7");
  EXPECT_ERROR_MENTIONS(rooms::LaserScanner(map, {360, 0.0}), "max_range_m");
  EXPECT_ERROR_MENTIONS(rooms::LaserScanner(OccupancyGrid{}), "no cells");
  EXPECT_ERROR_MENTIONS(rooms::LaserScanner(testing::carve_map(32766, 1, {})), "32766 x 1",
                        "32765");
  const rooms::LaserScanner scanner(map, {16, 5.0});
  rooms::DeviceLaserScanner device(context(), scanner);
  compute::Buffer<std::int32_t> steps;
  const std::vector<ScanCell> outside[] = {
      {ScanCell{3, 3}, ScanCell{30, 5}}, {ScanCell{-1, 0}}, {ScanCell{0, 20}}, {ScanCell{2, -4}}};
  for (const auto& cells : outside) {
    EXPECT_ERROR_MENTIONS(device.scan_steps(cells, steps), "outside", "30 x 20");
    EXPECT_ERROR_MENTIONS(device.scan_ranges(cells), "outside");
  }
  EXPECT_ERROR_MENTIONS(device.scan_steps(outside[0], steps), "cell 1", "col 30");
  EXPECT_ERROR_MENTIONS(device.set_beams_per_work_item(0), "beams per work-item", "16");
  EXPECT_ERROR_MENTIONS(device.set_beams_per_work_item(17), "beams per work-item");
  const std::vector<ScanCell> inside{{3, 3}};
  EXPECT_ERROR_MENTIONS(device.scan_steps(inside, 0), "batch_cells");
  std::vector<std::int32_t> wrong_size(15);
  EXPECT_ERROR_MENTIONS(scanner.scan_steps(3, 3, wrong_size), "16 beams", "15");
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(LaserScanDeviceTest);

}  // namespace
}  // namespace kartograf
