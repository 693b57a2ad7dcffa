// Over-segmentation in Lab (methods.md M1 step 2) at 640x480:
//   region_grow_parallel/<backend>/640x480/t<threshold>[/depth]: ParallelRegionGrowing::segment on
//       inputs resident on the device, plus finish(), after a warm-up call (the per-frame cost);
//   region_grow_sequential/cpu/640x480/t<threshold>: the paper's stack-based grow_regions_lab.
// Input: frame 100 of the synthetic robot tour (synth/, seed 1, Kinect noise), colour -> Lab and
// depth -> points once before the cases run. Reports the segment count.
// KARTOGRAF_BENCH_BACKENDS restricts the backends; KARTOGRAF_CPU_THREADS the CPU backend's threads.
#include <benchmark/benchmark.h>

#include <string>

#include "bench_support.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/segmentation/parallel_region_growing.hpp"
#include "kartograf/segmentation/region_growing.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"

namespace kartograf {
namespace {

using compute::BackendKind;

struct HostFrame {
  segmentation::LabImage lab;
  PointImage points;
};

const HostFrame& host_frame() {
  static const HostFrame frame = [] {
    const PinholeIntrinsics camera{640, 480, 525.0, 525.0, 319.5, 239.5};
    const synth::World world = synth::make_building(1);
    const synth::SyntheticFrame rendered = synth::render(
        world, camera, synth::robot_tour(world, 500)[100].pose, synth::NoiseModel::kinect(), 100);
    const compute::Context cpu = compute::Context::cpu();
    return HostFrame{segmentation::to_lab(rendered.color),
                     geometry::backproject(cpu, rendered.depth, camera, {5000.0})};
  }();
  return frame;
}

segmentation::RegionGrowingParams params_for(float threshold, float depth_jump) {
  segmentation::RegionGrowingParams params;
  params.lab_threshold = threshold;
  params.max_depth_jump = depth_jump;
  return params;
}

void parallel_steady(benchmark::State& state, BackendKind backend, float threshold,
                     float depth_jump) {
  const compute::Context context(bench::context_options(backend));
  const HostFrame& host = host_frame();
  const auto lab = compute::Buffer<Eigen::Vector4f>::from_host(context, host.lab.pixels());
  const auto points = compute::Buffer<Point4f>::from_host(context, host.points.pixels());
  segmentation::ParallelRegionGrowing growing(context, host.lab.width(), host.lab.height());
  const auto params = params_for(threshold, depth_jump);
  growing.segment(lab, points, params);  // warm-up: pipelines built, driver JIT done
  context.finish();
  std::uint32_t segments = 0;
  for (auto _ : state) {
    segments = growing.segment(lab, points, params);
    context.finish();
  }
  state.counters["segments"] = segments;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(host.lab.size()));
  state.SetLabel(context.device_info().name);
}

void sequential(benchmark::State& state, float threshold, float depth_jump) {
  const HostFrame& host = host_frame();
  const auto params = params_for(threshold, depth_jump);
  std::uint32_t segments = 0;
  for (auto _ : state) {
    const segmentation::SegmentLabelImage labels =
        segmentation::grow_regions_lab(host.lab, host.points, params);
    segments = segmentation::segment_count(labels);
  }
  state.counters["segments"] = segments;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(host.lab.size()));
}

void register_benchmarks() {
  const std::string size = "640x480";
  for (const float threshold : {10.0f, 20.0f}) {
    const std::string variant = "/t" + std::to_string(static_cast<int>(threshold));
    for (const BackendKind backend : bench::backends_to_run()) {
      const std::string name = bench::case_name("region_grow_parallel", backend, size);
      bench::repeated(benchmark::RegisterBenchmark((name + variant).c_str(), parallel_steady,
                                                   backend, threshold, 0.0f),
                      5)
          ->MinTime(0.2);
      bench::repeated(benchmark::RegisterBenchmark((name + variant + "/depth").c_str(),
                                                   parallel_steady, backend, threshold, 0.05f),
                      5)
          ->MinTime(0.2);
    }
    const std::string name = bench::case_name("region_grow_sequential", BackendKind::cpu, size);
    bench::repeated(
        benchmark::RegisterBenchmark((name + variant).c_str(), sequential, threshold, 0.0f), 5)
        ->MinTime(0.2);
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_benchmarks);
}
