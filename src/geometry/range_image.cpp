#include "kartograf/geometry/range_image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"

namespace kartograf::geometry {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

void require_positive(double value, const char* field) {
  require(std::isfinite(value) && value > 0, std::string("range image: ") + field +
                                                 " must be finite and > 0, got " +
                                                 std::to_string(value));
}

// Where a sensor-frame point falls in the image, and its range.
struct Projection {
  int column = 0, row = 0;
  double range = 0, elevation = 0;
};

class SphericalLayout {
 public:
  explicit SphericalLayout(const RangeImageParams& params)
      : step_deg_(params.angular_step_deg),
        max_elevation_deg_(params.max_elevation_deg),
        columns_(static_cast<int>(std::lround(360.0 / params.angular_step_deg))),
        rows_(static_cast<int>(std::lround((params.max_elevation_deg - params.min_elevation_deg) /
                                           params.angular_step_deg))) {}

  int columns() const { return columns_; }
  int rows() const { return rows_; }
  double step() const { return step_deg_ * kDegree; }  // radians

  bool project(const Eigen::Vector3d& q, Projection& out) const {
    out.range = q.norm();
    // In degrees, so that a ray on a pixel border lands where the numbers say.
    const double azimuth_deg = std::atan2(q.y(), q.x()) / kDegree;
    out.elevation = std::atan2(q.z(), std::hypot(q.x(), q.y()));
    out.column = std::min(columns_ - 1, static_cast<int>((180.0 - azimuth_deg) / step_deg_));
    const double row = std::floor((max_elevation_deg_ - out.elevation / kDegree) / step_deg_);
    if (row < 0 || row >= rows_) return false;
    out.row = static_cast<int>(row);
    return true;
  }

 private:
  double step_deg_, max_elevation_deg_;
  int columns_, rows_;
};

}  // namespace

void RangeImageParams::validate() const {
  require_positive(angular_step_deg, "angular_step_deg");
  // Finer steps would overflow the image's int size (360 / step columns).
  require(angular_step_deg >= 1e-3, "range image: angular_step_deg must be >= 0.001, got " +
                                        std::to_string(angular_step_deg));
  require(std::isfinite(min_elevation_deg) && std::isfinite(max_elevation_deg) &&
              min_elevation_deg >= -90 && max_elevation_deg <= 90 &&
              max_elevation_deg - min_elevation_deg >= angular_step_deg,
          "range image: need -90 <= min_elevation_deg < max_elevation_deg <= 90 (at least one "
          "row), got " +
              std::to_string(min_elevation_deg) + " .. " + std::to_string(max_elevation_deg));
  require_positive(min_range, "min_range");
  require(std::isfinite(max_range) && max_range > min_range,
          "range image: max_range must be finite and > min_range");
  require(std::isfinite(surface_radius) && surface_radius >= 0,
          "range image: surface_radius must be finite and >= 0");
  require(max_splat_pixels >= 0, "range image: max_splat_pixels must be >= 0");
  require(std::isfinite(occlusion_margin) && occlusion_margin >= 0,
          "range image: occlusion_margin must be finite and >= 0");
}

RangeImage make_range_image(std::span<const Eigen::Vector3f> points,
                            const Eigen::Isometry3d& sensor_to_world,
                            const RangeImageParams& params) {
  params.validate();
  require(sensor_to_world.matrix().allFinite(), "range image: the viewpoint pose is not finite");
  const SphericalLayout layout(params);
  const int w = layout.columns(), h = layout.rows();
  // Two float images, the index and the points, per pixel.
  constexpr double kBytesPerPixel = 2 * sizeof(float) + sizeof(std::int32_t) + sizeof(Point4f);
  require_fits_in_memory(kBytesPerPixel * w * h,
                         "range image: " + std::to_string(w) + " x " + std::to_string(h) +
                             " pixels at an angular step of " +
                             std::to_string(params.angular_step_deg) + " degrees");
  const Eigen::Isometry3d world_to_sensor = sensor_to_world.inverse();

  constexpr float kFar = std::numeric_limits<float>::infinity();
  Image<float> nearest(w, h, kFar), occluder(w, h, kFar);
  RangeImage out;
  out.sensor_to_world = sensor_to_world;
  out.index = Image<std::int32_t>(w, h, -1);
  out.points = PointImage(w, h, invalid_point());

  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    const Eigen::Vector3d q = world_to_sensor * points[i].cast<double>();
    Projection p;
    if (!layout.project(q, p) || p.range < params.min_range || p.range > params.max_range) continue;
    const float range = static_cast<float>(p.range);
    if (range < nearest(p.column, p.row)) {
      nearest(p.column, p.row) = range;
      out.index(p.column, p.row) = static_cast<std::int32_t>(i);
    }
    // The disc this point occludes: its angular radius, wider in azimuth towards the poles.
    const double radius = std::atan2(params.surface_radius, p.range) / layout.step();
    const int rows_out = std::min(params.max_splat_pixels, static_cast<int>(radius));
    const int columns_out = std::min(
        params.max_splat_pixels, static_cast<int>(radius / std::max(std::cos(p.elevation), 1e-3)));
    for (int dy = -rows_out; dy <= rows_out; ++dy) {
      const int y = p.row + dy;
      if (y < 0 || y >= h) continue;
      for (int dx = -columns_out; dx <= columns_out; ++dx) {
        const int x = (p.column + dx + w) % w;  // azimuth wraps around
        occluder(x, y) = std::min(occluder(x, y), range);
      }
    }
  }
  const float keep = static_cast<float>(1.0 + params.occlusion_margin);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::int32_t i = out.index(x, y);
      if (i < 0) continue;
      if (params.surface_radius > 0 && nearest(x, y) > keep * occluder(x, y)) {
        out.index(x, y) = -1;  // seen through the gaps of a nearer surface
        continue;
      }
      const Eigen::Vector3d q =
          world_to_sensor * points[static_cast<std::size_t>(i)].cast<double>();
      out.points(x, y) = Point4f(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                 static_cast<float>(q.z()), 1.0f);
    }
  }
  return out;
}

}  // namespace kartograf::geometry
