// Simulated laser scans of the feature-based room segmentation (rooms/laser_scan_device.hpp) on
// every available backend: 360 beams, 50 m, from the free cells of the ipa map office_e
// ($KARTOGRAF_DATA_DIR/ipa_room_maps/test_maps, default ../shared/data; a synthetic map of rooms
// off a corridor when it is absent).
//   laser_scan/<backend>/<map>_every4th/<split>: every 4th free cell (row-major order);
//   laser_scan/<backend>/<map>_lattice4/<split>:  free cells on the lattice of every 4th column
//                                                 and row (what segment_feature_based scans);
//   <split>: per_beam (one work-item per cell and beam) or per_cell (one per cell, a loop over its
//   beams); the CPU backend has one split (KARTOGRAF_CPU_THREADS threads).
// Steady state: the map's skip image and directions already on the device, one scan_steps call
// into a device buffer plus finish(), after a warm-up call; counter beams_per_s.
// KARTOGRAF_BENCH_BACKENDS=cpu,vulkan,opencl restricts the backends (default: all available).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/rooms/laser_scan_device.hpp"

namespace kartograf {
namespace {

using compute::BackendKind;
using rooms::ScanCell;

// 0.05 m cells: a 2 m corridor along the bottom, 5 x 5 m rooms above it opening onto it by 1 m
// doors.
OccupancyGrid synthetic_map() {
  constexpr int kRooms = 8, kRoom = 100, kWall = 2, kCorridor = 40;
  const int width = kRooms * (kRoom + kWall) + kWall, height = kRoom + kCorridor + 3 * kWall;
  OccupancyGrid map;
  map.resolution = 0.05;
  map.cells = Image<CellState>(width, height, CellState::occupied);
  const auto carve = [&](int x0, int y0, int x1, int y1) {
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) map.cells(x, y) = CellState::free;
    }
  };
  for (int k = 0; k < kRooms; ++k) {
    const int x0 = kWall + k * (kRoom + kWall);
    carve(x0, kWall, x0 + kRoom, kWall + kRoom);
    carve(x0 + 40, kWall + kRoom, x0 + 60, 2 * kWall + kRoom);  // door
  }
  carve(kWall, 2 * kWall + kRoom, width - kWall, 2 * kWall + kRoom + kCorridor);
  return map;
}

struct ScanMap {
  std::string name;
  OccupancyGrid map;
};

ScanMap scan_map() {
  const char* data = std::getenv("KARTOGRAF_DATA_DIR");
  const std::filesystem::path path =
      std::filesystem::path(data && *data ? data : KARTOGRAF_DEFAULT_DATA_DIR) / "ipa_room_maps" /
      "test_maps" / "office_e.png";
  if (std::filesystem::exists(path)) return {"office_e", io::read_png_map(path, 0.05)};
  std::cerr << "laser_scan_bench: " << path << " is missing; scanning a synthetic map\n";
  return {"synthetic", synthetic_map()};
}

// Free cells: every `every`-th in row-major order, or (lattice) those whose column and row are
// multiples of `every`.
std::vector<ScanCell> cells_of(const OccupancyGrid& map, int every, bool lattice) {
  std::vector<ScanCell> cells;
  int n = 0;
  for (int row = 0; row < map.height(); ++row) {
    for (int col = 0; col < map.width(); ++col) {
      if (map.cells(col, row) != CellState::free) continue;
      const bool take = lattice ? col % every == 0 && row % every == 0 : n++ % every == 0;
      if (take) cells.push_back({col, row});
    }
  }
  return cells;
}

void scan(benchmark::State& state, BackendKind backend,
          std::shared_ptr<const rooms::LaserScanner> scanner,
          std::shared_ptr<const std::vector<ScanCell>> cells, bool per_cell) {
  const compute::Context context(bench::context_options(backend));
  rooms::DeviceLaserScanner device(context, *scanner);
  device.set_beams_per_work_item(per_cell ? device.beams() : 1);
  compute::Buffer<std::int32_t> steps;
  device.scan_steps(*cells, steps);  // warm-up: pipeline / kernel build, driver compilation
  context.finish();
  for (auto _ : state) {
    device.scan_steps(*cells, steps);
    context.finish();
  }
  const double beams = static_cast<double>(cells->size()) * device.beams();
  state.counters["cells"] = static_cast<double>(cells->size());
  state.counters["beams_per_s"] = benchmark::Counter(
      beams * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(context.device_info().name);
}

void register_cases() {
  const ScanMap source = scan_map();
  const auto scanner = std::make_shared<const rooms::LaserScanner>(source.map);
  for (const bool lattice : {false, true}) {
    const auto cells =
        std::make_shared<const std::vector<ScanCell>>(cells_of(source.map, 4, lattice));
    const std::string size = source.name + (lattice ? "_lattice4" : "_every4th");
    for (const BackendKind backend : bench::backends_to_run()) {
      for (const bool per_cell : {false, true}) {
        if (backend == BackendKind::cpu && per_cell) continue;  // one split on the CPU backend
        const std::string name =
            bench::case_name("laser_scan", backend, size) + (backend == BackendKind::cpu ? ""
                                                             : per_cell ? "/per_cell"
                                                                        : "/per_beam");
        bench::repeated(
            benchmark::RegisterBenchmark(name.c_str(), scan, backend, scanner, cells, per_cell), 3)
            ->MinTime(0.5);
      }
    }
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_cases);
}
