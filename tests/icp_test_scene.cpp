#include "icp_test_scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace kartograf::testing {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Entry and exit distances of a ray through a box (slab method); empty when it misses.
std::optional<std::pair<double, double>> slabs(const SceneBox& box, const Eigen::Vector3d& origin,
                                               const Eigen::Vector3d& direction) {
  const Eigen::Isometry3d world_to_box = box.box_to_world.inverse();
  const Eigen::Vector3d o = world_to_box * origin;
  const Eigen::Vector3d d = world_to_box.linear() * direction;
  double near = -kInfinity, far = kInfinity;
  for (int axis = 0; axis < 3; ++axis) {
    if (d(axis) == 0.0) {
      if (std::fabs(o(axis)) > box.half_extents(axis)) return std::nullopt;
      continue;
    }
    const double t1 = (-box.half_extents(axis) - o(axis)) / d(axis);
    const double t2 = (box.half_extents(axis) - o(axis)) / d(axis);
    near = std::max(near, std::min(t1, t2));
    far = std::min(far, std::max(t1, t2));
  }
  if (near > far) return std::nullopt;
  return std::pair{near, far};
}

Eigen::Isometry3d box_pose(const Eigen::Vector3d& centre, double yaw_deg) {
  return Eigen::Translation3d(centre) *
         Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitY());
}

}  // namespace

PointImage render(const Scene& scene, const PinholeIntrinsics& camera,
                  const Eigen::Isometry3d& camera_to_world, double max_range) {
  PointImage image(camera.width, camera.height, invalid_point());
  const Eigen::Vector3d origin = camera_to_world.translation();
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      // A ray with unit z in the camera frame: its parameter t is the depth.
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      const Eigen::Vector3d direction = camera_to_world.linear() * ray;
      double best = kInfinity;
      if (scene.room) {
        const auto hit = slabs(*scene.room, origin, direction);
        if (hit && hit->first < 0 && hit->second > 0) best = hit->second;
      }
      for (const SceneBox& box : scene.objects) {
        const auto hit = slabs(box, origin, direction);
        if (hit && hit->first > 0) best = std::min(best, hit->first);
      }
      for (const ScenePlane& plane : scene.planes) {
        const double t = (plane.offset - plane.normal.dot(origin)) / plane.normal.dot(direction);
        if (t > 0) best = std::min(best, t);
      }
      if (best * ray.norm() > max_range) continue;
      const Eigen::Vector3d p = best * ray;
      image(u, v) = Point4f(static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(p.z()), 1.0f);
    }
  }
  return image;
}

Scene corner_scene(double scale) {
  Scene scene;
  scene.room = SceneBox{box_pose(scale * Eigen::Vector3d(0.15, -0.1, 1.1), 0.0),
                        scale * Eigen::Vector3d(1.75, 1.2, 2.1)};
  scene.objects.push_back({box_pose(scale * Eigen::Vector3d(-0.55, 0.75, 2.0), 20.0),
                           scale * Eigen::Vector3d(0.3, 0.35, 0.25)});
  scene.objects.push_back({box_pose(scale * Eigen::Vector3d(0.7, 0.45, 2.5), -30.0),
                           scale * Eigen::Vector3d(0.25, 0.65, 0.2)});
  return scene;
}

Scene plane_scene() {
  Scene scene;
  scene.planes.push_back({Eigen::Vector3d::UnitZ(), 2.0});
  return scene;
}

Eigen::Isometry3d reference_camera() {
  return Eigen::Isometry3d(Eigen::AngleAxisd(0.17, Eigen::Vector3d::UnitY()) *
                           Eigen::AngleAxisd(-0.08, Eigen::Vector3d::UnitX()));
}

PinholeIntrinsics vga_camera() {
  return {640, 480, 525.0, 525.0, 319.5, 239.5};
}
PinholeIntrinsics qvga_camera() {
  return {320, 240, 262.5, 262.5, 159.5, 119.5};
}

double rotation_error_deg(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return Eigen::AngleAxisd(estimate.linear() * truth.linear().transpose()).angle() * 180.0 /
         std::numbers::pi;
}

double translation_error(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return (estimate.translation() - truth.translation()).norm();
}

}  // namespace kartograf::testing
