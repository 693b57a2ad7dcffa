#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/ply.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "output_transaction.hpp"

namespace kartograf::cli {

namespace {

constexpr double kUnitsPerMetre = synth::kTumDepthUnitsPerMetre;
constexpr double kMaxMetres = 10.0;

// The demo's input: one frame of the default synthetic world (seed 1), seen by a Kinect-like
// sensor from the robot tour inside the first room.
struct DemoFrame {
  PinholeIntrinsics intrinsics;
  DepthImage depth;  // 5000 units per metre
};

DemoFrame render_demo_frame() {
  constexpr std::uint64_t kSeed = 1;
  constexpr int kTourFrames = 300, kFrame = 20;
  const synth::World world = synth::make_building(kSeed);
  const Trajectory tour = synth::robot_tour(world, kTourFrames);
  DemoFrame frame;
  frame.intrinsics = {640, 480, 525.0, 525.0, 319.5, 239.5};
  frame.depth =
      synth::render(world, frame.intrinsics, tour[kFrame].pose, synth::NoiseModel::kinect(), kSeed)
          .depth;
  return frame;
}

// Wall-clock durations of the demo's stages, in the order they ran.
class StageTimer {
 public:
  template <class Work>
  auto time(std::string name, Work&& work) {
    const auto start = std::chrono::steady_clock::now();
    if constexpr (std::is_void_v<decltype(work())>) {
      work();
      record(std::move(name), start);
    } else {
      auto result = work();
      record(std::move(name), start);
      return result;
    }
  }

  void print(std::ostream& out) const {
    out << "timings (ms):\n" << std::fixed << std::setprecision(2);
    for (const auto& [name, ms] : stages_) {
      out << "  " << std::left << std::setw(18) << name << std::right << std::setw(10) << ms
          << "\n";
    }
  }

 private:
  void record(std::string name, std::chrono::steady_clock::time_point start) {
    const std::chrono::duration<double, std::milli> elapsed =
        std::chrono::steady_clock::now() - start;
    stages_.emplace_back(std::move(name), elapsed.count());
  }
  std::vector<std::pair<std::string, double>> stages_;
};

std::size_t count_valid(const Image<Point4f>& image) {
  std::size_t valid = 0;
  for (const Point4f& p : image.pixels()) valid += p.head<3>().allFinite() ? 1 : 0;
  return valid;
}

std::string percent_of(std::size_t part, std::size_t whole) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(1) << (whole ? 100.0 * part / whole : 0.0) << "%";
  return text.str();
}

}  // namespace

int run_demo_command(const DemoOptions& options, std::ostream& out) {
  compute::ContextParams context_options = compute::ContextParams::from_environment();
  context_options.backend = compute::parse_backend_choice(options.backend, options.backend_source);
  OutputFolder folder("demo", options.out_dir, options.force,
                      {"depth.png", "depth_color.png", "normals.png", "cloud.ply"});

  out << "backends:\n";
  print_backend_summary(out, compute::probe_backends());

  StageTimer timer;
  const DemoFrame frame = timer.time("synthesize", [] { return render_demo_frame(); });
  const PinholeIntrinsics& intrinsics = frame.intrinsics;
  out << "input: synthetic world (seed 1, Kinect noise), " << intrinsics.width << "x"
      << intrinsics.height << " depth in 1/5000 m, fx=fy=" << intrinsics.fx << "\n";

  compute::Context context =
      timer.time("context", [&] { return compute::Context(context_options); });
  out << "using backend " << compute::to_string(context.backend()) << " (requested "
      << compute::to_string(context_options.backend) << "): " << context.device_info().name << "\n";
  // Kernel compilation is a one-time cost; kept out of the per-frame stages below.
  timer.time("kernels", [&] { context.build_all_kernels(); });

  const geometry::DepthBackprojector projector(
      context, intrinsics, geometry::DepthRange{kUnitsPerMetre, 0.1, kMaxMetres});
  compute::DeviceImage<Point4f> device_points(context, intrinsics.width, intrinsics.height);
  compute::DeviceImage<Point4f> device_normals(context, intrinsics.width, intrinsics.height);
  // Each stage ends with finish() so that its time is its own, not the next stage's.
  const auto device_depth = timer.time("upload", [&] {
    auto depth = compute::DeviceImage<std::uint16_t>::from_host(context, frame.depth);
    context.finish();
    return depth;
  });
  timer.time("backproject", [&] {
    projector.run(device_depth, device_points);
    context.finish();
  });
  timer.time("normals", [&] {
    geometry::estimate_normals(context, device_points, device_normals);
    context.finish();
  });
  const PointImage points = timer.time("download points", [&] { return device_points.to_image(); });
  const NormalImage normals =
      timer.time("download normals", [&] { return device_normals.to_image(); });

  // The colormap spans the frame's own depths, not the 10 m valid range: more contrast.
  const auto depths = frame.depth.pixels();
  const double colormap_max_metres =
      std::max<double>(1, *std::max_element(depths.begin(), depths.end())) / kUnitsPerMetre;

  const std::filesystem::path& dir = folder.dir();
  const std::vector<std::string> written = timer.time("write", [&] {
    const InterruptsDeferred writing;  // a signal waits for the files, then drops them
    io::write_png(dir / "depth.png", frame.depth);
    io::write_png(dir / "depth_color.png",
                  io::colorize_depth(frame.depth, kUnitsPerMetre, colormap_max_metres));
    io::write_png(dir / "normals.png", io::colorize_normals(normals));
    io::write_ply(dir / "cloud.ply", points, &normals);
    folder.commit();
    return std::vector<std::string>{"depth.png", "depth_color.png", "normals.png", "cloud.ply"};
  });

  const std::size_t pixels = points.size();
  const std::size_t valid_points = count_valid(points);
  const std::size_t valid_normals = count_valid(normals);
  out << "valid points:  " << valid_points << " of " << pixels << " ("
      << percent_of(valid_points, pixels) << ")\n"
      << "valid normals: " << valid_normals << " of " << pixels << " ("
      << percent_of(valid_normals, pixels) << ")\n";
  timer.print(out);
  out << "wrote:\n";
  for (const auto& name : written) out << "  " << (options.out_dir / name).string() << "\n";
  return 0;
}

}  // namespace kartograf::cli
