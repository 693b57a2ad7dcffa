// kartograf_plane_bench: Kartograf's plane extraction in both modes (regions: the M1 paper's Lab
// growing; cells: planar cells first) on the plane benchmark's frames, with each mode's time, its
// parts and its quality figures (docs/benchmarks.md "Planes"). The same frames, scoring and tables
// as kartograf_peer_bench's plane part, without its peers (no Open3D or PCL needed); with CAPE
// beside them when built with KARTOGRAF_CAPE_DIR (scripts/fetch-cape.sh).
#include <chrono>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <thread>

#include <CLI/CLI.hpp>

#include "peer/peer_methods.hpp"
#include "peer/peer_timing.hpp"
#include "peer/plane_bench.hpp"
#include "peer/plane_methods.hpp"

int main(int argc, char** argv) {
  using kartograf::peer::PlaneBenchOptions;
  PlaneBenchOptions options;
  CLI::App app{"Kartograf's plane extraction modes on the plane benchmark's frames"};
  const char* data = std::getenv("KARTOGRAF_DATA_DIR");
  const std::filesystem::path data_dir = data && *data ? data : KARTOGRAF_DEFAULT_DATA_DIR;
  options.seven_scenes = data_dir / "7scenes_redkitchen";
  options.mosd = data_dir / "pcl_mosd";
  app.add_option("--seven-scenes", options.seven_scenes, "7-Scenes folder ('' to skip)")
      ->capture_default_str();
  app.add_option("--seven-scenes-frames", options.seven_scenes_frames, "7-Scenes frame indices")
      ->capture_default_str();
  app.add_option("--mosd", options.mosd, "PCL's mOSD folder ('' to skip)")->capture_default_str();
  app.add_option("--synthetic-frames", options.synthetic_frames,
                 "Synthetic robot-tour frames with exact plane ids (0 to skip)")
      ->capture_default_str()
      ->check(CLI::Range(0, 290));
  app.add_option("--min-time", options.timing.min_time, "Seconds of calls per method and frame")
      ->capture_default_str();
  app.add_option("--max-calls", options.timing.max_calls, "Most timed calls per method and frame")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  app.add_option("--overlays", options.overlays, "Write every mode's planes over every frame here");
  app.add_flag("!--no-device-backends", options.device_backends, "The CPU backend only");
  app.add_option("--streams", options.throughput.streams,
                 "Frames at a time: threads, each extracting its own frames (0: skip)")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  app.add_flag("--details", options.details, "Every frame's time and scores on stderr");
  app.add_option("--only", options.only, "Only methods whose name contains this");
  CLI11_PARSE(app, argc, argv);
#ifdef KARTOGRAF_WITH_CAPE
  options.peers = kartograf::peer::cape_plane_methods();
#endif
  try {
    const auto start = std::chrono::steady_clock::now();
    std::cout << "# Kartograf plane benchmark\n\n- machine: " << kartograf::peer::cpu_model()
              << ", " << std::thread::hardware_concurrency() << " cores; load average at start "
              << kartograf::peer::load_average()
              << "\n- threads: " << kartograf::peer::kartograf_threads() << "\n";
    kartograf::peer::run_plane_bench(options, std::cout);
    std::cout << "\nload average at the end " << kartograf::peer::load_average() << "; run took "
              << static_cast<long>(kartograf::peer::seconds_since(start)) << " s\n";
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "kartograf_plane_bench: " << error.what() << "\n";
    return 1;
  }
}
