#pragma once
// The map: every frame's points, moved by its pose into the world, fused into one coloured cloud
// with normals on a voxel grid (docs/methods.md M3 step 5: the union of the aligned clouds, here
// voxel-downsampled so that it does not grow with the number of frames).
//
// Each voxel (the grid of geometry/voxel_downsample.hpp: floor(p / voxel_size), a 2^20-cell range
// per axis) accumulates, over all frames, the sum of its points, of their unit normals (rotated
// into the world) and of their colours, and its point count; the cloud holds one point per voxel
// with at least min_points points: the mean position, the re-normalised mean normal (none when
// the normals cancel) and the mean colour (rounded half up). Sums are in double, so the result
// does not depend on the order frames arrive in beyond rounding.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::mapping {

struct MapFusionParams {
  double voxel_size = 0.02;  // metres
  int pixel_stride = 1;      // fuse 1 pixel in stride x stride of each frame
  double max_depth = 4.0;    // metres: farther points are too noisy for the map
  int min_points = 2;        // voxels with fewer points are left out (flying pixels, noise)
};

class MapFusion {
 public:
  // Throws Error for voxel_size not finite and > 0, stride < 1, max_depth <= 0, min_points < 1.
  explicit MapFusion(MapFusionParams params = {});

  // Adds one organized frame (camera frame) at camera_to_world. normals (NaN: none) and colours
  // (null: none) must have the points' size. Points beyond max_depth are skipped; a point outside
  // the grid's range is an Error.
  void add(const PointImage& points, const NormalImage& normals, const RgbImage* colors,
           const Eigen::Isometry3d& camera_to_world);

  std::size_t voxel_count() const { return voxels_.size(); }
  std::size_t fused_points() const { return fused_points_; }
  // One point per voxel with at least min_points points, in the order voxels were first seen.
  // Normals are (0, 0, 0) where a voxel has none; colours are absent when no frame had colour.
  PointCloud cloud() const;

 private:
  struct Voxel {
    Eigen::Vector3d position_sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d color_sum = Eigen::Vector3d::Zero();
    std::uint32_t points = 0;
    std::uint32_t normals = 0;
    std::uint32_t colors = 0;
  };
  Voxel& voxel_at(std::uint64_t key);
  void grow();

  MapFusionParams params_;
  double inverse_size_;
  std::vector<Voxel> voxels_;
  // Open addressing, linear probing: key per slot (0 = empty) and the voxel's index.
  std::vector<std::uint64_t> slot_keys_;
  std::vector<std::uint32_t> slot_voxels_;
  unsigned capacity_log2_ = 0;
  std::size_t fused_points_ = 0;
  bool any_colors_ = false;
};

}  // namespace kartograf::mapping
