#pragma once
// Organized point clouds: one float4 (x, y, z, 1) per pixel, all-NaN where the pixel has no point.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "kartograf/core/image.hpp"

namespace kartograf {

using Point4f = Eigen::Vector4f;
using PointImage = Image<Point4f>;
using NormalImage = Image<Point4f>;  // (nx, ny, nz, 0), all-NaN where no normal could be estimated
using DepthImage = Image<std::uint16_t>;

inline Point4f invalid_point() { return Point4f::Constant(std::numeric_limits<float>::quiet_NaN()); }
inline bool is_valid(const Point4f& p) { return !std::isnan(p.x()); }

}  // namespace kartograf
