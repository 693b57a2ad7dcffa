// The TSDF's reconstruction of the synthetic world, whose surfaces are exact (issue 24's accuracy
// line on a few frames): rendered at the ground-truth poses with and without the Kinect noise
// model, fused at 1 cm voxels, meshed and scored (bench/tsdf_accuracy.cpp runs whole tours).
#include <gtest/gtest.h>

#include <cmath>
#include <unordered_map>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/eval/mesh_metrics.hpp"
#include "kartograf/mapping/tsdf_mesh.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "kartograf/synth/world.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

struct Reconstruction {
  eval::MeshAccuracy accuracy;
  double completeness = 0;
};

// Exact depth over the sensor's range: the noise model's range without its noise.
synth::NoiseModel exact_sensor() {
  synth::NoiseModel n = synth::NoiseModel::none();
  n.min_range = synth::NoiseModel{}.min_range;
  n.max_range = synth::NoiseModel{}.max_range;
  return n;
}

Reconstruction reconstruct(const synth::World& world, bool noise) {
  const PinholeIntrinsics camera{320, 240, 262.5, 262.5, 159.5, 119.5};
  const geometry::DepthRange range{5000.0, 0.3, 4.0};
  const Trajectory tour = synth::robot_tour(world, synth::tour_frames_needed(world));
  mapping::TsdfVolumeParams params;  // 1 cm voxels, 4 cm truncation
  params.max_blocks = 1 << 16;
  const compute::Context cpu = compute::Context::cpu();  // outlives the volume
  mapping::TsdfVolume volume(cpu, params);
  std::unordered_map<std::int64_t, Eigen::Vector3d> seen;  // one true point per 2 cm voxel
  for (std::size_t i = 0; i < 60 && i < tour.size(); i += 6) {
    const Eigen::Isometry3d& pose = tour[i].pose;
    const synth::SyntheticFrame exact = synth::render(world, camera, pose, exact_sensor(), i);
    const synth::SyntheticFrame sensed =
        noise ? synth::render(world, camera, pose, synth::NoiseModel{}, i) : exact;
    volume.integrate(sensed.depth, sensed.color, camera, range, pose);
    for (int v = 0; v < camera.height; v += 3) {
      for (int u = 0; u < camera.width; u += 3) {
        const double z = exact.depth_metres(u, v);
        if (!std::isfinite(z) || z < range.min_metres || z > range.max_metres) continue;
        const Eigen::Vector3d p = pose * Eigen::Vector3d((u - camera.cx) / camera.fx * z,
                                                         (v - camera.cy) / camera.fy * z, z);
        const Eigen::Array3i c = (p / 0.02).array().floor().cast<int>() + 4096;
        seen.try_emplace(c.x() + 8192LL * (c.y() + 8192LL * c.z()), p);
      }
    }
  }
  const TriangleMesh mesh = mapping::extract_mesh(volume.download());
  std::vector<Eigen::Vector3d> truth;
  for (const auto& [key, p] : seen) truth.push_back(p);
  return {
      eval::mesh_accuracy(
          mesh, [&](const Eigen::Vector3d& p) { return synth::distance_to_surfaces(world, p); }),
      eval::mesh_completeness(mesh, truth, 0.02)};
}

TEST(TsdfSyntheticWorld, MeshLiesOnTheTrueSurfacesAndCoversWhatWasSeen) {
  const synth::World world = synth::make_building(3);
  const Reconstruction exact = reconstruct(world, false);
  const Reconstruction noisy = reconstruct(world, true);
  RecordProperty("exact_mean_mm", testing::scientific(1000 * exact.accuracy.mean_m));
  RecordProperty("exact_completeness", testing::scientific(exact.completeness));
  RecordProperty("noisy_mean_mm", testing::scientific(1000 * noisy.accuracy.mean_m));
  RecordProperty("noisy_completeness", testing::scientific(noisy.completeness));
  ASSERT_GT(exact.accuracy.vertices, 10000u);
  // The bounds: 5 mm without noise, 12 mm with it; 95 % of the seen surface within 2 cm.
  EXPECT_LT(exact.accuracy.mean_m, 0.005);
  EXPECT_LT(noisy.accuracy.mean_m, 0.012);
  EXPECT_GE(exact.completeness, 0.95);
  EXPECT_GE(noisy.completeness, 0.95);
}

TEST(TsdfSyntheticWorld, DistanceToSurfacesIsExactOnKnownPoints) {
  const synth::World world = synth::make_building(3);
  const auto [open, yaw] = synth::most_open_point(world, 1);
  // 2 cm above the floor where nothing stands.
  EXPECT_NEAR(synth::distance_to_surfaces(world, {open.x(), open.y(), 0.02}), 0.02, 1e-12);
  // 3 mm above the middle of a piece of furniture's top.
  ASSERT_FALSE(world.furniture.empty());
  double top = 0;
  for (int s : world.furniture.front().solids) top = std::max(top, world.solids[s].box.max.z());
  const Eigen::Vector2d middle =
      0.5 * (world.furniture.front().footprint.min + world.furniture.front().footprint.max);
  EXPECT_NEAR(synth::distance_to_surfaces(world, {middle.x(), middle.y(), top + 0.003}), 0.003,
              1e-9);
}

}  // namespace
}  // namespace kartograf
