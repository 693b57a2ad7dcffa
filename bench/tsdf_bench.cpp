// The TSDF's operations per 640x480 frame on every available backend (issue 24's benchmarks), on
// the first 40 frames of ../shared/data/7scenes_redkitchen at their ground-truth poses, at 1 and
// 5 cm voxels (truncation 4 voxels, depth up to 4 m: as bench/peer/tsdf_open3d.py runs Open3D's
// VoxelBlockGrid on the same frames):
//   tsdf_integrate/<backend>/<voxel>   one frame's upload, block allocation and integration
//                                      (frames 5-39, after 5 that build the volume)
//   tsdf_raycast/<backend>/<voxel>     depth and colour of the 40-frame volume from a frame's pose
//   tsdf_mesh/<backend>/<voxel>        download and marching cubes of that volume (host)
//   tsdf_mesh_device/<backend>/<voxel> the same mesh made on the device, joined on the host
//   tsdf_esdf/<backend>/<voxel>        its height-band occupancy and the grid's ESDF, both on the
//                                      device (the 7-Scenes world's z as up)
//   tsdf_esdf3d/<backend>/<voxel>      the 3-D ESDF's update after one more frame (frames 5-39; the
//                                      integration not timed): mapping/esdf_volume.hpp's defaults
//                                      (1 m, cells of 8 cm at 1 cm voxels and 5 cm at 5 cm)
//   tsdf_esdf3d_whole/<backend>/<voxel> the 3-D ESDF of the 40-frame volume made from nothing
// KARTOGRAF_DATA_DIR overrides the data folder; KARTOGRAF_BENCH_BACKENDS=cpu,... the backends.
// bench/peer/tsdf_side_by_side.sh runs this and Open3D in one go and prints the ratios.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/mapping/esdf_volume.hpp"
#include "kartograf/mapping/tsdf_mesh.hpp"
#include "kartograf/mapping/tsdf_slice.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "kartograf/pipeline/sequence_frame_source.hpp"

