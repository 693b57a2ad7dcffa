// Plane extraction (docs/methods.md M1 steps 2-4) at 640x480:
//   plane_extraction/<backend>/640x480: PlaneExtractor::extract with its defaults (Lab codes,
//       tiled growing, moments, merging, pixel refinement, output), cycling through 8 frames of
//       the synthetic robot tour; counters: the median stage times of the last run [ms], planes;
//   region_grow/<backend>/640x480/t<threshold>: RegionGrower::grow (16 px tiles, 2 % depth jump:
//       the extraction's growing) on points resident on the device;
//   region_grow_sequential/cpu/640x480/t<threshold>: the paper's untiled growing (grow_regions).
// Input: synthetic world seed 1 with the Kinect noise model, colour -> Lab codes and depth ->
// points once before the cases run. KARTOGRAF_BENCH_BACKENDS restricts the backends;
// KARTOGRAF_CPU_THREADS sets the CPU backend's threads (default 1).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/segmentation/region_growing.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"

namespace kartograf {
namespace {

using compute::BackendKind;

const PinholeIntrinsics kCamera{640, 480, 525.0, 525.0, 319.5, 239.5};

struct HostFrame {
  RgbImage color;
  segmentation::LabCodeImage lab;
  PointImage points;
};

const std::vector<HostFrame>& host_frames() {
  static const std::vector<HostFrame> frames = [] {
    const synth::World world = synth::make_building(1);
    const Trajectory tour = synth::robot_tour(world, 300);
    const compute::Context cpu = compute::Context::cpu();
    std::vector<HostFrame> result;
    for (int f = 0; f < 8; ++f) {
      const int index = 7 + f * 37;
      const synth::SyntheticFrame rendered =
          synth::render(world, kCamera, tour[index].pose, synth::NoiseModel::kinect(), index);
      result.push_back({rendered.color, segmentation::to_lab_codes(rendered.color),
                        geometry::backproject(cpu, rendered.depth, kCamera, {5000.0})});
    }
    return result;
  }();
  return frames;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

void plane_extraction(benchmark::State& state, BackendKind backend) {
  const compute::Context context(bench::context_options(backend));
  const std::vector<HostFrame>& frames = host_frames();
  segmentation::PlaneExtractor extractor(context, kCamera);
  for (const HostFrame& frame : frames) extractor.extract(frame.points, frame.color);  // warm-up
  std::vector<double> lab, growing, moments, merging, output, planes;
  std::size_t next = 0;
  for (auto _ : state) {
    const HostFrame& frame = frames[next++ % frames.size()];
    const segmentation::PlaneSet set = extractor.extract(frame.points, frame.color);
    lab.push_back(set.timings.lab);
    growing.push_back(set.timings.growing);
    moments.push_back(set.timings.moments);
    merging.push_back(set.timings.merging);
    output.push_back(set.timings.output);
    planes.push_back(static_cast<double>(set.planes.size()));
  }
  state.counters["lab_ms"] = median(lab);
  state.counters["grow_ms"] = median(growing);
  state.counters["moments_ms"] = median(moments);
  state.counters["merge_ms"] = median(merging);
  state.counters["output_ms"] = median(output);
  state.counters["planes"] = median(planes);
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(context.device_info().name);
}

// The extraction's growing (tiles, depth jump) at another threshold.
segmentation::RegionGrowingParams tiled(float threshold) {
  segmentation::RegionGrowingParams params = segmentation::PlaneExtractionParams{}.growing;
  params.lab_threshold = threshold;
  return params;
}

void region_grow(benchmark::State& state, BackendKind backend, float threshold) {
  const compute::Context context(bench::context_options(backend));
  const HostFrame& host = host_frames().front();
  const auto points = compute::Buffer<Point4f>::from_host(context, host.points.pixels());
  segmentation::RegionGrower grower(context);
  const segmentation::RegionGrowingParams params = tiled(threshold);
  grower.grow(host.lab, points, params);  // warm-up: pipelines built, driver JIT done
  std::uint32_t segments = 0;
  for (auto _ : state) segments = grower.grow(host.lab, points, params);
  state.counters["segments"] = segments;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(host.lab.size()));
  state.SetLabel(context.device_info().name);
}

void region_grow_sequential(benchmark::State& state, float threshold) {
  const HostFrame& host = host_frames().front();
  segmentation::RegionGrowingParams params;
  params.lab_threshold = threshold;
  segmentation::SegmentLabelImage labels;
  std::uint32_t segments = 0;
  for (auto _ : state) segments = segmentation::grow_regions(host.lab, host.points, params, labels);
  state.counters["segments"] = segments;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(host.lab.size()));
}

void register_benchmarks() {
  const std::string size = "640x480";
  for (const BackendKind backend : bench::backends_to_run()) {
    bench::repeated(
        benchmark::RegisterBenchmark(bench::case_name("plane_extraction", backend, size).c_str(),
                                     plane_extraction, backend),
        5)
        ->MinTime(0.5);
  }
  for (const float threshold : {15.0f, 25.0f}) {
    const std::string variant = "/t" + std::to_string(static_cast<int>(threshold));
    for (const BackendKind backend : bench::backends_to_run()) {
      const std::string name = bench::case_name("region_grow", backend, size) + variant;
      bench::repeated(benchmark::RegisterBenchmark(name.c_str(), region_grow, backend, threshold),
                      5)
          ->MinTime(0.2);
    }
    const std::string name =
        bench::case_name("region_grow_sequential", BackendKind::cpu, size) + variant;
    bench::repeated(benchmark::RegisterBenchmark(name.c_str(), region_grow_sequential, threshold),
                    5)
        ->MinTime(0.2);
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_benchmarks);
}
