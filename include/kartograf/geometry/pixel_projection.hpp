#pragma once
// Projection of camera-frame points to the nearest pixel (the inverse of backproject.hpp's
// mapping), for the host-side checks of what one view sees of another.
#include <cmath>
#include <optional>

#include <Eigen/Core>

#include "kartograf/core/intrinsics.hpp"

namespace kartograf::geometry {

// The pixel (u, v) nearest to where camera-frame point p projects; nullopt behind the camera or
// outside the image.
inline std::optional<Eigen::Vector2i> nearest_pixel(const PinholeIntrinsics& camera,
                                                    const Eigen::Vector3d& p) {
  if (!(p.z() > 0)) return std::nullopt;
  const double u = std::floor(camera.fx * p.x() / p.z() + camera.cx + 0.5);
  const double v = std::floor(camera.fy * p.y() / p.z() + camera.cy + 0.5);
  if (!(u >= 0 && v >= 0 && u < camera.width && v < camera.height)) return std::nullopt;
  return Eigen::Vector2i(static_cast<int>(u), static_cast<int>(v));
}

}  // namespace kartograf::geometry
