#include "kartograf/mapping/tsdf_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kernels/tsdf/tsdf_mesh.h"
#include "mapping/edge_index.hpp"

namespace kartograf::mapping {

namespace {

// Marching cubes' triangles of each case (kernels/tsdf/tsdf_mesh.h's rule), made once.
const std::array<std::uint64_t, 256>& marching_cubes_cases() {
  static const std::array<std::uint64_t, 256> cases = [] {
    std::array<std::uint64_t, 256> table{};
    for (unsigned inside = 0; inside < 256; ++inside)
      table[inside] = kernels::tsdf_mc_triangles(inside);
    return table;
  }();
  return cases;
}

constexpr int kVoxelLimit = 1 << 19;  // voxel coordinates an edge key holds

struct Corner {
  Eigen::Vector3i voxel;
  float value = 0;
  std::uint32_t color = 0;
};

// Corner c of a cell is at offset (c & 1, c >> 1 & 1, c >> 2 & 1) from its lowest voxel.
Eigen::Vector3i corner_offset(int c) {
  return {c & 1, (c >> 1) & 1, (c >> 2) & 1};
}

std::uint32_t mix_colors(std::uint32_t a, std::uint32_t b, float t) {
  std::uint32_t out = 0;
  for (int shift : {0, 8, 16}) {
    const float x = static_cast<float>((a >> shift) & 0xff),
                y = static_cast<float>((b >> shift) & 0xff);
    // floor(v + 0.5), as the device's rule (kernels/tsdf/tsdf_mesh.h) rounds.
    out |= static_cast<std::uint32_t>(std::floor(x + (y - x) * t + 0.5f)) << shift;
  }
  return out;
}

class MeshBuilder {
 public:
  MeshBuilder(const TsdfBlocks& blocks, const MeshParams& params)
      : blocks_(blocks), params_(params) {}

  // The blocks a cell of `block` can reach: the block itself and those one step up on each
  // combination of axes (index dx + 2 dy + 4 dz), -1 where none.
  void enter_block(std::size_t block) {
    for (int c = 0; c < 8; ++c)
      neighbours_[c] = blocks_.find(blocks_.coords[block] + corner_offset(c));
  }

  // The cell whose lowest corner is voxel `low` of the block last entered (local coordinates).
  void cell(std::size_t block, const Eigen::Vector3i& local) {
    std::array<const TsdfVoxel*, 8> voxels{};
    bool any_inside = false, any_outside = false;
    for (int c = 0; c < 8; ++c) {
      voxels[c] = corner_voxel(local + corner_offset(c));
      if (!voxels[c]) return;
      (voxels[c]->tsdf < 0 ? any_inside : any_outside) = true;
    }
    if (!any_inside || !any_outside) return;  // no corner on the other side: no surface
    std::array<Corner, 8> corners;
    for (int c = 0; c < 8; ++c) {
      if (voxels[c]->weight < params_.min_weight) return;
      const Eigen::Vector3i voxel =
          blocks_.coords[block] * kTsdfBlockSide + local + corner_offset(c);
      corners[c] = {voxel, voxels[c]->tsdf, voxels[c]->color};
    }
    unsigned inside = 0;
    for (int c = 0; c < 8; ++c) inside |= corners[c].value < 0 ? 1u << c : 0u;
    const std::uint64_t triangles = marching_cubes_cases()[inside];
    for (unsigned k = 0; k < 5; ++k) {
      const auto edges = static_cast<unsigned>((triangles >> (12 * k)) & 0xfff);
      if ((edges & 15) == KG_TSDF_MC_NONE) break;
      triangle(corners, {edges & 15, (edges >> 4) & 15, (edges >> 8) & 15});
    }
  }

  TriangleMesh take() { return std::move(mesh_); }

