#include "kartograf/synth/laser_scan.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "kartograf/core/error.hpp"
#include "kartograf/core/random.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "parallel.hpp"

namespace kartograf::synth {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
enum Stream : std::uint64_t { kRange = 1, kDark = 2 };

}  // namespace

void LidarScanParams::validate() const {
  require(columns >= 2 && lines >= 2, "LidarScanParams: needs at least 2 columns and 2 lines");
  require(horizontal_fov_deg > 0 && horizontal_fov_deg <= 360,
          "LidarScanParams: fov must be in (0, 360]");
  require(
      min_elevation_deg < max_elevation_deg && min_elevation_deg >= -90 && max_elevation_deg <= 90,
      "LidarScanParams: elevations must satisfy -90 <= min < max <= 90");
  require(range_sigma >= 0 && min_range >= 0 && max_range > min_range,
          "LidarScanParams: range_sigma >= 0 and 0 <= min_range < max_range");
  require(dark_albedo > 0 && grazing_limit_deg > 0 && grazing_limit_deg <= 90,
          "LidarScanParams: dark_albedo > 0 and grazing_limit_deg in (0, 90]");
}

Eigen::Vector3d laser_beam_direction(const LidarScanParams& o, int column, int row) {
  const double azimuth =
      (-0.5 * o.horizontal_fov_deg + column * o.horizontal_fov_deg / (o.columns - 1)) * kDegree;
  const double elevation =
      (o.max_elevation_deg - row * (o.max_elevation_deg - o.min_elevation_deg) / (o.lines - 1)) *
      kDegree;
  return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
          std::sin(elevation)};
}

LaserScan scan_laser(const RayCaster& caster, const Eigen::Isometry3d& sensor_to_world,
                     const LidarScanParams& options, std::uint64_t seed) {
  options.validate();
  const World& world = caster.world();
  LaserScan scan;
  scan.sensor_to_world = sensor_to_world;
  scan.points = PointImage(options.columns, options.lines, invalid_point());
  scan.plane_id = LabelImage(options.columns, options.lines, kUnlabeled);
  scan.semantic = SemanticImage(options.columns, options.lines, SemanticClass::unknown);
  scan.range_true =
      Image<float>(options.columns, options.lines, std::numeric_limits<float>::quiet_NaN());
  const Eigen::Matrix3d rotation = sensor_to_world.linear();
  const Eigen::Vector3d origin = sensor_to_world.translation();

  detail::parallel_rows(options.lines, options.threads, [&](int begin, int end) {
    for (int row = begin; row < end; ++row) {
      for (int col = 0; col < options.columns; ++col) {
        const Eigen::Vector3d beam = laser_beam_direction(options, col, row);
        const Eigen::Vector3d d = rotation * beam;
        const auto hit = caster.cast(origin, d);
        if (!hit) continue;
        scan.range_true(col, row) = static_cast<float>(hit->t);
        scan.plane_id(col, row) = hit->plane;
        if (hit->plane) scan.semantic(col, row) = world.plane(hit->plane).semantic;

        const std::uint64_t key =
            hash_key(seed, static_cast<std::uint64_t>(row) * options.columns + col);
        const double cos_incidence = std::fabs(face_normal(hit->face).dot(d));
        if (std::acos(std::min(1.0, cos_incidence)) > options.grazing_limit_deg * kDegree) continue;
        const double albedo = luminance(surface_albedo(world, *hit));
        if (albedo < options.dark_albedo &&
            hash_uniform(key, kDark) < 1.0 - albedo / options.dark_albedo) {
          continue;
        }
        const double range = hit->t + options.range_sigma * hash_normal(key, kRange);
        if (range < options.min_range || range > options.max_range) continue;
        scan.points(col, row) =
            Point4f(static_cast<float>(range * beam.x()), static_cast<float>(range * beam.y()),
                    static_cast<float>(range * beam.z()), 1.0f);
      }
    }
  });
  return scan;
}

Eigen::Isometry3d default_scan_pose(const World& world) {
  const Room* largest = nullptr;
  for (const Room& room : world.rooms) {
    if (room.kind == RoomKind::room && (!largest || room.rect.area() > largest->rect.area()))
      largest = &room;
  }
  require(largest != nullptr, "default_scan_pose: the world has no room");
  const Eigen::Vector2d p = most_open_point(world, largest->id).first;
  const Rect2& r = largest->rect;
  double yaw = 0;
  if (r.size().x() >= r.size().y()) {
    yaw = (r.max.x() - p.x() >= p.x() - r.min.x()) ? 0.0 : std::numbers::pi;
  } else {
    yaw =
        (r.max.y() - p.y() >= p.y() - r.min.y()) ? 0.5 * std::numbers::pi : -0.5 * std::numbers::pi;
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(p.x(), p.y(), 0.8);
  return pose;
}

}  // namespace kartograf::synth
