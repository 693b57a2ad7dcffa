#include "kartograf/mapping/tsdf_mesh.hpp"

#include <array>
#include <cmath>
#include <cstdlib>
#include <string>
#include <unordered_map>

#include "kartograf/core/error.hpp"

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
    out |= static_cast<std::uint32_t>(std::lround(x + (y - x) * t)) << shift;
  }
  return out;
}

class MeshBuilder {
 public:
  MeshBuilder(const TsdfBlocks& blocks, const MeshParams& params)
      : blocks_(blocks), params_(params) {}

  // The cell whose lowest corner is voxel `low` of block `block` (local coordinates).
  void cell(std::size_t block, const Eigen::Vector3i& local) {
    std::array<Corner, 8> corners;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3i voxel =
          blocks_.coords[block] * kTsdfBlockSide + local + corner_offset(c);
      const TsdfVoxel* v = corner_voxel(block, local + corner_offset(c), voxel);
      if (!v || v->weight < params_.min_weight) return;
      corners[c] = {voxel, v->tsdf, v->color};
    }
    for (const auto& t : kTetrahedra) {
      tetrahedron({corners[t[0]], corners[t[1]], corners[t[2]], corners[t[3]]});
    }
  }

  TriangleMesh take() { return std::move(mesh_); }

 private:
  const TsdfVoxel* corner_voxel(std::size_t block, const Eigen::Vector3i& local,
                                const Eigen::Vector3i& voxel) const {
    if ((local.array() < kTsdfBlockSide).all()) {
      return &blocks_.voxels[block * kTsdfBlockVoxels + local.x() + 8 * local.y() + 64 * local.z()];
    }
    return blocks_.voxel(voxel);
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
    const auto [it, inserted] = edges_.try_emplace(key, static_cast<int>(mesh_.vertices.size()));
    if (inserted) {
      const float t = a.value / (a.value - b.value);
      const Eigen::Vector3f p = a.voxel.cast<float>() + t * step.cast<float>();
      mesh_.vertices.push_back((p.array() + 0.5f) * static_cast<float>(blocks_.voxel_size));
      mesh_.colors.push_back(mix_colors(a.color, b.color, t));
    }
    return it->second;
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
  std::unordered_map<std::uint64_t, int> edges_;
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
    for (int z = 0; z < kTsdfBlockSide; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        for (int x = 0; x < kTsdfBlockSide; ++x) builder.cell(b, {x, y, z});
      }
    }
  }
  return builder.take();
}

}  // namespace kartograf::mapping
