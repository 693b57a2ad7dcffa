// Reconstruction accuracy of the TSDF volume on the synthetic world, whose geometry is exact
// (issue 24's first acceptance line): the survey tour of a building is rendered (with or without
// the Kinect noise model), fused at the ground-truth poses, and meshed; then
//   accuracy      the mean (and 90th percentile) distance of mesh vertices to the world's surfaces
//   completeness  the fraction of the surface the views saw (noise-free, within the fusion's depth
//                 range, one sample per 1 cm voxel) that has a mesh vertex within 2 cm.
// Usage: kartograf_tsdf_accuracy [--seed N] [--noise] [--step K] [--voxel M] [--frames N]
//                                [--touch-step P (0: automatic)]
//                                [--backend cpu|vulkan|opencl]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/eval/mesh_metrics.hpp"
#include "kartograf/mapping/tsdf_mesh.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "kartograf/synth/world.hpp"

namespace {

using namespace kartograf;

struct Options {
  std::uint64_t seed = 1;
  bool noise = false;
  int step = 1;
  int frames = 0;  // 0: the whole tour
  double voxel = 0.01;
  int touch_step = 0;
  std::string backend = "cpu";
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] {
      if (i + 1 >= argc) throw Error("missing value after " + a);
      return std::string(argv[++i]);
    };
    if (a == "--seed")
      o.seed = std::stoull(value());
    else if (a == "--noise")
      o.noise = true;
    else if (a == "--step")
      o.step = std::stoi(value());
    else if (a == "--frames")
      o.frames = std::stoi(value());
    else if (a == "--voxel")
      o.voxel = std::stod(value());
    else if (a == "--touch-step")
      o.touch_step = std::stoi(value());
    else if (a == "--backend")
      o.backend = value();
    else
      throw Error("unknown option " + a);
  }
  return o;
}

// One seen surface point per 1 cm voxel, from a noise-free frame's exact depth.
void add_seen_surface(const synth::SyntheticFrame& exact, const PinholeIntrinsics& k,
                      const Eigen::Isometry3d& pose, const geometry::DepthRange& range,
                      std::unordered_map<std::uint64_t, Eigen::Vector3d>& seen) {
  for (int v = 0; v < k.height; v += 2) {
    for (int u = 0; u < k.width; u += 2) {
      const double z = exact.depth_metres(u, v);
      if (!std::isfinite(z) || z < range.min_metres || z > range.max_metres) continue;
      const Eigen::Vector3d p =
          pose * Eigen::Vector3d((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
      const Eigen::Vector3i cell = (p / 0.01).array().floor().cast<int>() + (1 << 20);
      seen.try_emplace(static_cast<std::uint64_t>(cell.x()) |
                           static_cast<std::uint64_t>(cell.y()) << 21 |
                           static_cast<std::uint64_t>(cell.z()) << 42,
                       p);
    }
  }
}

int run(const Options& o) {
  const synth::World world = synth::make_building(o.seed);
  const int tour = synth::tour_frames_needed(world);
  const Trajectory trajectory = synth::robot_tour(world, tour);
  const PinholeIntrinsics camera{640, 480, 525.0, 525.0, 319.5, 239.5};
  const geometry::DepthRange range{5000.0, 0.3, 4.0};
  synth::NoiseModel noisy;
  // Exact depth over the sensor's range: the noise model's range without its noise.
  synth::NoiseModel exact_model = synth::NoiseModel::none();
  exact_model.min_range = noisy.min_range;
  exact_model.max_range = noisy.max_range;
  compute::ContextParams context_params;
  context_params.backend = compute::parse_backend_choice(o.backend, "--backend");
  const compute::Context context(context_params);
  mapping::TsdfVolumeParams params;
  params.voxel_size = o.voxel;
  params.truncation = 4 * o.voxel;
  params.touch_step = o.touch_step;
  params.max_blocks = std::size_t{1} << 18;
  mapping::TsdfVolume volume(context, params);
  std::unordered_map<std::uint64_t, Eigen::Vector3d> seen;
  double fuse_seconds = 0;
  int fused = 0;
  const int last = o.frames > 0 ? std::min(tour, o.frames) : tour;
  for (int i = 0; i < last; i += o.step) {
    const Eigen::Isometry3d& pose = trajectory[i].pose;
    const synth::SyntheticFrame exact = synth::render(world, camera, pose, exact_model, i);
    const synth::SyntheticFrame frame =
        o.noise ? synth::render(world, camera, pose, noisy, i) : exact;
    add_seen_surface(exact, camera, pose, range, seen);
    const auto start = std::chrono::steady_clock::now();
    volume.integrate(frame.depth, frame.color, camera, range, pose);
    context.finish();
    fuse_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++fused;
  }
  const auto start = std::chrono::steady_clock::now();
  const TriangleMesh mesh = mapping::extract_mesh(volume.download());
  const double mesh_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const eval::MeshAccuracy accuracy = eval::mesh_accuracy(
      mesh, [&](const Eigen::Vector3d& p) { return synth::distance_to_surfaces(world, p); });
  std::vector<Eigen::Vector3d> truth;
  truth.reserve(seen.size());
  for (const auto& [key, p] : seen) truth.push_back(p);
  std::printf("seed %llu noise %s voxel %.3f frames %d blocks %zu vertices %zu triangles %zu\n",
              static_cast<unsigned long long>(o.seed), o.noise ? "kinect" : "none", o.voxel, fused,
              volume.block_count(), mesh.vertices.size(), mesh.triangles.size());
  std::printf(
      "accuracy mean %.2f mm p90 %.2f mm (by area %.2f mm); completeness (2 cm) %.1f %% of %zu "
      "seen voxels\n",
      1000 * accuracy.mean_m, 1000 * accuracy.p90_m, 1000 * accuracy.area_mean_m,
      100 * eval::mesh_completeness(mesh, truth, 0.02), truth.size());
  std::printf("integration %.2f ms/frame (%s), meshing %.2f s\n", 1000 * fuse_seconds / fused,
              o.backend.c_str(), mesh_seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kartograf_tsdf_accuracy: %s\n", e.what());
    return 1;
  }
}
