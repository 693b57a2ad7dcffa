// Mesh extraction from a TSDF (mapping/tsdf_mesh.hpp) on fields written directly: a sphere's
// signed distance, and fields with holes and jumps.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <utility>

#include "kartograf/mapping/tsdf_mesh.hpp"

namespace kartograf {
namespace {

using mapping::kTsdfBlockSide;
using mapping::kTsdfBlockVoxels;
using mapping::TsdfBlocks;
using mapping::TsdfVoxel;

// The truncated signed distance of a sphere, in every block of a cube of blocks around it.
TsdfBlocks sphere_field(const Eigen::Vector3d& centre, double radius, double voxel,
                        double truncation, int blocks_each_way) {
  TsdfBlocks field;
  field.voxel_size = voxel;
  field.truncation = truncation;
  for (int z = -blocks_each_way; z < blocks_each_way; ++z)
    for (int y = -blocks_each_way; y < blocks_each_way; ++y)
      for (int x = -blocks_each_way; x < blocks_each_way; ++x) {
        field.coords.emplace_back(x, y, z);
        for (std::size_t i = 0; i < kTsdfBlockVoxels; ++i) {
          const Eigen::Vector3i v = Eigen::Vector3i(x, y, z) * kTsdfBlockSide +
                                    Eigen::Vector3i(int(i % 8), int(i / 8 % 8), int(i / 64));
          const Eigen::Vector3d p = (v.cast<double>().array() + 0.5) * voxel;
          const double d = ((p - centre).norm() - radius) / truncation;
          field.voxels.push_back({float(std::clamp(d, -1.0, 1.0)), 1.0f, 0x204080u});
        }
      }
  return field;
}

TEST(TsdfMesh, SphereIsClosedOnTheSurfaceAndFacesOut) {
  const Eigen::Vector3d centre(0.013, -0.021, 0.007);
  const double radius = 0.3;
  const TsdfBlocks field = sphere_field(centre, radius, 0.01, 0.04, 5);
  const TriangleMesh mesh = mapping::extract_mesh(field);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  double worst = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    worst = std::max(worst, std::abs((v.cast<double>() - centre).norm() - radius));
  }
  // Linear interpolation of a distance field that is linear along rays: well under a millimetre.
  EXPECT_LT(worst, 5e-4);
  std::map<std::pair<int, int>, int> edge_uses;
  std::size_t facing_out = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++edge_uses[{std::min(a, b), std::max(a, b)}];
    }
    const Eigen::Vector3f& p = mesh.vertices[t[0]];
    const Eigen::Vector3f n = (mesh.vertices[t[1]] - p).cross(mesh.vertices[t[2]] - p);
    if (n.dot(p - centre.cast<float>()) > 0) ++facing_out;
  }
  for (const auto& [edge, uses] : edge_uses) ASSERT_EQ(uses, 2) << edge.first << "-" << edge.second;
  EXPECT_EQ(facing_out, mesh.triangles.size());
  EXPECT_EQ(mesh.colors.size(), mesh.vertices.size());
  EXPECT_EQ(mesh.colors.front(), 0x204080u);
}

// Marching cubes' cases on random fields: every sign pattern a cell can have turns up, and the
// surface must still be closed and consistently oriented: each edge run as often one way as the
// other (by two triangles, or four where two cells' fans meet on an ambiguous face they share).
// A field whose outer voxels are all outside closes every surface.
TEST(TsdfMesh, RandomFieldsGiveClosedConsistentlyOrientedSurfaces) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> value(-0.9f, 0.9f);
  for (int trial = 0; trial < 4; ++trial) {
    TsdfBlocks field = sphere_field({0, 0, 0}, 0.1, 0.01, 0.04, 1);  // 16^3 voxels
    for (std::size_t b = 0; b < field.size(); ++b)
      for (std::size_t i = 0; i < kTsdfBlockVoxels; ++i) {
        const Eigen::Vector3i v = field.coords[b] * kTsdfBlockSide +
                                  Eigen::Vector3i(int(i % 8), int(i / 8 % 8), int(i / 64));
        const bool border = (v.array() == -8).any() || (v.array() == 7).any();
        field.voxels[b * kTsdfBlockVoxels + i].tsdf = border ? 0.9f : value(random);
      }
    const TriangleMesh mesh = mapping::extract_mesh(field);
    ASSERT_GT(mesh.triangles.size(), 1000u);
    std::map<std::pair<int, int>, int> directed;
    for (const Eigen::Vector3i& t : mesh.triangles)
      for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    std::size_t shared_on_faces = 0;
    for (const auto& [edge, uses] : directed) {
      const auto back = directed.find({edge.second, edge.first});
      ASSERT_TRUE(back != directed.end() && back->second == uses)
          << "trial " << trial << ": edge " << edge.first << "-" << edge.second << " is open";
      ASSERT_LE(uses, 2);
      shared_on_faces += uses == 2;
    }
    RecordProperty("edges_shared_on_faces_" + std::to_string(trial), int(shared_on_faces));
    EXPECT_LT(shared_on_faces, directed.size() / 100);
  }
}

