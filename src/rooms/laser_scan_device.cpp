#include "kartograf/rooms/laser_scan_device.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"
#include "kernels/laser_scan/laser_scan.h"

namespace kartograf::rooms {

namespace {

constexpr compute::KernelSpec kLaserScanKernel{"laser_scan", KG_LASER_SCAN_LOCAL_X, 1};
// Vulkan guarantees 65535 work-groups per dimension; larger grids fold into y.
constexpr std::uint32_t kMaxGroupsX = 65535;

}  // namespace

DeviceLaserScanner::DeviceLaserScanner(const compute::Context& context, const LaserScanner& scanner)
    : context_(&context),
      beams_(scanner.beams()),
      map_width_(scanner.map_width()),
      map_height_(scanner.map_height()),
      max_steps_(scanner.max_steps()),
      resolution_(scanner.resolution()),
      skips_(compute::Buffer<std::int32_t>::from_host(context, scanner.skips().pixels())),
      directions_(compute::Buffer<std::int32_t>::from_host(context, scanner.directions())) {
  // A loop over a cell's beams per work-item suits CPUs and CPU-hosted drivers (fewer, longer
  // items); a GPU wants one item per beam.
  beams_per_item_ = context.device_info().is_gpu() ? 1 : beams_;
}

void DeviceLaserScanner::set_beams_per_work_item(int beams_per_item) {
  require(beams_per_item >= 1 && beams_per_item <= beams_,
          "device laser scanner: beams per work-item must be in [1, " + std::to_string(beams_) +
              "], got " + std::to_string(beams_per_item));
  beams_per_item_ = beams_per_item;
}

void DeviceLaserScanner::scan_steps(std::span<const ScanCell> cells,
                                    compute::Buffer<std::int32_t>& steps) {
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const ScanCell& cell = cells[i];
    if (cell.col < 0 || cell.row < 0 || cell.col >= map_width_ || cell.row >= map_height_) {
      throw Error("device laser scanner: cell " + std::to_string(i) + " (col " +
                  std::to_string(cell.col) + ", row " + std::to_string(cell.row) +
                  ") is outside the " + std::to_string(map_width_) + " x " +
                  std::to_string(map_height_) + " map");
    }
  }
  const std::size_t total = cells.size() * static_cast<std::size_t>(beams_);
  require(total <= std::numeric_limits<std::uint32_t>::max(),
          "device laser scanner: " + std::to_string(cells.size()) + " cells of " +
              std::to_string(beams_) + " beams exceed 2^32 - 1 beams in one call");
  if (steps.size() != total) steps = compute::Buffer<std::int32_t>(*context_, total);
  if (cells.empty()) return;

  if (cells_.size() < cells.size()) cells_ = compute::Buffer<ScanCell>(*context_, cells.size());
  cells_.upload(cells);
  const std::uint32_t items_per_cell =
      static_cast<std::uint32_t>((beams_ + beams_per_item_ - 1) / beams_per_item_);
  const std::size_t items = cells.size() * items_per_cell;
  const kernels::LaserScanParams params{static_cast<std::uint32_t>(items),
                                        items_per_cell,
                                        static_cast<std::uint32_t>(beams_),
                                        static_cast<std::uint32_t>(beams_per_item_),
                                        map_width_,
                                        map_height_,
                                        max_steps_};
  const std::uint32_t groups = compute::groups_for(items, kLaserScanKernel.local_x);
  const std::uint32_t groups_x = std::min(groups, kMaxGroupsX);
  const std::uint32_t groups_y = (groups + groups_x - 1) / groups_x;
  compute::dispatch(*context_, kLaserScanKernel, {skips_, directions_, cells_, steps}, params,
                    {groups_x, groups_y});
}

namespace {

// Scans `cells` in batches of `batch_cells` into `steps`; use(first cell, steps) reads each batch's
// steps in place where device memory is host memory (no copy on the CPU).
template <class Use>
void scan_in_batches(DeviceLaserScanner& scanner, std::span<const ScanCell> cells,
                     std::size_t batch_cells, compute::Buffer<std::int32_t>& steps,
                     const Use& use) {
  require(batch_cells > 0, "device laser scanner: batch_cells must be > 0");
  for (std::size_t first = 0; first < cells.size(); first += batch_cells) {
    const std::size_t count = std::min(batch_cells, cells.size() - first);
    scanner.scan_steps(cells.subspan(first, count), steps);
    use(first, compute::read_on_host(steps));
  }
}

}  // namespace

std::vector<std::int32_t> DeviceLaserScanner::scan_steps(std::span<const ScanCell> cells,
                                                         std::size_t batch_cells) {
  const std::size_t beams = static_cast<std::size_t>(beams_);
  std::vector<std::int32_t> steps(cells.size() * beams);
  scan_in_batches(*this, cells, batch_cells, batch_steps_,
                  [&](std::size_t first, const auto& batch) {
                    std::copy(batch.begin(), batch.end(), steps.begin() + first * beams);
                  });
  return steps;
}

std::vector<double> DeviceLaserScanner::scan_ranges(std::span<const ScanCell> cells,
                                                    std::size_t batch_cells) {
  const std::size_t beams = static_cast<std::size_t>(beams_);
  std::vector<double> ranges(cells.size() * beams);
  scan_in_batches(*this, cells, batch_cells, batch_steps_,
                  [&](std::size_t first, const auto& batch) {
                    std::transform(batch.begin(), batch.end(), ranges.begin() + first * beams,
                                   [&](std::int32_t s) { return s * resolution_; });
                  });
  return ranges;
}

}  // namespace kartograf::rooms
