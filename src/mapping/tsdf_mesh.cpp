#include "kartograf/mapping/tsdf_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "mapping/edge_index.hpp"

namespace kartograf::mapping {

namespace {

// Corner c of a cell is at offset (c & 1, c >> 1 & 1, c >> 2 & 1) from its lowest voxel. The six
// tetrahedra around the diagonal 0-7: each a chain of corners whose offsets only grow, so every
// edge's far end is its near end plus an offset in {0, 1}^3.
constexpr std::array<std::array<int, 4>, 6> kTetrahedra{
    {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}}};
constexpr int kVoxelLimit = 1 << 19;  // voxel coordinates an edge key holds

struct Corner {
  Eigen::Vector3i voxel;
  float value = 0;
  std::uint32_t color = 0;
};

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
    for (const auto& t : kTetrahedra) {
      tetrahedron({corners[t[0]], corners[t[1]], corners[t[2]], corners[t[3]]});
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

  // The triangle on three crossing edges (each: inside corner, outside corner), facing outside.
  void triangle(const std::array<std::pair<const Corner*, const Corner*>, 3>& edges) {
    std::array<int, 3> v{};
    for (int i = 0; i < 3; ++i) v[i] = vertex_on(*edges[i].first, *edges[i].second);
    const Eigen::Vector3f normal = (mesh_.vertices[v[1]] - mesh_.vertices[v[0]])
                                       .cross(mesh_.vertices[v[2]] - mesh_.vertices[v[0]]);
    const Eigen::Vector3f outward = (edges[0].second->voxel - edges[0].first->voxel).cast<float>();
    if (normal.dot(outward) < 0) std::swap(v[1], v[2]);
    mesh_.triangles.emplace_back(v[0], v[1], v[2]);
  }

  void tetrahedron(const std::array<Corner, 4>& t) {
    std::array<const Corner*, 4> inside{}, outside{};
    int n_in = 0, n_out = 0;
    for (const Corner& c : t) (c.value < 0 ? inside[n_in++] : outside[n_out++]) = &c;
    if (n_in == 0 || n_out == 0) return;
    for (int i = 0; i < n_in; ++i) {
      for (int o = 0; o < n_out; ++o) {
        if (is_jump(*inside[i], *outside[o])) return;
      }
    }
    // Edges are (inside, outside); a corner's order in the chain decides which end is lower.
    const auto edge = [](const Corner* in, const Corner* out) { return std::make_pair(in, out); };
    if (n_in == 1 || n_out == 1) {
      const bool lone_inside = n_in == 1;
      std::array<std::pair<const Corner*, const Corner*>, 3> e;
      for (int k = 0; k < 3; ++k) {
        e[k] = lone_inside ? edge(inside[0], outside[k]) : edge(inside[k], outside[0]);
      }
      triangle(e);
      return;
    }
    triangle(
        {edge(inside[0], outside[0]), edge(inside[0], outside[1]), edge(inside[1], outside[1])});
    triangle(
        {edge(inside[0], outside[0]), edge(inside[1], outside[1]), edge(inside[1], outside[0])});
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
