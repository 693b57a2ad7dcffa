// The 3-D ESDF (mapping/esdf_volume.hpp, kernels/esdf/esdf3.h) on every backend: against a brute
// force of its rule on random fields, incremental updates against one update of the final field
// (a moving object, a camera that leaves the grid), a replaced block set, real 7-Scenes frames
// against the CPU backend, and bad inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/mapping/esdf_volume.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "test_support.hpp"
#include "tsdf_scene.hpp"

namespace kartograf {
namespace {

using mapping::EsdfGrid;
using mapping::EsdfVolume;
using mapping::EsdfVolumeParams;
using mapping::TsdfBlocks;
using mapping::TsdfVolume;
using mapping::TsdfVolumeParams;
using mapping::TsdfVoxel;
using tsdf_scene::depth_range;
using tsdf_scene::kCamera;
using tsdf_scene::pose_at;
using tsdf_scene::render;
using tsdf_scene::Scene;
using tsdf_scene::volume_params;

// Random blocks in a 3x3x2 region (some absent), each voxel observed or not, near a surface or not.
TsdfBlocks random_blocks(const TsdfVolumeParams& params, double surface_share,
                         std::mt19937& random) {
  TsdfBlocks blocks;
  blocks.voxel_size = params.voxel_size;
  blocks.truncation = params.truncation;
  std::uniform_real_distribution<float> uniform(0, 1);
  for (int z = -1; z < 1; ++z) {
    for (int y = 0; y < 3; ++y) {
      for (int x = -2; x < 1; ++x) {
        if (uniform(random) < 0.3f) continue;
        blocks.coords.emplace_back(x, y, z);
        for (std::size_t i = 0; i < mapping::kTsdfBlockVoxels; ++i) {
          TsdfVoxel v;
          v.weight = std::floor(uniform(random) * 6);
          v.tsdf = uniform(random) < surface_share ? uniform(random) * 0.5f - 0.3f : 1.0f;
          blocks.voxels.push_back(v);
        }
      }
    }
  }
  return blocks;
}

// The rule by brute force: each cell's mark from its voxels, each distance from every marked cell.
EsdfGrid brute_force(const TsdfBlocks& blocks, const EsdfGrid& grid, int cell_voxels,
                     float min_weight) {
  EsdfGrid out = grid;
  std::fill(out.occupied.begin(), out.occupied.end(), 0);
  const float near = static_cast<float>(blocks.voxel_size / blocks.truncation);
  std::vector<Eigen::Vector3i> marked;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (std::size_t i = 0; i < mapping::kTsdfBlockVoxels; ++i) {
      const TsdfVoxel& v = blocks.voxels[b * mapping::kTsdfBlockVoxels + i];
      if (v.weight < min_weight || v.tsdf >= near) continue;
      const Eigen::Vector3i voxel =
          blocks.coords[b] * 8 + Eigen::Vector3i(int(i % 8), int(i / 8 % 8), int(i / 64));
      const Eigen::Vector3i cell = (voxel.cast<double>() / cell_voxels).array().floor().cast<int>();
      const std::ptrdiff_t at = out.index(cell);
      EXPECT_GE(at, 0) << "a surface cell outside the grid";
      if (at >= 0 && !out.occupied[std::size_t(at)]) marked.push_back(cell);
      if (at >= 0) out.occupied[std::size_t(at)] = 1;
    }
  }
  for (int z = 0; z < grid.dims.z(); ++z) {
    for (int y = 0; y < grid.dims.y(); ++y) {
      for (int x = 0; x < grid.dims.x(); ++x) {
        const Eigen::Vector3i cell = grid.first_cell + Eigen::Vector3i(x, y, z);
        double best = grid.max_distance;
        for (const Eigen::Vector3i& m : marked)
          best = std::min(best, (m - cell).cast<double>().norm() * grid.resolution);
        out.distances[std::size_t(out.index(cell))] = static_cast<float>(best);
      }
    }
  }
  return out;
}

// The same marks, and distances within the device's square root (a few units in the last place).
void expect_same_field(const EsdfGrid& a, const EsdfGrid& b, const std::string& what) {
  ASSERT_EQ(a.dims, b.dims) << what;
  ASSERT_EQ(a.first_cell, b.first_cell) << what;
  std::size_t marks = 0, distances = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    marks += a.occupied[i] != b.occupied[i];
    distances += std::abs(a.distances[i] - b.distances[i]) > 2e-6f * b.distances[i];
  }
  EXPECT_EQ(marks, 0u) << what;
  EXPECT_EQ(distances, 0u) << what << ": of " << a.size();
}

