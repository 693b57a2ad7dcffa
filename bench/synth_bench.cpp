// The synthetic world generator's stages (CPU only; no files): building a world, planning the
// robot tour, rendering a frame (with and without sensor noise, on one thread and on all cores),
// ray casting a frame through the grid (the reference the renderer is tested against), the floor
// plan and the laser scan. File writing is measured end to end by `time kartograf synth`
// (docs/synthetic-world.md).
//
//   ./build/bench/kartograf_synth_bench --benchmark_filter=render
#include <benchmark/benchmark.h>

#include <cstdint>

#include "kartograf/synth/floor_plan.hpp"
#include "kartograf/synth/laser_scan.hpp"
#include "kartograf/synth/ray_caster.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"

namespace kartograf::synth {
namespace {

const PinholeIntrinsics kKinect{640, 480, 525.0, 525.0, 319.5, 239.5};

// The default world and its tour, built once.
struct Scene {
  World world = make_building(1);
  Trajectory tour = robot_tour(world, 300);
};
const Scene& scene() {
  static const Scene s;
  return s;
}

void make_building_bench(benchmark::State& state) {
  std::uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(make_building(seed++));
}
BENCHMARK(make_building_bench)->Name("make_building")->Unit(benchmark::kMillisecond);

void robot_tour_bench(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(robot_tour(scene().world, 300));
}
BENCHMARK(robot_tour_bench)->Name("robot_tour/300")->Unit(benchmark::kMillisecond);

// Arguments: noise (0 none, 1 kinect), threads (0 = all cores). Frames cycle through the tour.
void render_bench(benchmark::State& state) {
  const NoiseModel noise = state.range(0) ? NoiseModel::kinect() : NoiseModel::none();
  const RenderParams options{static_cast<int>(state.range(1))};
  std::size_t frame = 0;
  for (auto _ : state) {
    const StampedPose& pose = scene().tour[frame % scene().tour.size()];
    benchmark::DoNotOptimize(render(scene().world, kKinect, pose.pose, noise, frame, options));
    frame += 7;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(render_bench)
    ->Name("render/640x480")
    ->ArgNames({"kinect_noise", "threads"})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({1, 0})
    ->Unit(benchmark::kMillisecond);

void ray_cast_frame_bench(benchmark::State& state) {
  const RayCaster caster(scene().world);
  std::size_t frame = 0;
  for (auto _ : state) {
    const Eigen::Isometry3d& pose = scene().tour[frame % scene().tour.size()].pose;
    double sum = 0;
    for (int v = 0; v < kKinect.height; ++v) {
      for (int u = 0; u < kKinect.width; ++u) {
        const Eigen::Vector3d ray((u - kKinect.cx) / kKinect.fx, (v - kKinect.cy) / kKinect.fy,
                                  1.0);
        if (const auto hit = caster.cast(pose.translation(), pose.linear() * ray)) sum += hit->t;
      }
    }
    benchmark::DoNotOptimize(sum);
    frame += 7;
  }
}
BENCHMARK(ray_cast_frame_bench)->Name("ray_cast/640x480/threads:1")->Unit(benchmark::kMillisecond);

void floor_plan_bench(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(make_floor_plan(scene().world));
}
BENCHMARK(floor_plan_bench)->Name("floor_plan/0.05m")->Unit(benchmark::kMillisecond);

void laser_scan_bench(benchmark::State& state) {
  const RayCaster caster(scene().world);
  LidarScanParams options;
  options.threads = 1;
  const Eigen::Isometry3d pose = default_scan_pose(scene().world);
  for (auto _ : state) benchmark::DoNotOptimize(scan_laser(caster, pose, options, 1));
}
BENCHMARK(laser_scan_bench)->Name("laser_scan/361x201/threads:1")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace kartograf::synth

BENCHMARK_MAIN();
