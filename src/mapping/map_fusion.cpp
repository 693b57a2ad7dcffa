#include "kartograf/mapping/map_fusion.hpp"

#include <cmath>
#include <string>

#include "geometry/voxel_key.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

namespace gd = geometry::detail;

MapFusion::MapFusion(MapFusionParams params) : params_(params) {
  require(std::isfinite(params_.voxel_size) && params_.voxel_size > 0,
          "map fusion: voxel_size must be finite and > 0");
  require(params_.pixel_stride >= 1, "map fusion: pixel_stride must be >= 1");
  require(params_.max_depth > 0, "map fusion: max_depth must be > 0");
  require(params_.min_points >= 1, "map fusion: min_points must be >= 1");
  inverse_size_ = 1.0 / params_.voxel_size;
  capacity_log2_ = gd::hash_capacity_log2(0);
  slot_keys_.assign(std::size_t{1} << capacity_log2_, gd::kEmptyVoxelKey);
  slot_voxels_.assign(slot_keys_.size(), 0);
}

void MapFusion::grow() {
  capacity_log2_ += 1;
  std::vector<std::uint64_t> keys(std::size_t{1} << capacity_log2_, gd::kEmptyVoxelKey);
  std::vector<std::uint32_t> indices(keys.size(), 0);
  const std::size_t mask = keys.size() - 1;
  for (std::size_t s = 0; s < slot_keys_.size(); ++s) {
    if (slot_keys_[s] == gd::kEmptyVoxelKey) continue;
    std::size_t slot = gd::voxel_slot(slot_keys_[s], capacity_log2_);
    while (keys[slot] != gd::kEmptyVoxelKey) slot = (slot + 1) & mask;
    keys[slot] = slot_keys_[s];
    indices[slot] = slot_voxels_[s];
  }
  slot_keys_ = std::move(keys);
  slot_voxels_ = std::move(indices);
}

MapFusion::Voxel& MapFusion::voxel_at(std::uint64_t key) {
  const std::size_t mask = slot_keys_.size() - 1;
  std::size_t slot = gd::voxel_slot(key, capacity_log2_);
  while (slot_keys_[slot] != gd::kEmptyVoxelKey) {
    if (slot_keys_[slot] == key) return voxels_[slot_voxels_[slot]];
    slot = (slot + 1) & mask;
  }
  slot_keys_[slot] = key;
  slot_voxels_[slot] = static_cast<std::uint32_t>(voxels_.size());
  voxels_.emplace_back();
  if (2 * voxels_.size() > slot_keys_.size()) {
    grow();  // keeps the load at most 1/2; the new voxel is the last one
  }
  return voxels_.back();
}

void MapFusion::add(const PointImage& points, const NormalImage& normals, const RgbImage* colors,
                    const Eigen::Isometry3d& camera_to_world) {
  require(normals.width() == points.width() && normals.height() == points.height(),
          "map fusion: normals differ in size from the points");
  require(!colors || (colors->width() == points.width() && colors->height() == points.height()),
          "map fusion: colours differ in size from the points");
  require(camera_to_world.matrix().allFinite(), "map fusion: the pose has NaN/Inf entries");
  if (colors) any_colors_ = true;
  const Eigen::Matrix3d rotation = camera_to_world.linear();
  const int stride = params_.pixel_stride;
  for (int v = 0; v < points.height(); v += stride) {
    for (int u = 0; u < points.width(); u += stride) {
      const Point4f& p = points(u, v);
      if (!is_valid(p) || p.z() > params_.max_depth) continue;
      const Eigen::Vector3d world = camera_to_world * p.head<3>().cast<double>();
      Eigen::Vector3d cell;
      if (!gd::voxel_of(world * inverse_size_, cell)) {
        throw Error("map fusion: point (" + std::to_string(world.x()) + ", " +
                    std::to_string(world.y()) + ", " + std::to_string(world.z()) +
                    ") is outside the voxel grid's range");
      }
      Voxel& voxel = voxel_at(gd::voxel_key(cell));
      voxel.position_sum += world;
      ++voxel.points;
      const Point4f& n = normals(u, v);
      if (is_valid(n)) {
        voxel.normal_sum += rotation * n.head<3>().cast<double>();
        ++voxel.normals;
      }
      if (colors) {
        const Rgb8& c = (*colors)(u, v);
        voxel.color_sum += Eigen::Vector3d(c[0], c[1], c[2]);
        ++voxel.colors;
      }
      ++fused_points_;
    }
  }
}

PointCloud MapFusion::cloud() const {
  PointCloud cloud;
  for (const Voxel& voxel : voxels_) {
    if (voxel.points < static_cast<std::uint32_t>(params_.min_points)) continue;
    cloud.points.push_back((voxel.position_sum / voxel.points).cast<float>());
    const double length = voxel.normal_sum.norm();
    // Normals that cancel (two sides of a thin wall) leave no direction.
    const bool has_normal = voxel.normals > 0 && length >= 1e-3 * voxel.normals;
    cloud.normals.push_back(has_normal ? Eigen::Vector3f((voxel.normal_sum / length).cast<float>())
                                       : Eigen::Vector3f::Zero());
    if (any_colors_) {
      Rgb8 color{0, 0, 0};
      if (voxel.colors > 0) {
        for (int c = 0; c < 3; ++c) {
          color[static_cast<std::size_t>(c)] =
              static_cast<std::uint8_t>(std::floor(voxel.color_sum[c] / voxel.colors + 0.5));
        }
      }
      cloud.colors.push_back(color);
    }
  }
  return cloud;
}

}  // namespace kartograf::mapping
