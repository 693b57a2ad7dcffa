// Every compute operation on every available backend, at 640x480 and 1280x720.
//   <op>/<backend>/<width>x<height>/steady: inputs resident on the device, one call + finish,
//                                           after a warm-up call (the per-frame cost);
//   <op>/<backend>/<width>x<height>/cold:   a fresh context, then the first call (pipeline or
//                                           program build and driver JIT included).
// KARTOGRAF_BENCH_BACKENDS=cpu,vulkan,opencl restricts the backends (default: all available).
#include <benchmark/benchmark.h>

#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "bench_support.hpp"
#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/geometry/segment_moments.hpp"
#include "kartograf/registration/icp_sums.hpp"

namespace kartograf {
namespace {

using compute::BackendKind;

PinholeIntrinsics camera(int width, int height) {
  const double f = 525.0 * width / 640.0;
  return {width, height, f, f, width / 2.0 - 0.5, height / 2.0 - 0.5};
}

// A room corner seen from 1.2 m: two walls and a floor, a few holes; millimetre depth.
DepthImage room_depth(int width, int height) {
  const PinholeIntrinsics k = camera(width, height);
  DepthImage depth(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double x = (u - k.cx) / k.fx, y = (v - k.cy) / k.fy;
      double z = 3.0 / (1.0 + 0.4 * x);                // a slanted wall
      if (y > 0.05) z = std::min(z, 1.2 / y);          // the floor
      const bool hole = (u * 7 + v * 13) % 101 == 0;   // missing returns
      depth(u, v) = hole ? 0 : static_cast<std::uint16_t>(std::lround(z * 1000.0));
    }
  }
  return depth;
}

// Inputs of every operation, made once on the host with the CPU backend.
struct HostFrame {
  HostFrame(int width, int height) : intrinsics(camera(width, height)), depth(room_depth(width, height)) {
    const compute::Context cpu = compute::Context::cpu();
    points = geometry::backproject(cpu, depth, intrinsics);
    normals = geometry::estimate_normals(cpu, points);
    labels.resize(points.size());
    const int tiles_x = (width + 15) / 16;
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) labels[v * width + u] = (v / 16) * tiles_x + u / 16;
    }
    label_count = static_cast<std::uint32_t>(tiles_x * ((height + 15) / 16));
  }
  PinholeIntrinsics intrinsics;
  DepthImage depth;
  PointImage points;
  NormalImage normals;
  std::vector<std::uint32_t> labels;
  std::uint32_t label_count = 0;
};

const HostFrame& host_frame(int width) {
  static const HostFrame vga(640, 480), hd(1280, 720);
  return width == 640 ? vga : hd;
}

// The same inputs resident on one context's device; constructing it dispatches nothing.
struct Frame {
  Frame(const compute::Context& context, const HostFrame& host)
      : depth(compute::DeviceImage<std::uint16_t>::from_host(context, host.depth)),
        projector(context, host.intrinsics, geometry::DepthRange{}),
        points(compute::DeviceImage<Point4f>::from_host(context, host.points)),
        normals(compute::DeviceImage<Point4f>::from_host(context, host.normals)),
        labels(compute::Buffer<std::uint32_t>::from_host(context, host.labels)),
        label_count(host.label_count),
        reduction(context),
        moments(context) {
    pairs.source = &points.buffer();
    pairs.target = &points.buffer();
    pairs.target_normals = &normals.buffer();
    pairs.source_to_target = Eigen::Translation3d(0.01, 0.0, 0.0) * Eigen::Isometry3d::Identity();
    pairs.max_distance = 0.1;
  }

  compute::DeviceImage<std::uint16_t> depth;
  geometry::DepthBackprojector projector;
  compute::DeviceImage<Point4f> points, normals;
  compute::Buffer<std::uint32_t> labels;
  std::uint32_t label_count = 0;
  registration::IcpReduction reduction;
  geometry::SegmentMomentReducer moments;
  registration::Correspondences pairs;
};

using Operation = std::function<void(const compute::Context&, Frame&)>;

const std::vector<std::pair<std::string, Operation>>& operations() {
  static const std::vector<std::pair<std::string, Operation>> list = {
      {"backproject", [](const compute::Context&, Frame& f) { f.projector.run(f.depth, f.points); }},
      {"normals",
       [](const compute::Context& c, Frame& f) { geometry::estimate_normals(c, f.points, f.normals); }},
      {"icp_point_to_point_sums",
       [](const compute::Context&, Frame& f) {
         benchmark::DoNotOptimize(f.reduction.point_to_point(f.pairs, Eigen::Vector3d(0, 0, 2)));
       }},
      {"icp_point_to_plane_sums",
       [](const compute::Context&, Frame& f) {
         benchmark::DoNotOptimize(f.reduction.point_to_plane(f.pairs, Eigen::Vector3d(0, 0, 2)));
       }},
      {"segment_moments",
       [](const compute::Context&, Frame& f) {
         geometry::SegmentMomentParams params;
         params.label_count = f.label_count;
         params.origin = Eigen::Vector3f(0, 0, 2);
         benchmark::DoNotOptimize(f.moments.run(f.points.buffer(), f.labels, params));
       }},
  };
  return list;
}

void steady_state(benchmark::State& state, BackendKind backend, const Operation& operation, int width,
                  int height) {
  const compute::Context context(bench::context_options(backend));
  Frame frame(context, host_frame(width));
  operation(context, frame);  // warm-up: pipelines built, driver JIT done
  context.finish();
  for (auto _ : state) {
    operation(context, frame);
    context.finish();
  }
  state.SetItemsProcessed(state.iterations() * width * height);
  state.SetLabel(context.device_info().name);
}

void cold_start(benchmark::State& state, BackendKind backend, const Operation& operation, int width,
                int height) {
  state.SetItemsProcessed(static_cast<std::int64_t>(width) * height);
  const compute::ContextParams options = bench::context_options(backend);
  for (auto _ : state) {
    state.PauseTiming();
    auto context = std::make_unique<compute::Context>(options);
    auto frame = std::make_unique<Frame>(*context, host_frame(width));
    context->finish();
    state.ResumeTiming();
    operation(*context, *frame);
    context->finish();
    state.PauseTiming();
    frame.reset();
    context.reset();
    state.ResumeTiming();
  }
}

void register_benchmarks() {
  for (const BackendKind backend : bench::backends_to_run()) {
    for (const auto& [name, operation] : operations()) {
      for (auto [width, height] : {std::pair{640, 480}, std::pair{1280, 720}}) {
        const std::string prefix =
            bench::case_name(name, backend, std::to_string(width) + "x" + std::to_string(height));
        bench::repeated(benchmark::RegisterBenchmark((prefix + "/steady").c_str(), steady_state,
                                                     backend, operation, width, height),
                        5)
            ->MinTime(0.2);
        bench::repeated(benchmark::RegisterBenchmark((prefix + "/cold").c_str(), cold_start,
                                                     backend, operation, width, height),
                        3)
            ->Iterations(1);
      }
    }
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_benchmarks);
}
