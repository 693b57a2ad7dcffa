#pragma once
// An unorganized point cloud on the host: what PLY files hold. Normals and colours are either
// absent (empty) or given for every point.
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/color.hpp"

namespace kartograf {

struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Rgb8> colors;

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_normals() const { return !normals.empty(); }
  bool has_colors() const { return !colors.empty(); }
};

}  // namespace kartograf
