#pragma once
// Camera trajectories: timestamped rigid poses (camera-to-world).
#include <vector>

#include <Eigen/Geometry>

namespace kartograf {

struct StampedPose {
  double timestamp = 0;  // seconds
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

using Trajectory = std::vector<StampedPose>;

}  // namespace kartograf
