#pragma once
// A picture of a map seen from above, for people to look at: the map's points projected on the
// floor plane (the highest point of each pixel wins, so furniture shows over the floor; points
// far above the cameras, the ceiling, are left out), with the camera trajectory drawn over it in
// red (start green, end blue) and, where known, the true one in yellow.
//
// "Up" is the mean of the cameras' up axes (-y of the optical frame): a robot's or a hand-held
// camera is held roughly upright, whatever the world frame is (SLAM's world is the first camera).
// The picture's x axis is the first camera's viewing direction projected on the floor.
#include <filesystem>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_cloud.hpp"

namespace kartograf::io {

struct TopViewParams {
  int size = 1000;                 // pixels on the longer side (plus margins)
  int margin = 10;                 // pixels
  double ceiling_clearance = 1.0;  // metres above the highest camera: higher points are left out
};

// Unit up vector of camera-to-world poses; throws Error when there are none.
Eigen::Vector3d estimate_up(const std::vector<Eigen::Isometry3d>& camera_poses);

// Points without colours are shaded by height. true_path (e.g. the ground truth's camera
// positions in the map's frame) is drawn in yellow under the trajectory. Throws Error when there
// are no poses.
RgbImage render_top_view(const PointCloud& map, const std::vector<Eigen::Isometry3d>& camera_poses,
                         const TopViewParams& options = {},
                         const std::vector<Eigen::Vector3d>& true_path = {});

// render_top_view, written as PNG (atomic).
void write_top_view_png(const std::filesystem::path& path, const PointCloud& map,
                        const std::vector<Eigen::Isometry3d>& camera_poses,
                        const TopViewParams& options = {});

}  // namespace kartograf::io