class EsdfVolumeTest : public testing::BackendTest {};

TEST_P(EsdfVolumeTest, EqualsTheBruteForceRuleOnRandomFields) {
  std::mt19937 random(3);
  const TsdfVolumeParams tsdf = volume_params(0.02, 0.06);
  for (const int cell_voxels : {1, 2, 4, 8}) {
    for (const double share : {0.0, 0.003, 0.05}) {
      EsdfVolumeParams params;
      params.cell_voxels = cell_voxels;
      params.max_distance = 0.09 * cell_voxels;
      params.min_weight = 2;
      const TsdfBlocks blocks = random_blocks(tsdf, share, random);
      TsdfVolume volume(context(), tsdf);
      volume.assign(blocks);
      EsdfVolume esdf(context(), tsdf, params);
      const mapping::EsdfUpdate update = esdf.update(volume);
      EXPECT_EQ(update.changed_blocks, blocks.size());
      const EsdfGrid grid = esdf.download();
      const std::string what = std::to_string(cell_voxels) + " voxels a cell, " +
                               std::to_string(share) + " near a surface";
      ASSERT_GT(grid.size(), 0u) << what;
      expect_same_field(grid, brute_force(blocks, grid, cell_voxels, params.min_weight), what);
      // The grid's margin: no cell outside it has a distance below max_distance.
      EXPECT_EQ(grid.distance(Eigen::Vector3d(-40, 0, 0)), float(params.max_distance));
    }
  }
}

// A camera moving along the wall (the grid grows) while the sphere moves away (its old surface is
// carved): the ESDF updated after every frame equals one made in one update of the final field.
TEST_P(EsdfVolumeTest, IncrementalUpdatesGiveTheWholeFieldsTransform) {
  const TsdfVolumeParams tsdf = volume_params(0.02, 0.06);
  TsdfVolume volume(context(), tsdf);
  EsdfVolumeParams params;
  params.max_distance = 0.3;
  params.growth_m = 0.3;
  EsdfVolume incremental(context(), tsdf, params);
  Scene scene;
  std::size_t grew = 0, local = 0;
  for (int frame = 0; frame < 24; ++frame) {
    if (frame == 12) scene.sphere_centre.x() += 0.6;
    const Eigen::Isometry3d pose = pose_at(0.15 * (frame % 12), 0.0, frame % 3 * 5.0);
    volume.integrate(render(scene, pose), {}, kCamera, depth_range(), pose);
    const mapping::EsdfUpdate update = incremental.update(volume);
    EXPECT_GT(update.changed_blocks, 0u);
    grew += update.grew ? 1 : 0;
    local += update.cells_recomputed < update.grid_cells ? 1 : 0;
  }
  EXPECT_GE(grew, 2u);
  EXPECT_GE(local, 5u);
  EXPECT_EQ(incremental.update(volume).changed_blocks, 0u);
  EsdfVolume whole(context(), tsdf, params);
  whole.update(volume);
  const EsdfGrid a = incremental.download(), b = whole.download();
  // The incremental grid holds the other; beyond it, only max_distance.
  std::size_t outside = 0, differing = 0, occupied = 0;
  for (int z = 0; z < a.dims.z(); ++z) {
    for (int y = 0; y < a.dims.y(); ++y) {
      for (int x = 0; x < a.dims.x(); ++x) {
        const Eigen::Vector3i cell = a.first_cell + Eigen::Vector3i(x, y, z);
        const std::size_t i = std::size_t(a.index(cell));
        const std::ptrdiff_t j = b.index(cell);
        occupied += a.occupied[i];
        if (j < 0) {
          outside += a.distances[i] != float(params.max_distance) || a.occupied[i];
          continue;
        }
        differing += a.distances[i] != b.distances[std::size_t(j)] ||
                     a.occupied[i] != b.occupied[std::size_t(j)];
      }
    }
  }
  EXPECT_GT(occupied, 500u);
  EXPECT_EQ(outside, 0u);
  EXPECT_EQ(differing, 0u) << "of " << a.size();
}