TEST(TsdfMesh, UnobservedCornersAndJumpsMakeNoSurface) {
  TsdfBlocks field = sphere_field({0, 0, 0}, 0.3, 0.01, 0.04, 5);
  const std::size_t full = mapping::extract_mesh(field).triangles.size();
  // Forget every voxel with x < 0: half of the sphere goes.
  for (std::size_t b = 0; b < field.size(); ++b) {
    if (field.coords[b].x() >= 0) continue;
    for (std::size_t i = 0; i < kTsdfBlockVoxels; ++i)
      field.voxels[b * kTsdfBlockVoxels + i].weight = 0;
  }
  const std::size_t half = mapping::extract_mesh(field).triangles.size();
  EXPECT_NEAR(double(half), full / 2.0, full * 0.05);
  // A field that jumps from +1 to -1 (one view's free space against another's back side).
  TsdfBlocks jump;
  jump.voxel_size = 0.01;
  jump.truncation = 0.04;
  jump.coords.emplace_back(0, 0, 0);
  for (std::size_t i = 0; i < kTsdfBlockVoxels; ++i) {
    jump.voxels.push_back({i % 8 < 4 ? 1.0f : -1.0f, 1.0f, 0});
  }
  EXPECT_TRUE(mapping::extract_mesh(jump).triangles.empty());
  jump.voxels.pop_back();
  EXPECT_THROW(mapping::extract_mesh(jump), Error);
}

}  // namespace
}  // namespace kartograf

#include "kartograf/mapping/tsdf_slice.hpp"

namespace kartograf {
namespace {

// A floor (z = 0) over 2 m x 2 m with a box 0.4 x 0.4 x 0.8 m standing at (1, 1): the truncated
// signed distance of their union, every voxel observed.
TsdfBlocks floor_and_box() {
  TsdfBlocks field;
  field.voxel_size = 0.02;
  field.truncation = 0.08;
  const auto box_distance = [](const Eigen::Vector3d& p) {
    const Eigen::Vector3d lo(0.8, 0.8, 0), hi(1.2, 1.2, 0.8);
    const Eigen::Vector3d out = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
    return out.squaredNorm() > 0 ? out.norm() : -std::min((p - lo).minCoeff(), (hi - p).minCoeff());
  };
  for (int z = -1; z < 6; ++z)
    for (int y = 0; y < 13; ++y)
      for (int x = 0; x < 13; ++x) {
        field.coords.emplace_back(x, y, z);
        for (std::size_t i = 0; i < kTsdfBlockVoxels; ++i) {
          const Eigen::Vector3i v = Eigen::Vector3i(x, y, z) * kTsdfBlockSide +
                                    Eigen::Vector3i(int(i % 8), int(i / 8 % 8), int(i / 64));
          const Eigen::Vector3d p = (v.cast<double>().array() + 0.5) * field.voxel_size;
          const double d = std::min(p.z(), box_distance(p)) / field.truncation;
          field.voxels.push_back({float(std::clamp(d, -1.0, 1.0)), 4.0f, 0});  // seen 4 times
        }
      }
  return field;
}

TEST(TsdfSlice, TheBoxIsOccupiedTheFloorFreeAndTheEsdfMeasuresTheGap) {
  mapping::TsdfSliceParams params;
  params.resolution = 0.05;
  const OccupancyGrid grid = mapping::tsdf_occupancy(floor_and_box(), params);
  ASSERT_GT(grid.width(), 30);
  const auto state_at = [&](double x, double y) {
    const Eigen::Vector2i c = grid.cell_of({x, y});
    return grid.cells(c.x(), c.y());
  };
  EXPECT_EQ(state_at(1.0, 1.0), CellState::occupied);  // the box's middle (its top and sides)
  EXPECT_EQ(state_at(1.19, 0.81), CellState::occupied);
  EXPECT_EQ(state_at(0.3, 0.3), CellState::free);
  EXPECT_EQ(state_at(1.7, 1.0), CellState::free);
  const Image<float> esdf = mapping::occupancy_esdf(grid);
  const Eigen::Vector2i far = grid.cell_of({1.7, 1.0});
  // 0.5 m from the box's face, to within a cell.
  EXPECT_NEAR(esdf(far.x(), far.y()), 0.5, 0.05);
  const Eigen::Vector2i middle = grid.cell_of({1.0, 1.0});
  EXPECT_LT(esdf(middle.x(), middle.y()), -0.1);  // inside: negative
  mapping::TsdfSliceParams bad;
  bad.band_min = 2;
  EXPECT_THROW(mapping::tsdf_occupancy(floor_and_box(), bad), Error);
}

}  // namespace
}  // namespace kartograf