 private:
  // Voxel `local` (0..8 on each axis) of the entered block, past its upper faces in the
  // neighbours; null where no block holds it.
  const TsdfVoxel* corner_voxel(const Eigen::Vector3i& local) const {
    const int x = local.x() >> 3, y = local.y() >> 3, z = local.z() >> 3;
    const std::ptrdiff_t block = neighbours_[x + 2 * y + 4 * z];
    if (block < 0) return nullptr;
    const Eigen::Vector3i inner = local.array() - kTsdfBlockSide * Eigen::Array3i(x, y, z);
    return &blocks_.voxels[static_cast<std::size_t>(block) * kTsdfBlockVoxels + inner.x() +
                           8 * inner.y() + 64 * inner.z()];
  }

  // The vertex on the edge between two corners, made once (keyed by its lower end: the other is
  // that plus an offset in {0, 1}^3).
  int vertex_on(const Corner& first, const Corner& second) {
    const bool ordered = (second.voxel - first.voxel).minCoeff() >= 0;
    const Corner& a = ordered ? first : second;
    const Corner& b = ordered ? second : first;
    const Eigen::Vector3i biased = a.voxel.array() + kVoxelLimit;
    const Eigen::Vector3i step = b.voxel - a.voxel;
    const std::uint64_t key =
        ((static_cast<std::uint64_t>(biased.x()) | static_cast<std::uint64_t>(biased.y()) << 20 |
          static_cast<std::uint64_t>(biased.z()) << 40)
         << 3) |
        static_cast<std::uint64_t>(step.x() | step.y() << 1 | step.z() << 2);
    bool inserted = false;
    const int index = edges_.find_or_add(key, static_cast<int>(mesh_.vertices.size()), inserted);
    if (inserted) {
      const float t = a.value / (a.value - b.value);
      const Eigen::Vector3f p = a.voxel.cast<float>() + t * step.cast<float>();
      mesh_.vertices.push_back((p.array() + 0.5f) * static_cast<float>(blocks_.voxel_size));
      mesh_.colors.push_back(mix_colors(a.color, b.color, t));
    }
    return index;
  }

  bool is_jump(const Corner& a, const Corner& b) const {
    return std::abs(a.value) >= params_.max_jump && std::abs(b.value) >= params_.max_jump;
  }

  // The triangle on three crossing edges of the cell, unless one is a jump.
  void triangle(const std::array<Corner, 8>& corners, const std::array<unsigned, 3>& edges) {
    std::array<std::pair<const Corner*, const Corner*>, 3> ends;
    for (int i = 0; i < 3; ++i) {
      const unsigned lower = kernels::tsdf_mc_edge_lower(edges[i]);
      ends[i] = {&corners[lower], &corners[lower | 1u << (edges[i] / 4)]};
      if (is_jump(*ends[i].first, *ends[i].second)) return;
    }
    std::array<int, 3> v{};
    for (int i = 0; i < 3; ++i) v[i] = vertex_on(*ends[i].first, *ends[i].second);
    mesh_.triangles.emplace_back(v[0], v[1], v[2]);
  }

  const TsdfBlocks& blocks_;
  MeshParams params_;
  TriangleMesh mesh_;
  detail::EdgeIndex edges_;
  std::array<std::ptrdiff_t, 8> neighbours_{};
};

}  // namespace

TriangleMesh extract_mesh(const TsdfBlocks& blocks, const MeshParams& params) {
  require(blocks.voxels.size() == blocks.coords.size() * kTsdfBlockVoxels,
          "mesh extraction: the field holds " + std::to_string(blocks.voxels.size()) +
              " voxels for " + std::to_string(blocks.coords.size()) + " blocks");
  require(std::isfinite(blocks.voxel_size) && blocks.voxel_size > 0,
          "mesh extraction: the voxel size must be positive");
  const int limit = kVoxelLimit / kTsdfBlockSide - 1;
  for (const Eigen::Vector3i& b : blocks.coords) {
    require((b.array().abs() < limit).all(),
            "mesh extraction: a block lies beyond 2^19 voxels from the origin");
  }
  MeshBuilder builder(blocks, params);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    builder.enter_block(b);
    for (int z = 0; z < kTsdfBlockSide; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        for (int x = 0; x < kTsdfBlockSide; ++x) builder.cell(b, {x, y, z});
      }
    }
  }
  return builder.take();
}

}  // namespace kartograf::mapping