namespace kartograf {
namespace {

constexpr std::size_t kFrames = 40, kWarmUp = 5;

struct Frames {
  PinholeIntrinsics camera;
  geometry::DepthRange range;
  std::vector<registration::RgbdImages> images;
  std::vector<Eigen::Isometry3d> poses;
};

// The frames, read once; empty when the data set is missing.
const Frames& frames() {
  static const Frames loaded = [] {
    Frames f;
    const char* configured = std::getenv("KARTOGRAF_DATA_DIR");
    const std::filesystem::path folder =
        std::filesystem::path(configured && *configured ? configured : KARTOGRAF_DEFAULT_DATA_DIR) /
        "7scenes_redkitchen";
    if (!std::filesystem::exists(folder)) return f;
    const io::OpenedSequence opened = io::open_sequence(folder);
    const pipeline::SequenceFrameSource source(*opened.sequence, kFrames);
    f.camera = source.camera();
    f.range = {source.depth_units_per_metre(), 0.1, 4.0};
    for (std::size_t i = 0; i < source.size(); ++i) {
      f.images.push_back(source.frame(i));
      f.poses.push_back(*f.images.back().ground_truth);
    }
    return f;
  }();
  return loaded;
}

mapping::TsdfVolumeParams volume_params(double voxel) {
  mapping::TsdfVolumeParams params;
  params.voxel_size = voxel;
  params.truncation = 4 * voxel;
  return params;
}

// A volume of the first `count` frames.
std::unique_ptr<mapping::TsdfVolume> fused(const compute::Context& context, double voxel,
                                           std::size_t count) {
  const Frames& f = frames();
  auto volume = std::make_unique<mapping::TsdfVolume>(context, volume_params(voxel));
  for (std::size_t i = 0; i < count; ++i)
    volume->integrate(f.images[i].depth, f.images[i].color, f.camera, f.range, f.poses[i]);
  return volume;
}

enum class Operation { integrate, raycast, mesh, device_mesh, esdf, esdf3d, esdf3d_whole };

// The 3-D ESDF's update after each frame, the frame's integration not timed.
void run_esdf3d_updates(benchmark::State& state, mapping::TsdfVolume& volume) {
  const Frames& f = frames();
  mapping::EsdfVolume esdf(volume.context(), volume.params());
  esdf.update(volume);
  std::size_t k = kWarmUp;
  double recomputed = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const std::size_t i = k++ % kFrames;
    volume.integrate(f.images[i].depth, f.images[i].color, f.camera, f.range, f.poses[i]);
    state.ResumeTiming();
    const mapping::EsdfUpdate update = esdf.update(volume);
    recomputed += double(update.cells_recomputed) / double(update.grid_cells);
  }
  state.counters["grid_cells"] = double(esdf.dims().cast<double>().prod());
  state.counters["recomputed_share"] = recomputed / double(k - kWarmUp);
}

void run_case(benchmark::State& state, compute::BackendKind backend, Operation operation,
              double voxel) {
  const Frames& f = frames();
  if (f.images.size() < kFrames) {
    state.SkipWithError("no ../shared/data/7scenes_redkitchen (KARTOGRAF_DATA_DIR)");
    return;
  }
  const compute::Context context(bench::context_options(backend));
  const bool integrating = operation == Operation::integrate || operation == Operation::esdf3d;
  const std::unique_ptr<mapping::TsdfVolume> volume =
      fused(context, voxel, integrating ? kWarmUp : kFrames);
  if (operation == Operation::esdf3d) return run_esdf3d_updates(state, *volume);
  std::size_t k = kWarmUp, active = 0;
  for (auto _ : state) {
    const std::size_t i = k++ % kFrames;
    if (operation == Operation::integrate) {
      active +=
          volume->integrate(f.images[i].depth, f.images[i].color, f.camera, f.range, f.poses[i])
              .active_blocks;
    } else if (operation == Operation::raycast) {
      benchmark::DoNotOptimize(volume->raycast(f.camera, f.range, f.poses[i]));
    } else if (operation == Operation::mesh) {
      benchmark::DoNotOptimize(mapping::extract_mesh(volume->download()));
    } else if (operation == Operation::device_mesh) {
      benchmark::DoNotOptimize(mapping::extract_mesh(*volume));
    } else if (operation == Operation::esdf) {
      benchmark::DoNotOptimize(mapping::tsdf_band_maps(*volume, {}));
    } else {
      mapping::EsdfVolume esdf(context, volume->params());
      benchmark::DoNotOptimize(esdf.update(*volume));
    }
  }
  state.counters["blocks"] = static_cast<double>(volume->block_count());
  if (operation == Operation::integrate)  // blocks a frame touches, mean
    state.counters["active"] = static_cast<double>(active) / static_cast<double>(k - kWarmUp);
}

void register_cases() {
  const std::pair<Operation, const char*> operations[] = {
      {Operation::integrate, "tsdf_integrate"},
      {Operation::raycast, "tsdf_raycast"},
      {Operation::mesh, "tsdf_mesh"},
      {Operation::device_mesh, "tsdf_mesh_device"},
      {Operation::esdf, "tsdf_esdf"},
      {Operation::esdf3d, "tsdf_esdf3d"},
      {Operation::esdf3d_whole, "tsdf_esdf3d_whole"}};
  for (const compute::BackendKind backend : bench::backends_to_run()) {
    for (const double voxel : {0.01, 0.05}) {
      for (const auto& [operation, name] : operations) {
        const std::string size = voxel == 0.01 ? "640x480_1cm" : "640x480_5cm";
        const bool per_frame = operation == Operation::integrate || operation == Operation::esdf3d;
        const int iterations = per_frame ? int(kFrames - kWarmUp) : 10;
        benchmark::RegisterBenchmark(bench::case_name(name, backend, size).c_str(), run_case,
                                     backend, operation, voxel)
            ->Iterations(iterations)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
    }
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_cases);
}
