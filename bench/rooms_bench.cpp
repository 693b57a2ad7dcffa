// Room segmentation of the ipa_room_segmentation benchmark maps (docs/methods.md M4), CPU:
//   rooms/<method>/<map>_<variant>: rooms::segment_rooms on the map in memory (reading the PNG is
//   outside the timing), median of 3 repetitions; counter rooms = rooms found.
// Maps: $KARTOGRAF_DATA_DIR/ipa_room_maps/test_maps (default ../shared/data), every map with a
// ground truth, plain and furnished (--benchmark_filter=_plain for the plain ones only).
// The survey's reference implementation takes, per map on this kind of machine: morphological
// 0.2-0.7 s, distance 0.4-0.8 s, Voronoi 11-19 s, feature-based 80-115 s, VRF 57-180 s.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include "kartograf/compute/context.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/outputs/room_io.hpp"
#include "kartograf/rooms/room_methods.hpp"

namespace kartograf {
namespace {

std::filesystem::path maps_folder() {
  const char* data = std::getenv("KARTOGRAF_DATA_DIR");
  return std::filesystem::path(data && *data ? data : KARTOGRAF_DEFAULT_DATA_DIR) /
         "ipa_room_maps" / "test_maps";
}

void register_cases() {
  for (const io::RoomMapCase& c : io::find_room_maps(maps_folder())) {
    if (c.variant != "plain" && c.variant != "furnitures") continue;
    const auto map = std::make_shared<OccupancyGrid>(io::read_png_map(c.map));
    for (const rooms::RoomMethod method : rooms::all_room_methods()) {
      const std::string name = "rooms/" + rooms::to_string(method) + "/" + c.name + "_" + c.variant;
      benchmark::RegisterBenchmark(name.c_str(),
                                   [map, method](benchmark::State& state) {
                                     std::size_t found = 0;
                                     for (auto _ : state)
                                       found = rooms::segment_rooms(compute::Context::cpu(), *map,
                                                                    method)
                                                   .records.size();
                                     state.counters["rooms"] = static_cast<double>(found);
                                   })
          ->Unit(benchmark::kMillisecond)
          ->Iterations(1)
          ->Repetitions(3)
          ->ReportAggregatesOnly(true)
          ->UseRealTime();
    }
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  try {
    kartograf::register_cases();
  } catch (const std::exception& e) {
    std::cerr << "kartograf_rooms_bench: " << e.what() << "\n";
    return 1;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
