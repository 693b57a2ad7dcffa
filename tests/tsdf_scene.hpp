#pragma once
// Test fields for the TSDF and what is made from it: an analytic scene (a sphere before a wall)
// rendered as depth from poses, and fields fused from it and from real 7-Scenes frames.
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/core/image.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf::tsdf_scene {

using mapping::TsdfVolume;
using mapping::TsdfVolumeParams;

inline const PinholeIntrinsics kCamera{160, 120, 140.0, 140.0, 79.5, 59.5};
constexpr double kUnits = 1000.0;  // millimetres

// A scene as the distance along a unit ray to its first surface (or infinity).
struct Scene {
  Eigen::Vector3d sphere_centre{0.1, -0.05, 1.6};
  double sphere_radius = 0.35;
  double wall_z = 2.4;  // a plane z = wall_z, facing the camera at the origin

  double hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& ray) const {
    double best = std::numeric_limits<double>::infinity();
    const Eigen::Vector3d oc = origin - sphere_centre;
    const double b = oc.dot(ray);
    const double disc = b * b - (oc.squaredNorm() - sphere_radius * sphere_radius);
    if (disc >= 0 && -b - std::sqrt(disc) > 0) best = -b - std::sqrt(disc);
    if (ray.z() > 1e-9) {
      const double t = (wall_z - origin.z()) / ray.z();
      if (t > 0) best = std::min(best, t);
    }
    return best;
  }
  // Distance from p to the nearest surface.
  double distance(const Eigen::Vector3d& p) const {
    return std::min(std::abs((p - sphere_centre).norm() - sphere_radius), std::abs(p.z() - wall_z));
  }
};

// The depth image (millimetres) of the scene from a camera at pose.
inline DepthImage render(const Scene& scene, const Eigen::Isometry3d& pose) {
  DepthImage depth(kCamera.width, kCamera.height);
  for (int v = 0; v < kCamera.height; ++v) {
    for (int u = 0; u < kCamera.width; ++u) {
      const Eigen::Vector3d ray_c((u - kCamera.cx) / kCamera.fx, (v - kCamera.cy) / kCamera.fy, 1);
      const Eigen::Vector3d ray = pose.linear() * ray_c.normalized();
      const double t = scene.hit(pose.translation(), ray);
      const double z = t / ray_c.norm();
      depth(u, v) =
          std::isfinite(t) && z < 60 ? static_cast<std::uint16_t>(std::lround(z * kUnits)) : 0;
    }
  }
  return depth;
}

inline Eigen::Isometry3d pose_at(double x, double y, double yaw_deg) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() =
      Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, 0);
  return pose;
}

inline geometry::DepthRange depth_range() {
  return {kUnits, 0.2, 5.0};
}

inline TsdfVolumeParams volume_params(double voxel_size, double truncation) {
  TsdfVolumeParams params;
  params.voxel_size = voxel_size;
  params.truncation = truncation;
  return params;
}

// A 2 cm field of the sphere and the wall seen from three yaws.
inline std::unique_ptr<TsdfVolume> sphere_and_wall(const compute::Context& context) {
  const Scene scene;
  const TsdfVolumeParams params = volume_params(0.02, 0.06);
  auto volume = std::make_unique<TsdfVolume>(context, params);
  for (const double yaw : {-10.0, 0.0, 12.0}) {
    const Eigen::Isometry3d pose = pose_at(0.05 * yaw / 10, 0.02, yaw);
    volume->integrate(render(scene, pose), {}, kCamera, depth_range(), pose);
  }
  return volume;
}

// A 2 cm field of 7-Scenes frames 0 and 10 at their poses, with colour or without.
inline std::unique_ptr<TsdfVolume> kitchen_frames(const compute::Context& context, bool color) {
  const TsdfVolumeParams params = volume_params(0.02, 0.06);
  auto volume = std::make_unique<TsdfVolume>(context, params);
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  for (const std::string name : {"frame-000000", "frame-000010"}) {
    volume->integrate(testing::read_depth(frames / (name + ".depth.png")),
                      color ? testing::read_color(frames / (name + ".color.jpg")) : RgbImage(),
                      PinholeIntrinsics::kinect_7scenes(), geometry::DepthRange{1000.0, 0.3, 4.0},
                      testing::read_pose(frames / (name + ".pose.txt")));
  }
  return volume;
}

}  // namespace kartograf::tsdf_scene
