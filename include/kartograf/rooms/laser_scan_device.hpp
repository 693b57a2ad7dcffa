#pragma once
// Simulated laser scans of many cells at once on a compute backend (issue 6: the ray casting of
// the feature-based room segmentation on the device). The scan is LaserScanner's
// (laser_features.hpp): integer sphere tracing over its skip image with fixed-point beam
// directions, so every backend returns exactly LaserScanner::scan_steps, bit for bit.
//
// Work split: one work-item per (cell, beam) on a GPU; on the CPU-hosted drivers (lavapipe, PoCL)
// one work-item per cell with a loop over its beams, which measured as fast or faster there
// (bench/laser_scan_bench.cpp; office_e, 80k cells: lavapipe 1.56 s vs 1.64 s, PoCL 1.3-2.2 s vs
// 2.3 s), and on the CPU backend (its kernel, kernels/laser_scan/, runs chunks of cells on
// KARTOGRAF_CPU_THREADS threads, src/compute/cpu_parallel.hpp).
#include <cstdint>
#include <span>
#include <vector>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/rooms/laser_features.hpp"

namespace kartograf::rooms {

// A map cell to scan from (col: image column, row: image row).
struct ScanCell {
  std::int32_t col = 0;
  std::int32_t row = 0;
};

class DeviceLaserScanner {
 public:
  // Uploads the scanner's skip image and beam directions once. The scanner may be destroyed
  // afterwards; `context` must outlive this object.
  DeviceLaserScanner(const compute::Context& context, const LaserScanner& scanner);

  int beams() const { return beams_; }
  double resolution() const { return resolution_; }

  // Step counts of a scan from every cell: steps[i * beams() + k] is beam k from cells[i] (whole
  // cells, at most the scanner's max_steps(); all zeros for a cell that is not free). `steps` is
  // reallocated when its size differs from cells.size() * beams(). Ordered like every dispatch:
  // nothing waits until the host reads `steps`. Throws Error for a cell outside the map, or more
  // than 2^32 - 1 beams in all. (lavapipe binds at most 128 MiB: ~93,000 cells of 360 beams.)
  void scan_steps(std::span<const ScanCell> cells, compute::Buffer<std::int32_t>& steps);

  // Convenience on the host, in batches of at most `batch_cells` cells per dispatch:
  // step counts, and ranges [m] (steps * resolution(), as LaserScanner::scan gives them), both
  // row-major cells x beams.
  std::vector<std::int32_t> scan_steps(std::span<const ScanCell> cells,
                                       std::size_t batch_cells = 16384);
  std::vector<double> scan_ranges(std::span<const ScanCell> cells, std::size_t batch_cells = 16384);

  // For measurements: beams per work-item on the device backends (1: one per (cell, beam);
  // beams(): one per cell). Throws Error outside [1, beams()].
  void set_beams_per_work_item(int beams_per_item);
  int beams_per_work_item() const { return beams_per_item_; }

 private:
  const compute::Context* context_;
  int beams_ = 0;
  int map_width_ = 0, map_height_ = 0;
  int max_steps_ = 0;
  double resolution_ = 0;
  int beams_per_item_ = 1;
  compute::Buffer<std::int32_t> skips_;        // padded grid, (map_width_ + 2) x (map_height_ + 2)
  compute::Buffer<std::int32_t> directions_;   // (dx, dy) per beam
  compute::Buffer<ScanCell> cells_;            // the last call's cells (grows, reused)
  compute::Buffer<std::int32_t> batch_steps_;  // the host convenience's batch output
};

}  // namespace kartograf::rooms
