#pragma once
// Unorganized clouds on a device (points with optional normals and colours), and their uniform
// 1-in-k subsampling (docs/methods.md M3 step 1: the paper keeps 1 point in 10).
//
// Subsampling keeps points 0, k, 2k, ... (ceil(n / k) points, in order, invalid ones included):
// the selection of registration::is_selected() for an unorganized cloud. A copy: exact on every
// backend.
#include <cstdint>
#include <string>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::geometry {

// normals and colors are empty (absent) or hold one entry per point. Points are (x, y, z, 1) or
// all-NaN (invalid); normals (nx, ny, nz, 0) or all-NaN; colours packed r | g << 8 | b << 16
// (pack_rgb, core/color.hpp).
struct DeviceCloud {
  compute::Buffer<Point4f> points;
  compute::Buffer<Point4f> normals;
  compute::Buffer<std::uint32_t> colors;

  std::size_t size() const { return points.size(); }
  bool has_normals() const { return !normals.empty(); }
  bool has_colors() const { return !colors.empty(); }
  // Throws Error, naming `what`, when normals or colours are neither absent nor one per point.
  void validate(const std::string& what) const;

  static DeviceCloud from_host(const compute::Context& context, const PointCloud& cloud);
  PointCloud to_host() const;  // invalid points are dropped (with their normals and colours)
};

// Throws Error for k < 1 or normals/colours whose count differs from the points'.
DeviceCloud subsample(const compute::Context& context, const DeviceCloud& cloud, int k);

}  // namespace kartograf::geometry
