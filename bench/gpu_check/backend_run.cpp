#include "backend_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "frame_ops.hpp"
#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/registration/odometry.hpp"
#include "kartograf/rooms/laser_scan_device.hpp"

namespace kartograf::gpu_check {

Inputs load_inputs(const std::filesystem::path& data_dir, int frames) {
  Inputs inputs;
  inputs.vga = seven_scenes(data_dir, frames);
  inputs.hd = enlarged(inputs.vga, 1280, 720);
  inputs.random = random_frames(inputs.vga.camera, 4, 20261126);
  inputs.map = office_map(data_dir);
  return inputs;
}

compute::BackendKind to_backend_kind(const std::string& name) {
  for (compute::BackendKind kind :
       {compute::BackendKind::cpu, compute::BackendKind::vulkan, compute::BackendKind::opencl}) {
    if (compute::to_string(kind) == name) return kind;
  }
  throw Error("kartograf_gpu_check: unknown backend '" + name + "' (cpu, vulkan, opencl)");
}

namespace {

// Device-to-device copy of a large buffer: the bandwidth floor of the per-pixel kernels.
void measure_copy(const compute::Context& context, const Repetitions& repetitions,
                  BackendResult& result) {
  // Host memory is the CPU's working memory too: a smaller copy there.
  const bool host_memory = context.device_info().type == compute::DeviceType::cpu;
  const std::size_t bytes = (host_memory ? 64u : 512u) << 20;
  compute::RawBuffer source(context, bytes), target(context, bytes);
  source.fill_zero();
  const Samples samples = measure(context, repetitions, [&] { target.copy_from(source, bytes); });
  const double ms = samples.device_ms.empty() ? median(samples.wall_ms) : median(samples.device_ms);
  result.copy_buffer_mib = static_cast<double>(bytes >> 20);
  result.copy_gb_per_s = 2.0 * static_cast<double>(bytes) / (ms * 1e6);
}

OperationResult summarize(const Operation& op, const FrameSet& set, const Samples& samples) {
  OperationResult row;
  row.input = set.name;
  row.operation = op.name;
  row.width = set.camera.width;
  row.height = set.camera.height;
  row.wall_ms = median(samples.wall_ms);
  row.device_ms = median(samples.device_ms);
  row.bytes_per_pixel = op.bytes_per_pixel;
  for (const auto& [command, values] : samples.command_ms) row.command_ms[command] = median(values);
  return row;
}

bool per_pixel(const Operation& op) {
  return op.name == "backproject" || op.name == "normals" || op.name.rfind("pyramid", 0) == 0 ||
         op.name.rfind("backproject +", 0) == 0;
}

void measure_operations(const compute::Context& context, const Inputs& inputs,
                        const Repetitions& repetitions, Results& results, std::ostream& log) {
  for (const FrameSet* set : {&inputs.vga, &inputs.hd, &inputs.random}) {
    auto workspace = make_workspace(context, *set);
    for (const Operation& op : frame_operations()) {
      if (set == &inputs.random && !per_pixel(op)) continue;
      const Samples samples = measure(context, repetitions, [&] { op.call(*workspace); });
      OperationResult row = summarize(op, *set, samples);
      row.backend = std::string(compute::to_string(context.backend()));
      log << "  " << row.backend << " " << set->name << " " << op.name << ": " << row.wall_ms
          << " ms wall, " << row.device_ms << " ms device\n";
      results.operations.push_back(std::move(row));
    }
  }
}

// The feature-based room segmentation's ray casting: 360 beams from every 7th free cell of
// office_e.
void measure_laser_scan(const compute::Context& context, const OccupancyGrid& map,
                        const Repetitions& repetitions, Results& results, std::ostream& log) {
  const rooms::LaserScanner scanner(map);
  rooms::DeviceLaserScanner device(context, scanner);
  std::vector<rooms::ScanCell> cells;
  int free_seen = 0;
  for (int row = 0; row < map.height(); ++row) {
    for (int col = 0; col < map.width(); ++col) {
      if (map.cells(col, row) == CellState::free && free_seen++ % 7 == 0)
        cells.push_back({col, row});
    }
  }
  compute::Buffer<std::int32_t> steps;
  const Samples samples = measure(context, repetitions, [&] { device.scan_steps(cells, steps); });
  Operation op{
      "laser scan " + std::to_string((cells.size() + 500) / 1000) + "k cells x 360", 0, {}};
  FrameSet set;
  set.name = "office_e";
  set.camera.width = map.width();
  set.camera.height = map.height();
  OperationResult row = summarize(op, set, samples);
  row.backend = std::string(compute::to_string(context.backend()));
  log << "  " << row.backend << " office_e " << op.name << ": " << row.wall_ms << " ms wall, "
      << row.device_ms << " ms device\n";
  results.operations.push_back(std::move(row));
}

std::vector<Eigen::Isometry3d> track_sequence(const compute::Context& context, const FrameSet& set,
                                              SequenceResult* result) {
  registration::RgbdOdometry odometry(context, set.camera, registration::OdometryParams{});
  std::vector<double> wall, device;
  std::map<std::string, double> per_command;  // summed over the frames after the first
  context.take_device_timings();
  for (const RgbdFrame& frame : set.frames) {
    const auto start = std::chrono::steady_clock::now();
    odometry.track(frame.depth, &frame.color);
    context.finish();
    wall.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    double total = 0;
    for (const compute::DeviceTiming& timing : context.take_device_timings()) {
      total += timing.milliseconds;
      if (result && &frame != &set.frames.front())
        per_command[timing.command] += timing.milliseconds;
    }
    device.push_back(total);
  }
  if (result) {
    // The first frame only builds its pyramid: leave it out of the per-frame figures.
    result->frames = static_cast<int>(set.frames.size());
    result->wall_ms_per_frame = median({wall.begin() + 1, wall.end()});
    result->device_ms_per_frame = median({device.begin() + 1, device.end()});
    for (const auto& [command, ms] : per_command)
      result->command_ms_per_frame[command] = ms / static_cast<double>(set.frames.size() - 1);
  }
  return odometry.poses();
}

void compare(const std::vector<Eigen::Isometry3d>& poses,
             const std::vector<Eigen::Isometry3d>& reference, SequenceResult& result) {
  result.max_translation_difference_m = 0;
  result.max_rotation_difference_deg = 0;
  for (std::size_t i = 0; i < std::min(poses.size(), reference.size()); ++i) {
    const Eigen::Isometry3d difference = reference[i].inverse() * poses[i];
    result.max_translation_difference_m =
        std::max(result.max_translation_difference_m, difference.translation().norm());
    const double angle = Eigen::AngleAxisd(difference.rotation()).angle() * 180.0 / M_PI;
    result.max_rotation_difference_deg = std::max(result.max_rotation_difference_deg, angle);
  }
}

void measure_sequence(const compute::Context& context, const Inputs& inputs,
                      SequenceReference& reference, Results& results) {
  if (reference.poses.empty()) {
    reference.poses = track_sequence(compute::Context::cpu(), inputs.vga, nullptr);
  }
  SequenceResult row;
  row.backend = std::string(compute::to_string(context.backend()));
  row.input = inputs.vga.name;
  // One untimed pass first: a GPU that idled through the CPU rows is still raising its clocks
  // (run 7's Vulkan sequence took twice the device time of run 6's at 345 MHz).
  track_sequence(context, inputs.vga, nullptr);
  const std::vector<Eigen::Isometry3d> poses = track_sequence(context, inputs.vga, &row);
  compare(poses, reference.poses, row);
  results.sequences.push_back(row);
}

}  // namespace

bool run_backend(compute::BackendKind kind, const Inputs& inputs, const Repetitions& repetitions,
                 SequenceReference& reference, Results& results, std::ostream& log) {
  BackendResult backend;
  backend.backend = std::string(compute::to_string(kind));
  compute::ContextParams options;
  options.backend = compute::choice_of(kind);
  options.profile = true;
  std::unique_ptr<compute::Context> context;
  try {
    context = std::make_unique<compute::Context>(options);
  } catch (const Error& error) {
    backend.error = std::string("unavailable: ") + error.what();
    log << "== " << backend.backend << ": " << backend.error << "\n";
    results.backends.push_back(backend);
    return true;
  }
  const compute::DeviceInfo& info = context->device_info();
  backend.device = info.name;
  backend.driver = info.driver;
  backend.limits = compute::describe(info.limits);
  log << "== " << backend.backend << ": " << info.name << "\n";
  bool ok = true;
  try {
    context->build_all_kernels();
    measure_copy(*context, repetitions, backend);
    measure_operations(*context, inputs, repetitions, results, log);
    measure_laser_scan(*context, inputs.map, repetitions, results, log);
    measure_sequence(*context, inputs, reference, results);
  } catch (const Error& error) {
    backend.error = error.what();
    log << "== " << backend.backend << " FAILED: " << error.what() << "\n";
    ok = false;
  }
  results.backends.push_back(backend);
  return ok;
}

}  // namespace kartograf::gpu_check
