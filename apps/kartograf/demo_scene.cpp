#include "demo_scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include <Eigen/Geometry>

namespace kartograf::demo {

namespace {

struct Box {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};

// World frame: x along the 5 m wall, y along the 4 m wall, z up, origin in a floor corner.
const Box kRoom{{0.0, 0.0, 0.0}, {5.0, 4.0, 2.6}};
const Box kCabinet{{2.6, 1.6, 0.0}, {3.4, 2.2, 0.9}};

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Distance along ray to where it leaves the room; the ray starts inside.
double exit_distance(const Box& room, const Eigen::Vector3d& origin, const Eigen::Vector3d& ray) {
  double t = kInfinity;
  for (int axis = 0; axis < 3; ++axis) {
    if (ray[axis] > 0) t = std::min(t, (room.max[axis] - origin[axis]) / ray[axis]);
    if (ray[axis] < 0) t = std::min(t, (room.min[axis] - origin[axis]) / ray[axis]);
  }
  return t;
}

// Distance along ray to where it enters box (slab test), if it does in front of the origin.
std::optional<double> entry_distance(const Box& box, const Eigen::Vector3d& origin,
                                     const Eigen::Vector3d& ray) {
  double enter = -kInfinity;
  double leave = kInfinity;
  for (int axis = 0; axis < 3; ++axis) {
    if (ray[axis] == 0) {
      if (origin[axis] < box.min[axis] || origin[axis] > box.max[axis]) return std::nullopt;
      continue;
    }
    double t0 = (box.min[axis] - origin[axis]) / ray[axis];
    double t1 = (box.max[axis] - origin[axis]) / ray[axis];
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0);
    leave = std::min(leave, t1);
  }
  if (enter > leave || enter <= 0) return std::nullopt;
  return enter;
}

// Camera-to-world rotation for a camera (x right, y down, z forward) looking along `forward`.
Eigen::Matrix3d look_rotation(const Eigen::Vector3d& forward) {
  const Eigen::Vector3d f = forward.normalized();
  const Eigen::Vector3d right = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = f.cross(right);
  Eigen::Matrix3d rotation;
  rotation << right, down, f;
  return rotation;
}

}  // namespace

DemoFrame render_demo_room() {
  DemoFrame frame;
  frame.intrinsics = {640, 480, 525.0, 525.0, 319.5, 239.5};
  const PinholeIntrinsics& k = frame.intrinsics;

  const Eigen::Vector3d camera(0.4, 0.4, 1.2);
  // Towards the camera's mirror image through the room centre: along the floor's diagonal.
  const Eigen::Vector2d across = (kRoom.min + kRoom.max).head<2>() - 2.0 * camera.head<2>();
  const double yaw = std::atan2(across.y(), across.x());
  const double pitch = -10.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                std::sin(pitch));
  const Eigen::Matrix3d camera_to_world = look_rotation(forward);

  frame.depth = DepthImage(k.width, k.height, 0);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      // With the camera-frame ray scaled to z = 1, the hit distance is the depth itself.
      const Eigen::Vector3d ray =
          camera_to_world * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      double depth = exit_distance(kRoom, camera, ray);
      if (const auto cabinet = entry_distance(kCabinet, camera, ray)) {
        depth = std::min(depth, *cabinet);
      }
      const double millimetres = std::round(depth * 1000.0);
      if (std::isfinite(millimetres) && millimetres > 0 && millimetres <= 65535) {
        frame.depth(u, v) = static_cast<std::uint16_t>(millimetres);
      }
    }
  }
  return frame;
}

}  // namespace kartograf::demo
