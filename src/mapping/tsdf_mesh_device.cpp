// The TSDF's mesh on its device (kernels/tsdf/tsdf_mesh.h), joined on the host.
#include <algorithm>
#include <array>
#include <cstdlib>
#include <numeric>
#include <string>
#include <vector>

#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"
#include "kartograf/core/sort_order.hpp"
#include "kartograf/mapping/tsdf_mesh.hpp"
#include "kernels/tsdf/tsdf_mesh.h"
#include "mapping/edge_index.hpp"

namespace kartograf::mapping {

namespace {

constexpr compute::KernelSpec kMeshKernel{"tsdf_mesh", KG_TSDF_LOCAL_X, 1};

// What the cells appended: per triangle its order key, its vertices' edge keys, points and colours.
struct DeviceTriangles {
  std::vector<std::uint32_t> order;
  std::vector<std::uint64_t> edge_keys;
  std::vector<float> points;
  std::vector<std::uint32_t> colors;
};

// Runs the cells with room for `capacity` triangles; returns how many they made (more than the
// capacity: nothing downloaded, run again with room).
std::size_t run_cells(const TsdfVolume& volume, kernels::TsdfMeshParams p, std::size_t capacity,
                      DeviceTriangles& out) {
  const compute::Context& context = volume.context();
  // Per triangle: its order key, 3 edge keys, 9 coordinates and 3 colours, on the device and
  // again on the host.
  require_fits_in_memory(2.0 * static_cast<double>(capacity) * (4 + 24 + 36 + 12),
                         "the device mesh's " + std::to_string(capacity) + " triangles");
  auto status = compute::Buffer<std::uint32_t>::from_host(context, std::vector<std::uint32_t>{0});
  compute::Buffer<std::uint32_t> order(context, capacity), colors(context, 3 * capacity);
  compute::Buffer<std::uint64_t> edge_keys(context, 3 * capacity);
  compute::Buffer<float> points(context, 9 * capacity);
  p.capacity = static_cast<std::uint32_t>(capacity);
  compute::dispatch(
      context, kMeshKernel,
      {volume.device_table_keys(), volume.device_table_blocks(), volume.device_block_keys(),
       volume.device_voxels(), status, order, edge_keys, points, colors},
      p, {compute::groups_for(p.count, KG_TSDF_LOCAL_X), 1});
  const std::size_t made = status.to_vector()[0];
  if (made > capacity) return made;
  // Only what the cells wrote crosses to the host.
  const auto first = [made](const auto& buffer, std::size_t per) {
    decltype(buffer.to_vector()) values(made * per);
    buffer.download(values);
    return values;
  };
  out = {first(order, 1), first(edge_keys, 3), first(points, 9), first(colors, 3)};
  return made;
}

// The host mesher's order: blocks by key, cells x fastest, triangles as each cell made them.
std::vector<std::size_t> host_order(const TsdfVolume& volume, std::size_t blocks,
                                    const std::vector<std::uint32_t>& order) {
  std::vector<std::uint64_t> keys(blocks);
  volume.device_block_keys().download(keys);
  const int limit = KG_TSDF_MESH_VOXEL_BIAS / kTsdfBlockSide - 1;
  for (const std::uint64_t key : keys) {
    for (const unsigned shift : {0u, 21u, 42u})
      require(std::abs(kernels::tsdf_key_axis(key, shift)) < limit,
              "mesh extraction: a block lies beyond 2^19 voxels from the origin");
  }
  const std::vector<std::size_t> by_key = ascending_order(std::span<const std::uint64_t>(keys));
  std::vector<std::uint32_t> rank(blocks);
  for (std::uint32_t r = 0; r < blocks; ++r) rank[by_key[r]] = r;
  std::vector<std::uint64_t> sort_keys(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::uint32_t cell = order[i] / 16, k = order[i] % 16;
    sort_keys[i] =
        ((std::uint64_t{rank[cell / kTsdfBlockVoxels]} * kTsdfBlockVoxels + cell % kTsdfBlockVoxels)
         << 4) |
        k;
  }
  return ascending_order(std::span<const std::uint64_t>(sort_keys));
}

}  // namespace

TriangleMesh extract_mesh(const TsdfVolume& volume, const MeshParams& params) {
  const std::size_t blocks = std::min(volume.block_count(), volume.params().max_blocks);
  TriangleMesh mesh;
  if (blocks == 0) return mesh;
  // A triangle's order key is cell x 16 + its number in the cell, in 32 bits.
  require(blocks < (std::size_t{1} << 19),
          "mesh extraction on the device: more than 2^19 blocks; use the host's on a download");
  kernels::TsdfMeshParams p{};
  p.capacity_log2 = volume.table_log2();
  p.count = static_cast<std::uint32_t>(blocks * kTsdfBlockVoxels);
  p.voxel_size = static_cast<float>(volume.params().voxel_size);
  p.min_weight = params.min_weight;
  p.max_jump = params.max_jump;
  DeviceTriangles found;
  // A guess of room; a second run when the cells made more.
  const std::size_t made = run_cells(volume, p, blocks * 64, found);
  if (made > blocks * 64) run_cells(volume, p, made, found);
  detail::EdgeIndex edges;
  for (const std::size_t t : host_order(volume, blocks, found.order)) {
    std::array<int, 3> v{};
    for (std::size_t i = 0; i < 3; ++i) {
      bool inserted = false;
      v[i] = edges.find_or_add(found.edge_keys[3 * t + i], static_cast<int>(mesh.vertices.size()),
                               inserted);
      if (!inserted) continue;
      const float* point = &found.points[9 * t + 3 * i];
      mesh.vertices.emplace_back(point[0], point[1], point[2]);
      mesh.colors.push_back(found.colors[3 * t + i]);
    }
    mesh.triangles.emplace_back(v[0], v[1], v[2]);
  }
  return mesh;
}

}  // namespace kartograf::mapping
