#include "kartograf/semantic/normals_image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/geometry/normals.hpp"

namespace kartograf::semantic {
namespace {

std::uint8_t to_level(double unit) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(unit * 255.0), 0L, 255L));
}

}  // namespace

PointImage smooth_organized_points(const PointImage& points, const NormalsImageParams& params) {
  require(params.smoothing_radius >= 0,
          "smooth_organized_points: smoothing_radius must be >= 0, got " +
              std::to_string(params.smoothing_radius));
  require(std::isfinite(params.max_relative_range_jump) && params.max_relative_range_jump > 0,
          "smooth_organized_points: max_relative_range_jump must be positive");
  const int w = points.width(), h = points.height(), r = params.smoothing_radius;
  PointImage smoothed(w, h, invalid_point());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Point4f& centre = points(x, y);
      if (!is_valid(centre)) continue;
      const float range = centre.head<3>().norm();
      const float limit = params.max_relative_range_jump * range;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int count = 0;
      for (int dy = std::max(-r, -y); dy <= std::min(r, h - 1 - y); ++dy) {
        for (int dx = std::max(-r, -x); dx <= std::min(r, w - 1 - x); ++dx) {
          const Point4f& q = points(x + dx, y + dy);
          if (!is_valid(q) || std::fabs(q.head<3>().norm() - range) > limit) continue;
          sum += q.head<3>().cast<double>();
          ++count;
        }
      }
      const Eigen::Vector3f mean = (sum / count).cast<float>();
      smoothed(x, y) = Point4f(mean.x(), mean.y(), mean.z(), 1.0f);
    }
  }
  return smoothed;
}

NormalImage estimate_organized_normals(const compute::Context& context, const PointImage& points,
                                       const NormalsImageParams& params) {
  PointImage shifted =
      params.smoothing_radius > 0 ? smooth_organized_points(points, params) : points;
  float min_z = std::numeric_limits<float>::infinity();
  for (const Point4f& p : shifted.pixels()) {
    if (is_valid(p)) min_z = std::min(min_z, p.z());
  }
  if (!std::isfinite(min_z)) return NormalImage(points.width(), points.height(), invalid_point());
  const float shift = std::max(0.0f, 1.0f - min_z);
  for (Point4f& p : shifted.pixels()) {
    if (is_valid(p)) p.z() += shift;
  }
  // z >= 1 everywhere, so this threshold admits any neighbour: the depth-jump test is off.
  geometry::NormalParams normal_params;
  normal_params.max_depth_jump = 1e30f;
  NormalImage normals = geometry::estimate_normals(context, shifted, normal_params);
  for (std::size_t i = 0; i < normals.size(); ++i) {
    Point4f& n = normals.pixels()[i];
    const Point4f& p = points.pixels()[i];
    if (!is_valid(n)) continue;
    if (!is_valid(p)) {
      n = invalid_point();
    } else if (n.head<3>().dot(p.head<3>()) > 0) {
      n.head<3>() = -n.head<3>();
    }
  }
  return normals;
}

RgbImage normals_to_rgb(const NormalImage& normals, NormalEncoding encoding) {
  RgbImage rgb(normals.width(), normals.height(), Rgb8{0, 0, 0});
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const Point4f& n = normals.pixels()[i];
    if (!is_valid(n)) continue;
    Rgb8& c = rgb.pixels()[i];
    for (int k = 0; k < 3; ++k) {
      c[k] = encoding == NormalEncoding::absolute ? to_level(std::fabs(n[k]))
                                                  : to_level((n[k] + 1.0) / 2.0);
    }
  }
  return rgb;
}

GrayImage normals_rgb_to_gray(const RgbImage& normals_rgb) {
  GrayImage gray(normals_rgb.width(), normals_rgb.height());
  for (std::size_t i = 0; i < gray.size(); ++i) {
    const Rgb8& c = normals_rgb.pixels()[i];
    gray.pixels()[i] = to_level((0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]) / 255.0);
  }
  return gray;
}

}  // namespace kartograf::semantic
