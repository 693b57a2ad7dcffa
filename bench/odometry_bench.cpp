// RGB-D odometry throughput over a sequence, on every available backend (Google Benchmark).
//   odometry/<backend>/640x480:               RgbdOdometry (point-to-plane, depth weights,
//       geometric degeneracy, photometric refinement, the M3 paper's re-estimation every 5th frame)
//       over 60 frames held in memory: no file I/O. Reports frames/s and the ATE of the run.
//   odometry/<backend>/640x480/no_reestimate: the same without the re-estimation (k = 0).
//   odometry/<backend>/320x240:               the same sequence rendered at half resolution.
// Input: frames 100-159 of the synthetic 500-frame robot tour (synth/, seed 1; Kinect noise
// model), about 4.5 cm and up to 3 degrees a frame, rendered once before the cases run.
// KARTOGRAF_BENCH_BACKENDS=cpu,vulkan,opencl restricts the backends (bench_support.hpp).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "bench_support.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/registration/odometry.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"

namespace kartograf {
namespace {

using compute::BackendKind;

struct Sequence {
  PinholeIntrinsics camera;
  std::vector<registration::RgbdImages> frames;
  std::vector<Eigen::Isometry3d> truth;
};

Sequence render(const PinholeIntrinsics& camera) {
  const synth::World world = synth::make_building(1);
  const Trajectory tour = synth::robot_tour(world, 500);
  Sequence sequence;
  sequence.camera = camera;
  for (std::size_t i = 100; i < 160; ++i) {
    synth::SyntheticFrame frame =
        synth::render(world, camera, tour[i].pose, synth::NoiseModel::kinect(), i);
    sequence.frames.push_back({std::move(frame.depth), std::move(frame.color), tour[i].timestamp});
    sequence.truth.push_back(tour[i].pose);
  }
  return sequence;
}

const Sequence& sequence_of(int width) {
  static const Sequence vga = render({640, 480, 525.0, 525.0, 319.5, 239.5});
  static const Sequence qvga = render({320, 240, 262.5, 262.5, 159.5, 119.5});
  return width == 640 ? vga : qvga;
}

double ate_rmse(const std::vector<Eigen::Isometry3d>& estimate,
                const std::vector<Eigen::Isometry3d>& truth) {
  eval::MatchedPoses matched;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    matched.ground_truth.push_back({static_cast<double>(i), truth[i]});
    matched.estimate.push_back({static_cast<double>(i), estimate[i]});
  }
  return eval::compute_ate(matched, eval::Alignment::se3).translation_m.rmse;
}

void run(benchmark::State& state, BackendKind backend, int width, int reestimate_interval) {
  const Sequence& sequence = sequence_of(width);
  const compute::Context context(bench::context_options(backend));
  registration::OdometryParams params;
  params.depth_range.units_per_metre = synth::kTumDepthUnitsPerMetre;
  params.reestimate_interval = reestimate_interval;
  double ate = 0;
  const auto track_all = [&] {
    registration::RgbdOdometry odometry(context, sequence.camera, params);
    for (const auto& frame : sequence.frames) odometry.track(frame.depth, &frame.color);
    return ate_rmse(odometry.poses(), sequence.truth);
  };
  track_all();  // warm-up: pipelines built, driver JIT done
  for (auto _ : state) ate = track_all();
  const double frames = static_cast<double>(sequence.frames.size());
  state.counters["frames_per_s"] = benchmark::Counter(
      frames * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["ate_mm"] = 1000.0 * ate;
  state.SetLabel(context.device_info().name);
}

void register_benchmarks() {
  for (const BackendKind backend : bench::backends_to_run()) {
    const auto add = [&](const std::string& label, int width, int k) {
      bench::repeated(benchmark::RegisterBenchmark(label.c_str(), run, backend, width, k), 3)
          ->Iterations(1);
    };
    add(bench::case_name("odometry", backend, "640x480"), 640, 5);
    add(bench::case_name("odometry", backend, "640x480") + "/no_reestimate", 640, 0);
    add(bench::case_name("odometry", backend, "320x240"), 320, 5);
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_benchmarks);
}
