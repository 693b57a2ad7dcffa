// Frame-to-frame ICP odometry on every available backend (Google Benchmark, median of 5).
//   icp_odometry/<backend>/640x480:  one new frame: depth -> back-projection -> pyramid (points,
//       normals, 3 levels) -> projective point-to-plane ICP against the previous frame's pyramid
//       with IcpParams{} (odometry_levels()); the per-frame cost of odometry. Reports frames/s.
//   icp_pyramid/<backend>/640x480:   the pyramid part alone (back-projection included).
//   icp_align/<backend>/640x480:     the ICP part alone.
// Input: a synthetic room corner with two boxes ray cast to millimetre depth from two poses 1 cm
// and 0.6 degrees apart (a 30 Hz hand-held motion). Counters: ICP iterations, fitness, and the
// error against the true motion (millimetre depth quantisation is the only noise).
// KARTOGRAF_BENCH_BACKENDS=cpu,vulkan,opencl restricts the backends (default: all available).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <string>

#include "../tests/icp_test_scene.hpp"
#include "bench_support.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/icp.hpp"

namespace kartograf {
namespace {

using compute::BackendKind;

DepthImage to_depth(const PointImage& points) {
  DepthImage depth(points.width(), points.height(), 0);
  for (int v = 0; v < points.height(); ++v) {
    for (int u = 0; u < points.width(); ++u) {
      const Point4f& p = points(u, v);
      if (is_valid(p)) depth(u, v) = static_cast<std::uint16_t>(std::lround(p.z() * 1000.0));
    }
  }
  return depth;
}

struct HostFrames {
  HostFrames() {
    const Eigen::Isometry3d pose = testing::reference_camera();
    previous = to_depth(testing::render(testing::corner_scene(), camera, pose));
    current = to_depth(testing::render(testing::corner_scene(), camera, pose * truth));
  }
  PinholeIntrinsics camera = testing::vga_camera();
  // The current camera in the previous camera's frame, which is also the transform that maps
  // current-frame points into the previous frame: what align(current, previous) estimates.
  Eigen::Isometry3d truth =
      Eigen::Translation3d(0.008, -0.004, 0.004) *
      Eigen::AngleAxisd(0.6 * std::numbers::pi / 180.0, Eigen::Vector3d(1, 2, 0.5).normalized());
  DepthImage previous, current;
};

const HostFrames& host_frames() {
  static const HostFrames frames;
  return frames;
}

// Device state of an odometry front end: the previous frame's pyramid stays, the new one is
// rebuilt from depth every frame.
struct Odometry {
  explicit Odometry(const compute::Context& context)
      : projector(context, host_frames().camera, geometry::DepthRange{}),
        depth(compute::DeviceImage<std::uint16_t>::from_host(context, host_frames().current)),
        previous(context, host_frames().camera),
        current(context, host_frames().camera),
        engine(context) {
    const auto previous_depth =
        compute::DeviceImage<std::uint16_t>::from_host(context, host_frames().previous);
    previous.build(projector, previous_depth);
    current.build(projector, depth);
    context.finish();
  }
  geometry::DepthBackprojector projector;
  compute::DeviceImage<std::uint16_t> depth;
  registration::FramePyramid previous, current;
  registration::IcpEngine engine;
};

enum class Part { whole, pyramid, align };

void run(benchmark::State& state, BackendKind backend, Part part) {
  const compute::Context context(bench::context_options(backend));
  Odometry odometry(context);
  registration::IcpResult result;
  const auto step = [&] {
    if (part != Part::align) odometry.current.build(odometry.projector, odometry.depth);
    if (part != Part::pyramid) result = odometry.engine.align(odometry.current, odometry.previous);
    context.finish();
  };
  step();  // warm-up: pipelines built, driver JIT done, buffers allocated
  for (auto _ : state) step();
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  if (part != Part::pyramid) {
    state.counters["iterations"] = result.iterations;
    state.counters["fitness"] = result.fitness;
    const Eigen::Isometry3d error = host_frames().truth.inverse() * result.source_to_target;
    state.counters["rotation_error_deg"] = se3::rotation_angle(error) * 180.0 / std::numbers::pi;
    state.counters["translation_error_mm"] = 1000.0 * error.translation().norm();
  }
  state.SetLabel(context.device_info().name);
}

void register_benchmarks() {
  for (const BackendKind backend : bench::backends_to_run()) {
    for (const auto& [name, part] :
         {std::pair{"icp_odometry", Part::whole}, std::pair{"icp_pyramid", Part::pyramid},
          std::pair{"icp_align", Part::align}}) {
      const std::string label = bench::case_name(name, backend, "640x480");
      bench::repeated(benchmark::RegisterBenchmark(label.c_str(), run, backend, part), 5)
          ->MinTime(0.5);
    }
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_benchmarks);
}
