#pragma once
// Analytic scenes for the ICP tests: boxes and planes ray cast exactly (in double) into organized
// point images, so that two frames of the same scene from known poses are noise-free.
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::testing {

struct SceneBox {
  Eigen::Isometry3d box_to_world = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Ones();
};

struct ScenePlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // world points x with normal . x = offset
  double offset = 2.0;
};

struct Scene {
  std::optional<SceneBox> room;   // seen from inside (walls, floor, ceiling)
  std::vector<SceneBox> objects;  // seen from outside
  std::vector<ScenePlane> planes;
};

// Camera frame: x right, y down, z forward. NaN where no surface lies within max_range.
PointImage render(const Scene& scene, const PinholeIntrinsics& camera,
                  const Eigen::Isometry3d& camera_to_world, double max_range = 8.0);

// A room corner (walls, floor, ceiling) with two rotated boxes: every motion is constrained.
// `scale` shrinks it about the camera (0.5: the back wall at 1.6 m instead of 3.2 m).
Scene corner_scene(double scale = 1.0);
// One wall: translation within it and rotation about its normal are unconstrained.
Scene plane_scene();
// The camera pose both frames start from (slightly turned, so no plane is axis-aligned with it).
Eigen::Isometry3d reference_camera();

PinholeIntrinsics vga_camera();   // 640x480, f = 525
PinholeIntrinsics qvga_camera();  // 320x240, f = 262.5

// Rotation error (degrees) and translation error (metres) of `estimate` against `truth`.
double rotation_error_deg(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);
double translation_error(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);

}  // namespace kartograf::testing