TEST_P(EsdfVolumeTest, StartsAgainWhenTheBlockSetIsReplaced) {
  const TsdfVolumeParams tsdf = volume_params(0.04, 0.12);
  TsdfVolume volume(context(), tsdf);
  EsdfVolume esdf(context(), tsdf);
  const Scene scene;
  for (const double x : {0.0, 0.5, 1.0}) {
    volume.integrate(render(scene, pose_at(x, 0, 0)), {}, kCamera, depth_range(), pose_at(x, 0, 0));
  }
  esdf.update(volume);
  // The far part evicted: the field forgets it.
  TsdfBlocks kept = volume.download();
  kept.coords.resize(kept.size() / 2);
  kept.voxels.resize(kept.size() * mapping::kTsdfBlockVoxels);
  volume.assign(kept);
  const mapping::EsdfUpdate update = esdf.update(volume);
  EXPECT_TRUE(update.restarted);
  EXPECT_EQ(update.changed_blocks, kept.size());
  EsdfVolume fresh(context(), tsdf);
  fresh.update(volume);
  expect_same_field(esdf.download(), fresh.download(), "after assign");
  // Cleared and refused from more frames than before: still a restart.
  volume.clear();
  for (int k = 0; k < 4; ++k)
    volume.integrate(render(scene, pose_at(0, 0, 0)), {}, kCamera, depth_range(), pose_at(0, 0, 0));
  EXPECT_TRUE(esdf.update(volume).restarted);
  EsdfVolume again(context(), tsdf);
  again.update(volume);
  expect_same_field(esdf.download(), again.download(), "after clear");
}

// Real frames: the same blocks on this backend and on the CPU give the same field.
TEST_P(EsdfVolumeTest, EqualsTheCpuBackendOnSevenScenesFrames) {
  const std::unique_ptr<TsdfVolume> kitchen = tsdf_scene::kitchen_frames(context(), false);
  const TsdfBlocks blocks = kitchen->download();
  const compute::Context cpu = compute::Context::cpu();
  TsdfVolume on_cpu(cpu, kitchen->params());
  on_cpu.assign(blocks);
  EsdfVolumeParams params;
  params.min_weight = 1;
  EsdfVolume a(context(), kitchen->params(), params), b(cpu, kitchen->params(), params);
  a.update(*kitchen);
  b.update(on_cpu);
  const EsdfGrid grid = a.download();
  EXPECT_GT(std::count(grid.occupied.begin(), grid.occupied.end(), 1), 1000);
  EXPECT_GT(std::count_if(grid.distances.begin(), grid.distances.end(),
                          [&](float d) { return d > 0 && d < params.max_distance; }),
            10000);
  expect_same_field(grid, b.download(), "7-Scenes frames 0 and 10");
}

TEST_P(EsdfVolumeTest, BadInputsAreErrors) {
  const TsdfVolumeParams tsdf = volume_params(0.02, 0.06);
  const auto refused = [&](EsdfVolumeParams p, const char* field) {
    try {
      EsdfVolume esdf(context(), tsdf, p);
      ADD_FAILURE() << field << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  EsdfVolumeParams p;
  p.cell_voxels = 3;
  refused(p, "cell_voxels");
  p = {};
  p.max_distance = std::nan("");
  refused(p, "max_distance");
  p = {};
  p.max_cells = 0;
  refused(p, "max_cells");
  // Another voxel size, then a budget the field does not fit.
  TsdfVolume volume(context(), volume_params(0.04, 0.12));
  const Scene scene;
  volume.integrate(render(scene, pose_at(0, 0, 0)), {}, kCamera, depth_range(), pose_at(0, 0, 0));
  EsdfVolume other(context(), tsdf);
  EXPECT_THROW(other.update(volume), Error);
  p = {};
  p.max_cells = 1000;
  EsdfVolume small(context(), volume.params(), p);
  try {
    small.update(volume);
    ADD_FAILURE() << "a grid past max_cells accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("max_cells"), std::string::npos) << e.what();
  }
  EXPECT_EQ(small.download().size(), 0u);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(EsdfVolumeTest);

}  // namespace
}  // namespace kartograf
